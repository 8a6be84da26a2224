#include "trivox/vmodel/vmodel.hpp"

namespace trivox::vmodel {

const char* blend_rule_name(BlendRule r) noexcept {
  switch (r) {
    case BlendRule::first: return "first";
    case BlendRule::sum_clip: return "sum_clip";
    case BlendRule::mean: return "mean";
    case BlendRule::distance: return "distance";
  }
  return "first";
}

bool blend_rule_from_name(std::string_view name, BlendRule& out) noexcept {
  for (BlendRule r : {BlendRule::first, BlendRule::sum_clip, BlendRule::mean, BlendRule::distance})
    if (name == blend_rule_name(r)) {
      out = r;
      return true;
    }
  return false;
}

const VCell* VModel::find_cell(const std::string& name) const noexcept {
  for (const auto& c : cells)
    if (c.name == name) return &c;
  return nullptr;
}

}  // namespace trivox::vmodel
