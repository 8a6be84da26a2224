// Tensor Gauss points of a surface patch with its xyz and first partials there, for surface
// integrals: areas and coordinate integrals (geom/trimmed_surface.hpp), volumes and moments of
// Boolean pieces (slice/piece_measures.hpp). A Bezier patch on [0, 1]^2 (what geom::untrim makes) is evaluated
// from Bernstein tables at the nodes, contracted along t first: O(n_t o_s o_t + n_s n_t o_s)
// per patch for orders o and n nodes, against a general evaluation per node. Any other patch
// is evaluated per knot span with TensorSpline::eval_derivatives.
#pragma once
#include <array>
#include <map>
#include <vector>

#include "trivox/spline/tensor_spline.hpp"

namespace trivox::geom::detail {

struct PatchPoint {
  std::array<double, 3> x, xs, xt;  ///< X, dX/ds, dX/dt (xyz)
  double w = 0.0;                   ///< the Gauss weight times the parameter element's area
};

/// Gauss rules on [0, 1] with the Bernstein basis of one order and its derivative at the nodes.
struct BernsteinRule {
  std::vector<double> nodes, weights;  ///< on [0, 1]
  std::vector<double> b, db;           ///< [node * order + i]
};

/// Rules by (order, points), built once per use.
class PatchRules {
public:
  const BernsteinRule& get(int order, int points);

private:
  std::map<std::pair<int, int>, BernsteinRule> rules_;
};

/// The points of patch p with points(order) Gauss points per direction and knot span
/// (order -> number of points, the same function for both directions), into `out` (cleared).
template <class Points>
void patch_points(const spline::Surface& p, Points points, PatchRules& rules, std::vector<PatchPoint>& out);

// ---- definitions ----

void bezier_points(const spline::Surface& p, int ns, int nt, PatchRules& rules, std::vector<PatchPoint>& out);
void spline_points(const spline::Surface& p, int ns, int nt, std::vector<PatchPoint>& out);

template <class Points>
void patch_points(const spline::Surface& p, Points points, PatchRules& rules, std::vector<PatchPoint>& out) {
  out.clear();
  const auto o = p.orders();
  const int ns = points(o[0]), nt = points(o[1]);
  bool bezier = !p.rational();
  for (int d = 0; d < 2; ++d)
    bezier = bezier && p.count(d) == o[static_cast<std::size_t>(d)] && p.domain(d) == std::array<double, 2>{0.0, 1.0};
  if (bezier)
    bezier_points(p, ns, nt, rules, out);
  else
    spline_points(p, ns, nt, out);
}

}  // namespace trivox::geom::detail
