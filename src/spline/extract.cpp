#include "trivox/spline/extract.hpp"

#include <algorithm>
#include <limits>
#include <string>

#include "tensor_ops.hpp"
#include "trivox/error.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::spline {

template <int P>
TensorSpline<P - 1> iso(const TensorSpline<P>& s, int dir, double t) {
  if (dir < 0 || dir >= P) throw Error("direction " + std::to_string(dir) + "; expected 0.." + std::to_string(P - 1));
  const KnotVector& kv = s.knots(dir);
  if (!kv.contains(t))
    throw Error("iso-parameter " + std::to_string(t) + " outside the domain [" + std::to_string(kv.front()) + ", " +
                std::to_string(kv.back()) + "]; expected a value inside it");
  const auto net = detail::apply_along(detail::to_net(s), dir, detail::basis_row(kv, t));
  // With extent 1 along dir, dropping the direction keeps the memory order of the rest.
  detail::Net<P - 1> out;
  out.H = net.H;
  out.values = net.values;
  std::array<KnotVector, P - 1> knots;
  for (int d = 0, e = 0; d < P; ++d) {
    if (d == dir) continue;
    out.extents[static_cast<std::size_t>(e)] = net.extents[static_cast<std::size_t>(d)];
    knots[static_cast<std::size_t>(e++)] = s.knots(d);
  }
  return detail::from_net<P - 1>(std::move(knots), s.dim(), s.rational(), std::move(out));
}

Curve iso_curve(const Trivariate& s, int dir, const std::array<double, 3>& fixed) {
  if (dir < 0 || dir > 2) throw Error("direction " + std::to_string(dir) + "; expected 0..2");
  // Fix the highest other direction first so the remaining indices stay simple.
  const int hi = dir == 2 ? 1 : 2;
  const int lo = dir == 0 ? 1 : 0;
  const Surface surf = iso(s, hi, fixed[static_cast<std::size_t>(hi)]);
  return iso(surf, lo, fixed[static_cast<std::size_t>(lo)]);
}

std::string_view face_name(Face f) {
  static constexpr std::array<std::string_view, 6> names{"u0", "u1", "v0", "v1", "w0", "w1"};
  return names[static_cast<std::size_t>(f)];
}

Face face_from_name(std::string_view name) {
  for (Face f : all_faces)
    if (face_name(f) == name) return f;
  throw Error("face \"" + std::string(name) + "\"; expected one of u0 u1 v0 v1 w0 w1");
}

Surface boundary_face(const Trivariate& s, Face f) {
  const int i = static_cast<int>(f);
  const int dir = i / 2;
  const auto dom = s.domain(dir);
  return iso(s, dir, (i % 2 == 0) ? dom[0] : dom[1]);
}

template <int P>
std::array<std::vector<double>, 2> bounding_box(const TensorSpline<P>& s, int coords) {
  const int k = coords < 0 ? s.dim() : std::min(coords, s.dim());
  std::array<std::vector<double>, 2> box{
      std::vector<double>(static_cast<std::size_t>(k), std::numeric_limits<double>::infinity()),
      std::vector<double>(static_cast<std::size_t>(k), -std::numeric_limits<double>::infinity())};
  // The box of every Bezier piece's control points, read straight from the Bezier form's net,
  // whose disjoint blocks of `order` points per span are the pieces (bezier_pieces), in the
  // pieces' order, so that ties (+0 and -0) resolve as a box over the pieces would: without
  // building a spline per piece (350k of them for the filleted teapot), and of the first k
  // coordinates only (knot insertion maps every coordinate alike, and apart).
  TensorSpline<P> b = [&] {
    if (k == s.dim()) return s;
    std::vector<double> pts(static_cast<std::size_t>(s.size()) * static_cast<std::size_t>(k));
    for (int r = 0; r < s.size(); ++r) std::copy_n(s.point(r).data(), k, pts.data() + static_cast<std::ptrdiff_t>(r) * k);
    return TensorSpline<P>(s.knot_vectors(), k, std::move(pts), s.weights());
  }();
  b = to_bezier_form(b);
  std::array<int, P> spans{}, orders = b.orders();
  int total = 1;
  for (int d = 0; d < P; ++d) {
    const auto dd = static_cast<std::size_t>(d);
    spans[dd] = static_cast<int>(b.knots(d).breakpoints().size()) - 1;
    total *= spans[dd];
  }
  int n = 1;
  for (int d = 0; d < P; ++d) n *= orders[static_cast<std::size_t>(d)];
  for (int e = 0; e < total; ++e) {
    const auto el = detail::piece_element<P>(e, spans);
    for (int r = 0; r < n; ++r) {
      const auto src = detail::piece_point<P>(el, r, orders);
      const auto p = b.point(b.row(src));
      for (int h = 0; h < k; ++h) {
        const auto hh = static_cast<std::size_t>(h);
        box[0][hh] = std::min(box[0][hh], p[hh]);
        box[1][hh] = std::max(box[1][hh], p[hh]);
      }
    }
  }
  return box;
}

template TensorSpline<0 + 1> iso(const TensorSpline<2>&, int, double);
template TensorSpline<2> iso(const TensorSpline<3>&, int, double);
template std::array<std::vector<double>, 2> bounding_box(const TensorSpline<1>&, int);
template std::array<std::vector<double>, 2> bounding_box(const TensorSpline<2>&, int);
template std::array<std::vector<double>, 2> bounding_box(const TensorSpline<3>&, int);

}  // namespace trivox::spline
