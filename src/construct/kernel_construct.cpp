#include "trivox/construct/kernel_construct.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include <Eigen/Dense>

#include "trivox/error.hpp"
#include "trivox/spline/calculus.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::construct {

using spline::TensorSpline;

namespace {

// ---------------------------------------------------------------------------------------------
// det J per Bezier piece, with the exact Bernstein product: c_k = sum_{i+j=k} C(m,i) C(n,j) /
// C(m+n,k) a_i b_j per direction. Convex weights, no collocation: stable at the high degrees that
// the paper's degree raising reaches (det J of degree 80 for quadratic ruling raised to 40).

/// A scalar tensor Bezier piece: coefficients, first direction fastest, degrees per direction.
template <int P>
struct Bern {
  std::array<int, P> deg{};
  std::vector<double> c;

  int count(int d) const { return deg[static_cast<std::size_t>(d)] + 1; }
};

std::vector<double> binomials(int n) {
  std::vector<double> b(static_cast<std::size_t>(n + 1), 1.0);
  for (int k = 1; k <= n; ++k) b[static_cast<std::size_t>(k)] = b[static_cast<std::size_t>(k - 1)] * (n - k + 1) / k;
  return b;
}

template <int P>
Bern<P> bern_product(const Bern<P>& a, const Bern<P>& b) {
  Bern<P> r;
  std::array<std::vector<double>, P> ba, bb, br;
  std::size_t total = 1;
  for (int d = 0; d < P; ++d) {
    const auto dd = static_cast<std::size_t>(d);
    r.deg[dd] = a.deg[dd] + b.deg[dd];
    ba[dd] = binomials(a.deg[dd]);
    bb[dd] = binomials(b.deg[dd]);
    br[dd] = binomials(r.deg[dd]);
    total *= static_cast<std::size_t>(r.deg[dd] + 1);
  }
  r.c.assign(total, 0.0);
  const std::size_t na = a.c.size(), nb = b.c.size();
  for (std::size_t i = 0; i < na; ++i) {
    std::array<int, P> ii{};
    std::size_t rest = i;
    double wa = a.c[i];
    for (int d = 0; d < P; ++d) {
      const auto dd = static_cast<std::size_t>(d);
      ii[dd] = static_cast<int>(rest % static_cast<std::size_t>(a.count(d)));
      rest /= static_cast<std::size_t>(a.count(d));
      wa *= ba[dd][static_cast<std::size_t>(ii[dd])];
    }
    if (wa == 0.0) continue;
    for (std::size_t j = 0; j < nb; ++j) {
      std::size_t rj = j, row = 0, stride = 1;
      double w = wa * b.c[j];
      for (int d = 0; d < P; ++d) {
        const auto dd = static_cast<std::size_t>(d);
        const int jj = static_cast<int>(rj % static_cast<std::size_t>(b.count(d)));
        rj /= static_cast<std::size_t>(b.count(d));
        w *= bb[dd][static_cast<std::size_t>(jj)];
        row += static_cast<std::size_t>(ii[dd] + jj) * stride;
        stride *= static_cast<std::size_t>(r.deg[dd] + 1);
      }
      r.c[row] += w;
    }
  }
  // Divide by C(m+n, k) per direction.
  for (std::size_t g = 0; g < total; ++g) {
    std::size_t rest = g;
    double w = 1.0;
    for (int d = 0; d < P; ++d) {
      const auto dd = static_cast<std::size_t>(d);
      w *= br[dd][rest % static_cast<std::size_t>(r.deg[dd] + 1)];
      rest /= static_cast<std::size_t>(r.deg[dd] + 1);
    }
    r.c[g] /= w;
  }
  return r;
}

template <int P>
Bern<P> bern_add(Bern<P> a, const Bern<P>& b, double scale) {
  for (std::size_t i = 0; i < a.c.size(); ++i) a.c[i] += scale * b.c[i];
  return a;
}

/// Coordinate h of the partial derivative along d of a Bezier piece (Bezier form, its own
/// domain): (degree / width) times the differences.
template <int P>
Bern<P> bern_derivative(const TensorSpline<P>& piece, int d, int h) {
  Bern<P> r;
  for (int e = 0; e < P; ++e) r.deg[static_cast<std::size_t>(e)] = piece.count(e) - 1 - (e == d ? 1 : 0);
  const int p = piece.count(d) - 1;
  const double f = p / (piece.domain(d)[1] - piece.domain(d)[0]);
  std::size_t total = 1;
  for (int e = 0; e < P; ++e) total *= static_cast<std::size_t>(r.count(e));
  r.c.resize(total);
  for (std::size_t g = 0; g < total; ++g) {
    typename TensorSpline<P>::Index i{};
    std::size_t rest = g;
    for (int e = 0; e < P; ++e) {
      i[static_cast<std::size_t>(e)] = static_cast<int>(rest % static_cast<std::size_t>(r.count(e)));
      rest /= static_cast<std::size_t>(r.count(e));
    }
    auto j = i;
    ++j[static_cast<std::size_t>(d)];
    r.c[g] = f * (piece.point(piece.row(j))[static_cast<std::size_t>(h)] - piece.point(piece.row(i))[static_cast<std::size_t>(h)]);
  }
  return r;
}

/// det J of one Bezier piece as a Bezier piece on the same domain.
template <int P>
TensorSpline<P> piece_determinant(const TensorSpline<P>& x) {
  Bern<P> det;
  if constexpr (P == 2) {
    det = bern_add(bern_product(bern_derivative(x, 0, 0), bern_derivative(x, 1, 1)),
                   bern_product(bern_derivative(x, 1, 0), bern_derivative(x, 0, 1)), -1.0);
  } else {
    std::array<Bern<3>, 3> du, dv, dw;
    for (int h = 0; h < 3; ++h) {
      du[static_cast<std::size_t>(h)] = bern_derivative(x, 0, h);
      dv[static_cast<std::size_t>(h)] = bern_derivative(x, 1, h);
      dw[static_cast<std::size_t>(h)] = bern_derivative(x, 2, h);
    }
    auto cross = [&](int a, int b) {
      return bern_add(bern_product(dv[static_cast<std::size_t>(a)], dw[static_cast<std::size_t>(b)]),
                      bern_product(dv[static_cast<std::size_t>(b)], dw[static_cast<std::size_t>(a)]), -1.0);
    };
    det = bern_add(bern_add(bern_product(du[0], cross(1, 2)), bern_product(du[1], cross(2, 0)), 1.0),
                   bern_product(du[2], cross(0, 1)), 1.0);
  }
  std::array<spline::KnotVector, P> kv;
  for (int d = 0; d < P; ++d)
    kv[static_cast<std::size_t>(d)] = spline::KnotVector::bezier(det.count(d), x.domain(d)[0], x.domain(d)[1]);
  return TensorSpline<P>(std::move(kv), 1, std::move(det.c));
}

template <int P>
typename TensorSpline<P>::Params corner_params(const TensorSpline<P>& s, int c) {
  typename TensorSpline<P>::Params t{};
  for (int d = 0; d < P; ++d) t[static_cast<std::size_t>(d)] = s.domain(d)[(c >> d) & 1];
  return t;
}

// ---------------------------------------------------------------------------------------------
// Alg. 1 steps.

template <int P>
TensorSpline<P> add_dof(const TensorSpline<P>& s0, AddDof how, int i) {
  if (i == 0) return s0;
  TensorSpline<P> s = s0;
  for (int d = 0; d < P; ++d) s = how == AddDof::refine ? spline::refine_uniform(s, d, i) : spline::elevate(s, d, i);
  return s;
}

template <int P>
bool interior(const TensorSpline<P>& s, const typename TensorSpline<P>::Index& i) {
  for (int d = 0; d < P; ++d)
    if (i[static_cast<std::size_t>(d)] == 0 || i[static_cast<std::size_t>(d)] == s.count(d) - 1) return false;
  return true;
}

/// Unit axes for the Sec. 6 grid: from the mean of the first to the mean of the last layer of
/// control points per direction, when they form a frame of the boundary's orientation; the
/// coordinate axes otherwise (the last one flipped for orientation -1).
template <int P>
std::array<Eigen::Matrix<double, P, 1>, P> grid_axes(const TensorSpline<P>& s, int orientation) {
  using Vec = Eigen::Matrix<double, P, 1>;
  std::array<Vec, P> axes;
  axes.fill(Vec::Zero());
  Eigen::Matrix<double, P, P> frame = Eigen::Matrix<double, P, P>::Zero();
  for (int d = 0; d < P; ++d) {
    Vec first = Vec::Zero(), last = Vec::Zero();
    int nf = 0, nl = 0;
    for (int r = 0; r < s.size(); ++r) {
      const auto i = s.multi_index(r);
      Vec p;
      for (int h = 0; h < P; ++h) p[h] = s.point(r)[static_cast<std::size_t>(h)];
      if (i[static_cast<std::size_t>(d)] == 0) first += p, ++nf;
      if (i[static_cast<std::size_t>(d)] == s.count(d) - 1) last += p, ++nl;
    }
    Vec a = last / nl - first / nf;
    axes[static_cast<std::size_t>(d)] = a.norm() > 0 ? Vec(a.normalized()) : Vec::Zero();
    frame.col(d) = axes[static_cast<std::size_t>(d)];
  }
  if (!(frame.determinant() * orientation > 0.1)) {
    for (int d = 0; d < P; ++d) axes[static_cast<std::size_t>(d)] = Vec::Unit(d);
    axes[P - 1] *= orientation;
  }
  return axes;
}

/// Alg. 1 line 16 (and Sec. 6 with width > 0): the interior control points' geometric
/// coordinates set to K, or to a uniform grid `width` wide centred at K.
template <int P>
void move_interior(TensorSpline<P>& s, const std::array<double, P>& k, double width, int orientation) {
  using Vec = Eigen::Matrix<double, P, 1>;
  std::array<Vec, P> axes;
  axes.fill(Vec::Zero());
  if (width > 0) axes = grid_axes(s, orientation);
  for (int r = 0; r < s.size(); ++r) {
    const auto i = s.multi_index(r);
    if (!interior(s, i)) continue;
    Vec p;
    for (int h = 0; h < P; ++h) p[h] = k[static_cast<std::size_t>(h)];
    if (width > 0)
      for (int d = 0; d < P; ++d) {
        const int m = s.count(d) - 2;  // interior points along d: indices 1..m
        if (m > 1) p += width * ((i[static_cast<std::size_t>(d)] - 1.0) / (m - 1) - 0.5) * axes[static_cast<std::size_t>(d)];
      }
    auto q = s.point(r);
    for (int h = 0; h < P; ++h) q[static_cast<std::size_t>(h)] = p[h];
  }
}

template <int P>
using KernelOf = std::conditional_t<P == 2, geom::PlanarKernel, geom::SpatialKernel>;

/// det J of s with every interior control point at K (plus the Sec. 6 offsets for width > 0)
/// is affine in K (the terms with K twice are cross products of K with itself). Per Bezier
/// piece, one spline with P + 1 coordinates per coefficient: (D_0, G_1, .., G_P), det J(K) =
/// D_0 + sum_d K_d G_d, from s with its interior at 0 and at each unit vector.
template <int P>
std::vector<TensorSpline<P>> affine_determinant(const TensorSpline<P>& s, double width, int orientation) {
  std::array<std::vector<TensorSpline<P>>, P + 1> pieces;
  for (int d = 0; d <= P; ++d) {
    std::array<double, P> k{};
    if (d > 0) k[static_cast<std::size_t>(d - 1)] = 1.0;
    TensorSpline<P> x = s;
    move_interior<P>(x, k, width, orientation);
    pieces[static_cast<std::size_t>(d)] = spline::bezier_pieces(x);
  }
  std::vector<TensorSpline<P>> out;
  for (std::size_t j = 0; j < pieces[0].size(); ++j) {
    std::array<TensorSpline<P>, P + 1> det;
    for (int d = 0; d <= P; ++d) det[static_cast<std::size_t>(d)] = piece_determinant(pieces[static_cast<std::size_t>(d)][j]);
    const int n = det[0].size();
    std::vector<double> pts(static_cast<std::size_t>(n * (P + 1)));
    for (int r = 0; r < n; ++r) {
      const double c0 = det[0].point(r)[0];
      pts[static_cast<std::size_t>(r * (P + 1))] = c0;
      for (int d = 1; d <= P; ++d)
        pts[static_cast<std::size_t>(r * (P + 1) + d)] = det[static_cast<std::size_t>(d)].point(r)[0] - c0;
    }
    out.emplace_back(det[0].knot_vectors(), P + 1, std::move(pts));
  }
  return out;
}

/// The constraints a piece of the affine det J puts on K inside the kernel (vertices `verts`):
/// none when every coefficient has the sign `orientation` (within tau) at every vertex; else
/// the piece halved in every direction, up to `levels` times; at the last level, one
/// half-space per coefficient that can have the wrong sign. False when some coefficient has
/// the wrong sign at every vertex (no K in the kernel can satisfy it).
template <int P>
bool collect_constraints(const TensorSpline<P>& piece, int levels, const std::vector<std::array<double, P>>& verts,
                         int orientation, double tau, std::vector<std::array<double, P + 1>>& out) {
  bool fine = true;
  for (int r = 0; r < piece.size() && fine; ++r) {
    const auto c = piece.point(r);
    for (const auto& v : verts) {
      double val = c[0];
      for (int d = 0; d < P; ++d) val += c[static_cast<std::size_t>(d + 1)] * v[static_cast<std::size_t>(d)];
      if (orientation * val < -tau) {
        fine = false;
        break;
      }
    }
  }
  if (fine) return true;
  if (levels > 0) {
    std::vector<TensorSpline<P>> parts{piece};
    for (int d = 0; d < P; ++d) {
      std::vector<TensorSpline<P>> next;
      for (const auto& x : parts) {
        auto [a, b] = spline::split(x, d, 0.5 * (x.domain(d)[0] + x.domain(d)[1]));
        next.push_back(std::move(a));
        next.push_back(std::move(b));
      }
      parts = std::move(next);
    }
    for (const auto& x : parts)
      if (!collect_constraints<P>(x, levels - 1, verts, orientation, tau, out)) return false;
    return true;
  }
  for (int r = 0; r < piece.size(); ++r) {
    const auto c = piece.point(r);
    double hi = -HUGE_VAL, lo = HUGE_VAL;
    for (const auto& v : verts) {
      double val = c[0];
      for (int d = 0; d < P; ++d) val += c[static_cast<std::size_t>(d + 1)] * v[static_cast<std::size_t>(d)];
      hi = std::max(hi, orientation * val);
      lo = std::min(lo, orientation * val);
    }
    if (lo >= -tau) continue;
    if (hi < -tau) return false;
    std::array<double, P + 1> h{};
    for (int d = 0; d < P; ++d) h[static_cast<std::size_t>(d)] = orientation * c[static_cast<std::size_t>(d + 1)];
    h[P] = orientation * c[0] + tau;
    out.push_back(h);
  }
  return true;
}

/// KernelPoint::fitted: the centroid of the part of the kernel where every (subdivided) Bezier
/// coefficient of det J has the boundary's sign, when it has positive measure.
template <int P>
std::optional<std::array<double, P>> fitted_point(const TensorSpline<P>& s, const KernelOf<P>& kern,
                                                  const std::array<double, P>& centroid, double width, int orientation,
                                                  int levels) {
  const auto pieces = affine_determinant(s, width, orientation);
  // The scale of det J at the centroid, for the same relative tolerance as jacobian_nonnegative.
  double scale = 0.0;
  for (const auto& x : pieces)
    for (int r = 0; r < x.size(); ++r) {
      const auto c = x.point(r);
      double val = c[0];
      for (int d = 0; d < P; ++d) val += c[static_cast<std::size_t>(d + 1)] * centroid[static_cast<std::size_t>(d)];
      scale = std::max(scale, std::abs(val));
    }
  const double tau = 1e-9 * scale;
  std::vector<std::array<double, P + 1>> constraints;
  for (const auto& x : pieces)
    if (!collect_constraints<P>(x, std::max(0, levels), kern.vertices, orientation, tau, constraints)) return std::nullopt;
  const auto region = geom::restrict_kernel(kern, constraints);
  if (region.empty()) return std::nullopt;
  return region.centroid;
}

template <int P>
bool accepted(const TensorSpline<P>& s, int orientation, const KernelConstructOptions& o) {
  if (o.acceptance == Acceptance::positive) {
    const auto r = geom::check_validity(s, o.validity);
    return r.verdict == geom::Validity::valid && r.orientation == orientation;
  }
  return jacobian_nonnegative(s, orientation, o.validity);
}

KernelConstructOptions with_coords(KernelConstructOptions o, int coords) {
  if (o.match.geometry_coords < 0) o.match.geometry_coords = coords;
  return o;
}

void require_count(KernelOp op, std::size_t got, std::initializer_list<std::size_t> allowed, const char* what) {
  for (std::size_t a : allowed)
    if (got == a) return;
  std::string want;
  for (std::size_t a : allowed) want += (want.empty() ? "" : " or ") + std::to_string(a);
  throw Error(std::string(kernel_op_name(op)) + " of " + std::to_string(got) + " " + what + "; expected " + want);
}

}  // namespace

