// Membership in a Boolean's trimmed cell (membership.hpp; Massarwi & Elber 2016, Sec. 4): a
// point of the cell's trivariate belongs to it when it lies in every `within` cell and in no
// `without` solid, each decided by its own locator, and its properties are then blended with the
// within cells' by the cell's rule (the clipped sum, the mean, or Massarwi & Elber 2016, Eq. 2's
// distance weights). Cost: one point location per condition, plus one closest-point query per
// boundary surface for the distance blend.
#include "membership.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>
#include <vector>

namespace trivox::slice {

namespace detail {

void build_trims(Locator::Data& D, const vmodel::VModel& model, const LocatorOptions& opt) {
  using Data = Locator::Data;
  const int nc = static_cast<int>(model.cells.size());
  // Booleans' trimming: one locator per condition, built recursively (their cells may be
  // trimmed too).
  D.trims.resize(static_cast<std::size_t>(nc));
  for (int c = 0; c < nc; ++c) {
    const auto& cell = model.cells[static_cast<std::size_t>(c)];
    if (cell.plain()) continue;
    auto trim = std::make_unique<Data::Trim>();
    trim->blend = cell.blend;
    const auto sub = [&](std::vector<vmodel::VCell> cells) {
      auto s = std::make_unique<Data::Sub>();
      s->model.units = model.units;
      s->model.properties = model.properties;
      s->model.cells = std::move(cells);
      s->loc = std::make_unique<Locator>(s->model, opt);
      return s;
    };
    for (const auto& w : cell.within) trim->within.push_back(sub({w}));
    for (const auto& solid : cell.without) trim->without.push_back(sub(solid));
    if (cell.blend == vmodel::BlendRule::distance) {
      // Without one boundary per value the distances are undefined: the plain mean then.
      if (cell.boundaries.size() != 1 + cell.within.size()) {
        trim->blend = vmodel::BlendRule::mean;
      } else {
        trim->power = cell.blend_power;
        for (const auto& list : cell.boundaries) {
          std::vector<geom::SurfaceDistance> d;
          for (const auto& f : list) d.emplace_back(f);
          trim->boundaries.push_back(std::move(d));
        }
      }
    }
    D.trims[static_cast<std::size_t>(c)] = std::move(trim);
    D.any_trim = true;
  }
}

}  // namespace detail

bool Locator::trimmed(int cell) const noexcept { return data_->trims[static_cast<std::size_t>(cell)] != nullptr; }
bool Locator::has_trims() const noexcept { return data_->any_trim; }

bool Locator::admits(int cell, const Vec3& p, double* props) const {
  const auto& trim = data_->trims[static_cast<std::size_t>(cell)];
  if (!trim) return true;
  for (const auto& o : trim->without)
    if (o->loc->locate(p).inside) return false;
  const int m = data_->m;
  const bool blend = props && m > 0 && trim->blend != vmodel::BlendRule::first;
  // The values to combine: the cell's own (props on entry), then each within cell's at p, with
  // its own blend applied; each within cell must hold p.
  std::vector<double> values;
  if (blend) values.assign(props, props + m);
  for (const auto& w : trim->within) {
    const auto r = w->loc->locate(p);
    if (!r.inside) return false;
    if (!blend) continue;
    const std::size_t at = values.size();
    values.resize(at + static_cast<std::size_t>(m));
    double x[3];
    w->loc->eval(r.cell, r.uvw, x, values.data() + at);
    w->loc->admits(r.cell, p, values.data() + at);
  }
  if (!blend) return true;
  const std::size_t n = values.size() / static_cast<std::size_t>(m);
  // Weights: 1 for the sum and the mean; Massarwi & Elber 2016, Eq. 2's d_i^k for the distance
  // blend, d_i the distance to input i's boundary (on every input's boundary at once, Eq. 2's
  // singular points, the plain mean).
  std::vector<double> w(n, 1.0);
  if (trim->blend == vmodel::BlendRule::distance) {
    double wsum = 0.0;
    for (std::size_t i = 0; i < n; ++i) wsum += w[i] = std::pow(geom::distance(trim->boundaries[i], p), trim->power);
    if (!(wsum > 0)) std::fill(w.begin(), w.end(), 1.0);
  }
  double wsum = 0.0;
  for (double x : w) wsum += x;
  for (int h = 0; h < m; ++h) {
    double acc = 0.0;
    for (std::size_t i = 0; i < n; ++i) acc += w[i] * values[i * static_cast<std::size_t>(m) + static_cast<std::size_t>(h)];
    props[h] = trim->blend == vmodel::BlendRule::sum_clip ? std::clamp(acc, 0.0, 1.0) : acc / wsum;
  }
  return true;
}

}  // namespace trivox::slice
