#include "trivox/vmodel/vmodel.hpp"

namespace trivox::vmodel {

const VCell* VModel::find_cell(const std::string& name) const noexcept {
  for (const auto& c : cells)
    if (c.name == name) return &c;
  return nullptr;
}

}  // namespace trivox::vmodel