// ---------------------------------------------------------------------------------------------

const char* kernel_op_name(KernelOp op) noexcept {
  switch (op) {
    case KernelOp::boolean_sum: return "boolean_sum";
    case KernelOp::half_boolean_sum: return "half_boolean_sum";
    default: return "ruled";
  }
}

KernelOp kernel_op_from_name(std::string_view name) {
  for (KernelOp op : {KernelOp::boolean_sum, KernelOp::half_boolean_sum, KernelOp::ruled})
    if (name == kernel_op_name(op)) return op;
  throw Error("constructor \"" + std::string(name) + "\"; expected boolean_sum, half_boolean_sum or ruled");
}

template <int P>
bool jacobian_nonnegative(const TensorSpline<P>& s, int orientation, const geom::ValidityOptions& options) {
  if (s.rational())
    throw Error("a rational spline: its Jacobian determinant is not a polynomial; expected a polynomial B-spline");
  if (s.dim() < P)
    throw Error(std::to_string(s.dim()) + " coordinates per control point; expected at least " + std::to_string(P));
  std::vector<TensorSpline<P>> stack;
  for (const auto& piece : spline::bezier_pieces(s)) stack.push_back(piece_determinant(piece));
  double scale = 0.0, top = -HUGE_VAL;
  for (const auto& d : stack)
    for (double c : d.points()) scale = std::max(scale, std::abs(c)), top = std::max(top, orientation * c);
  const double tau = 1e-9 * scale;
  if (!(top > tau)) return false;  // zero everywhere, or of the other sign
  std::array<double, P> width{};
  for (int d = 0; d < P; ++d) width[static_cast<std::size_t>(d)] = s.domain(d)[1] - s.domain(d)[0];
  std::reverse(stack.begin(), stack.end());
  int pieces = 0;
  while (!stack.empty()) {
    TensorSpline<P> x = std::move(stack.back());
    stack.pop_back();
    ++pieces;
    double lo = HUGE_VAL;
    for (double c : x.points()) lo = std::min(lo, orientation * c);
    if (lo >= -tau) continue;
    for (int c = 0; c < (1 << P); ++c)
      if (orientation * x.eval(corner_params(x, c))[0] < -tau) return false;
    typename TensorSpline<P>::Params mid{};
    int dir = 0;
    double widest = -1.0;
    for (int d = 0; d < P; ++d) {
      const auto dom = x.domain(d);
      mid[static_cast<std::size_t>(d)] = 0.5 * (dom[0] + dom[1]);
      const double rel = (dom[1] - dom[0]) / width[static_cast<std::size_t>(d)];
      if (x.count(d) > 1 && rel > widest) widest = rel, dir = d;
    }
    if (orientation * x.eval(mid)[0] < -tau) return false;
    if (widest < options.min_width || pieces + static_cast<int>(stack.size()) >= options.max_pieces) return false;
    auto [first, second] = spline::split(x, dir, mid[static_cast<std::size_t>(dir)]);
    stack.push_back(std::move(second));
    stack.push_back(std::move(first));
  }
  return true;
}

template <int P>
KernelResult<P> kernel_based(const TensorSpline<P>& s0, const KernelConstructOptions& o) {
  KernelResult<P> r;
  r.spline = s0;
  const auto regular = geom::check_validity(s0, o.validity);
  if (regular.verdict == geom::Validity::valid) {
    r.regular_valid = r.valid = r.strictly_valid = true;
    return r;
  }
  // Alg. 1 lines 5-9: the kernel of S_0's boundary and its centroid.
  std::array<double, P> k{};
  int orientation = 0;
  double size = 0.0;
  KernelOf<P> kern;
  try {
    if constexpr (P == 2) {
      kern = geom::planar_kernel(s0, o.kernel);
      if (!kern.empty()) k = kern.centroid, r.kernel_measure = kern.area, size = std::sqrt(kern.area);
    } else {
      kern = geom::spatial_kernel(s0, o.kernel);
      if (!kern.empty()) k = kern.centroid, r.kernel_measure = kern.volume, size = std::cbrt(kern.volume);
    }
    orientation = kern.orientation;
  } catch (const Error& e) {
    r.reason = std::string("the regular construction is invalid and its boundary has no kernel (") + e.what() + ")";
    return r;
  }
  if (!(r.kernel_measure > 0.0)) {
    r.reason = "the regular construction is invalid and its boundary has no kernel point (the conservative kernel "
               "of Hong & Elber 2022 is empty)";
    return r;
  }
  r.kernel = k;
  // KernelPoint::fitted takes its point from a tighter kernel (planar: cheap; trivariates keep
  // `kernel`, as each 3-D refinement multiplies a face's constraints by four).
  KernelOf<P> fit_kern = kern;
  if constexpr (P == 2)
    if (o.kernel_point == KernelPoint::fitted && o.fit_kernel.refinements > o.kernel.refinements) {
      const auto tight = geom::planar_kernel(s0, o.fit_kernel);
      if (!tight.empty()) fit_kern = tight;
    }
  // Alg. 1 lines 10-20.
  const int max_dof = std::max(0, o.max_dof);
  for (int i = 0; i <= max_dof; ++i) {
    TensorSpline<P> s = add_dof(s0, o.add_dof, i);
    move_interior<P>(s, k, o.spread * size, orientation);
    r.iterations = i;
    r.point = k;
    r.fitted = false;
    r.spread_width = o.spread * size;
    bool ok = accepted(s, orientation, o);
    if (!ok && o.kernel_point == KernelPoint::fitted)
      if (const auto f = fitted_point<P>(s, fit_kern, k, o.spread * size, orientation, o.fit_subdivisions)) {
        move_interior<P>(s, *f, o.spread * size, orientation);
        ok = accepted(s, orientation, o);
        r.point = *f;
        r.fitted = true;
      }
    if (!ok && o.kernel_point == KernelPoint::fitted && o.retry_spread > 0 && o.spread != o.retry_spread) {
      // Sec. 6 as a last try at this iteration: the interior on a grid around the fitted point.
      const double width = o.retry_spread * size;
      if (const auto f = fitted_point<P>(s, fit_kern, k, width, orientation, o.fit_subdivisions)) {
        move_interior<P>(s, *f, width, orientation);
        ok = accepted(s, orientation, o);
        r.point = *f;
        r.fitted = true;
        r.spread_width = width;
      }
    }
    r.spline = std::move(s);
    if (ok) {
      r.valid = true;
      r.strictly_valid = o.acceptance == Acceptance::positive ||
                         geom::check_validity(r.spline, o.validity).verdict == geom::Validity::valid;
      return r;
    }
  }
  r.reason = "no " + std::string(o.acceptance == Acceptance::positive ? "positive" : "non-negative") +
             " Jacobian after moving the interior control points to the kernel point with 0.." +
             std::to_string(max_dof) + (o.add_dof == AddDof::refine ? " knots per span" : " degree raisings");
  return r;
}

Surface regular_construct(KernelOp op, std::span<const Curve> c, const KernelConstructOptions& options) {
  const auto o = with_coords(options, 2);
  switch (op) {
    case KernelOp::boolean_sum:
      require_count(op, c.size(), {4}, "curves (bottom, top, left, right)");
      return boolean_sum(c[0], c[1], c[2], c[3], o.match);
    case KernelOp::half_boolean_sum:
      require_count(op, c.size(), {2}, "curves (c1, c2)");
      return half_boolean_sum(c[0], c[1], o.match);
    default:
      require_count(op, c.size(), {2}, "curves (bottom, top)");
      return ruled(c[0], c[1], o.ruling_order);
  }
}

Trivariate regular_construct(KernelOp op, std::span<const Surface> s, const KernelConstructOptions& options) {
  const auto o = with_coords(options, 3);
  switch (op) {
    case KernelOp::boolean_sum:
      require_count(op, s.size(), {6}, "surfaces (faces u0 u1 v0 v1 w0 w1)");
      return boolean_sum(s, o.match);
    case KernelOp::half_boolean_sum:
      require_count(op, s.size(), {2, 3}, "surfaces");
      return s.size() == 2 ? half_boolean_sum(s[0], s[1], o.match) : half_boolean_sum(s[0], s[1], s[2], o.match);
    default:
      require_count(op, s.size(), {2}, "surfaces (s0, s1)");
      return ruled(s[0], s[1], o.ruling_order);
  }
}

KernelResult<2> kernel_construct(KernelOp op, std::span<const Curve> curves, const KernelConstructOptions& options) {
  return kernel_based(regular_construct(op, curves, options), options);
}

KernelResult<3> kernel_construct(KernelOp op, std::span<const Surface> surfaces, const KernelConstructOptions& options) {
  return kernel_based(regular_construct(op, surfaces, options), options);
}

template KernelResult<2> kernel_based(const TensorSpline<2>&, const KernelConstructOptions&);
template KernelResult<3> kernel_based(const TensorSpline<3>&, const KernelConstructOptions&);
template bool jacobian_nonnegative(const TensorSpline<2>&, int, const geom::ValidityOptions&);
template bool jacobian_nonnegative(const TensorSpline<3>&, int, const geom::ValidityOptions&);

}  // namespace trivox::construct
