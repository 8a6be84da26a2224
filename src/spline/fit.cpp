#include "trivox/spline/fit.hpp"

#include "banded_qr.hpp"

#include <Eigen/Dense>
#include <Eigen/Jacobi>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numeric>
#include <string>
#include <utility>

#include "trivox/error.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::spline {

namespace {

using Matrix = Eigen::MatrixXd;
using SparseMatrix = Eigen::SparseMatrix<double>;
using Eigen::Index;
using detail::BandedQR;
using detail::RankReport;

std::size_t sz(long long i) { return static_cast<std::size_t>(i); }
std::string str(long long i) { return std::to_string(i); }

std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

std::string interval(double a, double b) { return "[" + num(a) + ", " + num(b) + "]"; }

double max_abs(std::span<const double> x) {
  double m = 0.0;
  for (double v : x) m = std::max(m, std::abs(v));
  return m;
}

// ---------------------------------------------------------------------------------------------
// Input checks

void check_dim(const std::string& where, int dim) {
  if (dim < 1) throw Error(where + ": " + str(dim) + " coordinates per point; expected at least 1");
}

void check_finite(const std::string& where, const std::string& what, std::span<const double> x, int dim) {
  for (std::size_t i = 0; i < x.size(); ++i)
    if (!std::isfinite(x[i]))
      throw Error(where + ": " + what + " " + str(static_cast<long long>(i / sz(dim))) + " coordinate " +
                  str(static_cast<long long>(i % sz(dim))) + " is " + num(x[i]) + "; expected a finite number");
}

void check_values(const std::string& where, std::span<const double> values, std::size_t count, int dim) {
  if (values.size() != count * sz(dim))
    throw Error(where + ": " + str(static_cast<long long>(values.size())) + " values for " +
                str(static_cast<long long>(count)) + " parameters of " + str(dim) + " coordinates; expected " +
                str(static_cast<long long>(count * sz(dim))));
  check_finite(where, "value", values, dim);
}

void check_params(const std::string& where, const std::string& name, std::span<const double> t,
                  const KnotVector& kv) {
  for (std::size_t j = 0; j < t.size(); ++j)
    if (!kv.contains(t[j]))
      throw Error(where + ": " + name + " " + str(static_cast<long long>(j)) + " is " + num(t[j]) +
                  "; expected a value in the knot domain " + interval(kv.front(), kv.back()));
}

void check_knots(const std::string& where, const KnotVector& knots, const std::string& name) {
  if (knots.order() < 1) throw Error(where + ": the " + name + " knot vector is empty; expected a valid knot vector");
}

void check_surface_knots(const std::string& where, const std::array<KnotVector, 2>& knots) {
  check_knots(where, knots[0], "u");
  check_knots(where, knots[1], "v");
}

// ---------------------------------------------------------------------------------------------
// Collocation matrices

/// The collocation matrix of a knot vector at parameters t, row by row: row j holds the `order`
/// basis values at t_j, those of columns first[j] .. first[j] + order - 1.
struct BasisRows {
  int order = 0;
  std::vector<int> first;
  std::vector<double> values;

  std::size_t rows() const noexcept { return first.size(); }
  double value(std::size_t j, int k) const noexcept { return values[j * sz(order) + sz(k)]; }
  /// First and last column with a non-zero value in row j (the non-zero set is an interval).
  std::pair<int, int> nonzero(std::size_t j) const noexcept {
    int lo = 0, hi = order - 1;
    while (lo < hi && value(j, lo) == 0.0) ++lo;
    while (hi > lo && value(j, hi) == 0.0) --hi;
    return {first[j] + lo, first[j] + hi};
  }
};

BasisRows basis_rows(const KnotVector& kv, std::span<const double> t) {
  BasisRows b;
  b.order = kv.order();
  b.first.resize(t.size());
  b.values.resize(t.size() * sz(b.order));
  int span = kv.order() - 1;
  for (std::size_t j = 0; j < t.size(); ++j) {
    span = kv.find_span(t[j], span);
    kv.basis(span, t[j], b.values.data() + j * sz(b.order));
    b.first[j] = span - b.order + 1;
  }
  return b;
}

/// Which columns (control points along one direction) are unknowns: index[l] is l's position
/// among the free columns, or -1 when l is pinned.
struct Columns {
  std::vector<int> index;
  int free = 0;
};

Columns free_columns(const std::vector<bool>& pinned) {
  Columns c;
  c.index.resize(pinned.size());
  for (std::size_t l = 0; l < pinned.size(); ++l) c.index[l] = pinned[l] ? -1 : c.free++;
  return c;
}

Columns all_columns(int n) { return free_columns(std::vector<bool>(sz(n), false)); }

/// The collocation matrix restricted to the free columns (renumbered).
SparseMatrix matrix(const BasisRows& b, const Columns& cols) {
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(b.values.size());
  for (std::size_t j = 0; j < b.rows(); ++j)
    for (int k = 0; k < b.order; ++k) {
      const int c = cols.index[sz(b.first[j] + k)];
      if (c >= 0 && b.value(j, k) != 0.0) entries.emplace_back(static_cast<Index>(j), c, b.value(j, k));
    }
  SparseMatrix A(static_cast<Index>(b.rows()), cols.free);
  A.setFromTriplets(entries.begin(), entries.end());
  A.makeCompressed();
  return A;
}

/// The tensor collocation matrix of scattered data (row j: N_i(u_j) N_k(v_j)) restricted to the
/// free control points, column cu.index[i] + cu.free * cv.index[k].
SparseMatrix tensor_matrix(const BasisRows& bu, const BasisRows& bv, const Columns& cu, const Columns& cv) {
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(bu.rows() * sz(bu.order) * sz(bv.order));
  for (std::size_t j = 0; j < bu.rows(); ++j)
    for (int kv = 0; kv < bv.order; ++kv) {
      const int cj = cv.index[sz(bv.first[j] + kv)];
      if (cj < 0 || bv.value(j, kv) == 0.0) continue;
      for (int ku = 0; ku < bu.order; ++ku) {
        const int ci = cu.index[sz(bu.first[j] + ku)];
        const double w = bu.value(j, ku) * bv.value(j, kv);
        if (ci >= 0 && w != 0.0) entries.emplace_back(static_cast<Index>(j), ci + cu.free * cj, w);
      }
    }
  SparseMatrix A(static_cast<Index>(bu.rows()), cu.free * cv.free);
  A.setFromTriplets(entries.begin(), entries.end());
  A.makeCompressed();
  return A;
}

// ---------------------------------------------------------------------------------------------
// Solvability and the solver

/// Number of parameters at which basis function l is non-zero.
long long support_count(const BasisRows& b, int l) {
  long long n = 0;
  for (std::size_t j = 0; j < b.rows(); ++j) {
    const auto [lo, hi] = b.nonzero(j);
    n += (lo <= l && l <= hi) ? 1 : 0;
  }
  return n;
}

/// The Schoenberg-Whitney condition on the free columns: the collocation matrix has full column
/// rank iff the sorted parameters hold a subsequence t_(j_0) < t_(j_1) < ... with
/// N_l(t_(j_l)) != 0 for the free l. The non-zero column ranges are monotone in t, so matching
/// each free column greedily to the first unused parameter whose range holds it decides this.
void check_schoenberg_whitney(const std::string& where, const std::string& direction, const KnotVector& kv,
                              std::span<const double> t, const BasisRows& b, const Columns& cols) {
  std::vector<std::size_t> by_t(t.size());
  std::iota(by_t.begin(), by_t.end(), std::size_t{0});
  std::stable_sort(by_t.begin(), by_t.end(), [&](std::size_t x, std::size_t y) { return t[x] < t[y]; });
  std::size_t j = 0;
  for (int l = 0; l < static_cast<int>(cols.index.size()); ++l) {
    if (cols.index[sz(l)] < 0) continue;
    while (j < by_t.size() && b.nonzero(by_t[j]).second < l) ++j;
    if (j < by_t.size() && b.nonzero(by_t[j]).first <= l) {
      // The subsequence must increase strictly: equal parameters give equal rows.
      const double taken = t[by_t[j]];
      while (j < by_t.size() && t[by_t[j]] == taken) ++j;
      continue;
    }
    throw Error(where + ": control point " + str(l) + direction + " is not determined by the data: its basis function " +
                "(support " + interval(kv[l], kv[l + kv.order()]) + ") is non-zero at " +
                str(support_count(b, l)) + " of " + str(static_cast<long long>(t.size())) +
                " parameters, none left after the control points before it took one each; expected the "
                "Schoenberg-Whitney condition (sorted parameters t_(0) < t_(1) < ... with N_l(t_(l)) != 0 for "
                "every fitted control point l): more parameters there, or knots adapted to the parameters "
                "(interpolation_knots, fitting_knots)");
  }
}

/// Row indices in non-decreasing order of `first`.
std::vector<std::size_t> by_first(const std::vector<int>& first) {
  std::vector<std::size_t> order(first.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return first[x] < first[y]; });
  return order;
}

/// The least-squares solution over the free columns of a 1-D collocation system:
/// cols.free x rhs.cols(), rows in free-column order.
Matrix solve_1d(const BasisRows& b, const Columns& cols, const Matrix& rhs, const RankReport& report) {
  if (cols.free == 0 || rhs.cols() == 0) return Matrix::Zero(cols.free, rhs.cols());
  // Row j's coefficients on the free columns, from column first(j) on (-1: none free).
  std::vector<double> a(sz(b.order));
  const auto row = [&](std::size_t j) {
    std::fill(a.begin(), a.end(), 0.0);
    int first = -1;
    for (int k = 0; k < b.order; ++k) {
      const int c = cols.index[sz(b.first[j] + k)];
      if (c < 0) continue;
      if (first < 0) first = c;
      a[sz(c - first)] = b.value(j, k);
    }
    return first;
  };
  std::vector<int> firsts(b.rows());
  for (std::size_t j = 0; j < b.rows(); ++j) firsts[j] = row(j);
  BandedQR qr(cols.free, b.order, rhs.cols());
  for (const std::size_t j : by_first(firsts))
    if (row(j) >= 0) qr.add_row(firsts[j], a, rhs.row(static_cast<Index>(j)));
  return qr.solve(report);
}

/// The least-squares solution over the free control points of scattered tensor data (row j:
/// N_i(u_j) N_k(v_j)): (cu.free * cv.free) x rhs.cols(), row cu.index[i] + cu.free * cv.index[k].
Matrix solve_tensor(const BasisRows& bu, const BasisRows& bv, const Columns& cu, const Columns& cv,
                    const Matrix& rhs, const RankReport& report) {
  const int n = cu.free * cv.free;
  if (n == 0 || rhs.cols() == 0) return Matrix::Zero(n, rhs.cols());
  // Number the unknowns with the direction that gives the smaller band fastest.
  const int wu = bu.order + cu.free * (bv.order - 1), wv = bv.order + cv.free * (bu.order - 1);
  const bool u_fast = wu <= wv;
  const auto column = [&](int ci, int cj) { return u_fast ? ci + cu.free * cj : cj + cv.free * ci; };
  const int w = std::min(wu, wv);
  std::vector<std::pair<int, double>> entries;
  std::vector<double> a(sz(w));
  // Row j's coefficients on the free columns, from column first(j) on (-1: none free).
  const auto row = [&](std::size_t j) {
    entries.clear();
    for (int kv = 0; kv < bv.order; ++kv)
      for (int ku = 0; ku < bu.order; ++ku) {
        const int ci = cu.index[sz(bu.first[j] + ku)], cj = cv.index[sz(bv.first[j] + kv)];
        if (ci >= 0 && cj >= 0) entries.emplace_back(column(ci, cj), bu.value(j, ku) * bv.value(j, kv));
      }
    if (entries.empty()) return -1;
    const int first = std::min_element(entries.begin(), entries.end())->first;
    std::fill(a.begin(), a.end(), 0.0);
    for (const auto& [c, value] : entries) a[sz(c - first)] = value;
    return first;
  };
  std::vector<int> firsts(bu.rows());
  for (std::size_t j = 0; j < bu.rows(); ++j) firsts[j] = row(j);
  BandedQR qr(n, w, rhs.cols());
  for (const std::size_t j : by_first(firsts))
    if (row(j) >= 0) qr.add_row(firsts[j], a, rhs.row(static_cast<Index>(j)));
  const Matrix X = qr.solve({report.where, report.kind, report.expected, [&](int c) {
                               const int ci = u_fast ? c % cu.free : c / cv.free;
                               const int cj = u_fast ? c / cu.free : c % cv.free;
                               return report.unknown(ci + cu.free * cj);
                             }});
  if (u_fast) return X;
  Matrix out(n, X.cols());
  for (int ci = 0; ci < cu.free; ++ci)
    for (int cj = 0; cj < cv.free; ++cj) out.row(ci + cu.free * cj) = X.row(column(ci, cj));
  return out;
}

/// The name of free column c of a direction: "control point l" (+ suffix).
std::function<std::string(int)> name_free(const Columns& cols, std::string suffix) {
  return [&cols, suffix](int c) {
    const auto it = std::find(cols.index.begin(), cols.index.end(), c);
    return "control point " + str(it - cols.index.begin()) + suffix;
  };
}

const char* const clustered =
    "parameters far enough apart to be told apart numerically (the Schoenberg-Whitney condition holds, "
    "but the system is too ill-conditioned)";

/// m x dim data, row j = values[j*dim ..].
Matrix data_rows(std::span<const double> values, std::size_t m, int dim) {
  Matrix Y(static_cast<Index>(m), dim);
  for (std::size_t j = 0; j < m; ++j)
    for (int c = 0; c < dim; ++c) Y(static_cast<Index>(j), c) = values[j * sz(dim) + sz(c)];
  return Y;
}

// ---------------------------------------------------------------------------------------------
// Curves

/// The pinned control points as an n x dim matrix (zero rows where free); marks them in `pinned`.
Matrix curve_pins(const std::string& where, const CurvePins& pins, int n, int dim, std::vector<bool>& pinned) {
  pinned.assign(sz(n), false);
  Matrix P = Matrix::Zero(n, dim);
  if (pins.points.size() != pins.rows.size() * sz(dim))
    throw Error(where + ": " + str(static_cast<long long>(pins.points.size())) + " pinned values for " +
                str(static_cast<long long>(pins.rows.size())) + " pinned control points; expected " +
                str(static_cast<long long>(pins.rows.size() * sz(dim))) + " (" + str(dim) + " per point)");
  check_finite(where, "pinned point", pins.points, dim);
  for (std::size_t r = 0; r < pins.rows.size(); ++r) {
    const int l = pins.rows[r];
    if (l < 0 || l >= n)
      throw Error(where + ": pinned control point index " + str(l) + "; expected an index in [0, " + str(n - 1) + "]");
    if (pinned[sz(l)])
      throw Error(where + ": control point " + str(l) + " pinned twice; expected distinct pinned indices");
    pinned[sz(l)] = true;
    for (int c = 0; c < dim; ++c) P(l, c) = pins.points[r * sz(dim) + sz(c)];
  }
  return P;
}

std::vector<double> to_points(const Matrix& net_rows) {
  std::vector<double> pts(sz(net_rows.size()));
  for (Index r = 0; r < net_rows.rows(); ++r)
    for (Index c = 0; c < net_rows.cols(); ++c) pts[sz(r * net_rows.cols() + c)] = net_rows(r, c);
  return pts;
}

Curve solve_curve(const std::string& where, std::span<const double> params, int dim, std::span<const double> values,
                  const KnotVector& knots, const CurvePins& pins) {
  check_dim(where, dim);
  check_knots(where, knots, "curve's");
  check_values(where, values, params.size(), dim);
  check_params(where, "parameter", params, knots);
  const int n = knots.size();
  std::vector<bool> pinned;
  Matrix net = curve_pins(where, pins, n, dim, pinned);
  const Columns cols = free_columns(pinned);
  if (params.size() < sz(cols.free))
    throw Error(where + ": " + str(static_cast<long long>(params.size())) + " parameters for " + str(cols.free) +
                " free control points; expected at least one parameter per free control point");
  const BasisRows b = basis_rows(knots, params);
  check_schoenberg_whitney(where, "", knots, params, b, cols);
  Matrix rhs = data_rows(values, params.size(), dim);
  if (!pins.empty()) rhs -= matrix(b, all_columns(n)) * net;
  const Matrix X = solve_1d(b, cols, rhs, {where, ErrorKind::failed, clustered, name_free(cols, "")});
  for (int l = 0; l < n; ++l)
    if (cols.index[sz(l)] >= 0) net.row(l) = X.row(cols.index[sz(l)]);
  return Curve({knots}, dim, to_points(net));
}

// ---------------------------------------------------------------------------------------------
// Surfaces: pinned boundary rows

const char* side_name(int s) {
  static constexpr const char* names[] = {"u0", "u1", "v0", "v1"};
  return names[s];
}

/// Control point (i, j) of entry k along side s.
std::array<int, 2> side_point(int s, int k, int nu, int nv) {
  switch (s) {
    case SurfacePins::u0: return {0, k};
    case SurfacePins::u1: return {nu - 1, k};
    case SurfacePins::v0: return {k, 0};
    default: return {k, nv - 1};
  }
}

/// True when the basis function of the first (at_back: last) control point is 1 at that end of
/// the domain, so that the spline there equals the end row of its control net.
bool interpolates_end(const KnotVector& kv, bool at_back) {
  const int p = kv.degree();
  const int from = at_back ? kv.size() : 1;
  const double end = at_back ? kv.back() : kv.front();
  for (int i = from; i < from + p; ++i)
    if (kv[i] != end) return false;
  return true;
}

/// The control points of boundary curve `c` of side s in the surface's space.
std::vector<double> boundary_curve_row(const std::string& where, int s, const Curve& c,
                                       const std::array<KnotVector, 2>& knots, int dim) {
  const std::string name = where + ": boundary curve " + side_name(s);
  const int along = s < 2 ? 1 : 0;  // the curve's parameter is v for u0/u1, u for v0/v1
  const KnotVector& target = knots[sz(along)];
  const KnotVector& across = knots[sz(1 - along)];
  const bool at_back = s % 2 == 1;
  const std::string dir = along == 0 ? "u" : "v";
  if (c.knots(0).order() < 1) throw Error(name + " is empty; expected a curve");
  if (c.dim() != dim)
    throw Error(name + " has " + str(c.dim()) + " coordinates; expected " + str(dim) + ", as the data");
  if (c.rational() && std::adjacent_find(c.weights().begin(), c.weights().end(), std::not_equal_to<>()) !=
                          c.weights().end())
    throw Error(name + " is rational with unequal weights; expected a polynomial curve (the fitted surface is "
                "polynomial)");
  if (c.knots(0).front() != target.front() || c.knots(0).back() != target.back())
    throw Error(name + " has domain " + interval(c.knots(0).front(), c.knots(0).back()) +
                "; expected the surface's " + dir + " domain " + interval(target.front(), target.back()) +
                " (reparametrize the curve)");
  if (!interpolates_end(across, at_back))
    throw Error(name + ": the surface's " + std::string(along == 0 ? "v" : "u") + " knots are not clamped at the " +
                (at_back ? "end" : "start") + "; expected knots that interpolate the boundary row there");
  const Curve poly({c.knots(0)}, dim, std::vector<double>(c.points().begin(), c.points().end()));
  try {
    const Curve in = to_space(poly, 0, target);
    return std::vector<double>(in.points().begin(), in.points().end());
  } catch (const Error& e) {
    throw Error(name + " (order " + str(c.knots(0).order()) + ", " + str(c.count(0)) +
                " control points) does not lie in the surface's " + dir + " space (order " + str(target.order()) +
                ", " + str(target.size()) + " control points): " + e.what(),
                ErrorKind::bad_input);
  }
}

std::vector<double> side_row(const std::string& where, const SurfacePins& pins, int s,
                             const std::array<KnotVector, 2>& knots, int dim) {
  const auto side = static_cast<SurfacePins::Side>(s);
  const auto& rows = pins.rows[sz(s)];
  if (pins.curves[sz(s)] && !rows.empty())
    throw Error(where + ": side " + side_name(s) + " pinned by both a curve and control rows; expected one");
  if (!pins.pinned(side)) return {};
  if (pins.curves[sz(s)]) return boundary_curve_row(where, s, *pins.curves[sz(s)], knots, dim);
  const int count = s < 2 ? knots[1].size() : knots[0].size();
  if (rows.size() != sz(count) * sz(dim))
    throw Error(where + ": " + str(static_cast<long long>(rows.size())) + " values for pinned row " + side_name(s) +
                "; expected " + str(count) + " control points x " + str(dim) + " coordinates");
  check_finite(where, std::string("pinned row ") + side_name(s) + " point", rows, dim);
  return rows;
}

/// The pinned control points of a surface: `points` is n_u x (n_v * dim) with entry
/// (i, j*dim + c), zero where free; whole rows i (pinned_u) and j (pinned_v) are pinned.
struct PinnedNet {
  Matrix points;
  std::vector<bool> pinned_u, pinned_v;
};

void place_side(const std::string& where, int s, const std::vector<double>& row, double tol, int dim,
                PinnedNet& net, std::vector<int>& owner) {
  const int nu = static_cast<int>(net.pinned_u.size()), nv = static_cast<int>(net.pinned_v.size());
  const int count = s < 2 ? nv : nu;
  for (int k = 0; k < count; ++k) {
    const auto [i, j] = side_point(s, k, nu, nv);
    int& who = owner[sz(i + nu * j)];
    for (int c = 0; c < dim; ++c) {
      const double value = row[sz(k) * sz(dim) + sz(c)];
      double& slot = net.points(i, j * dim + c);
      if (who >= 0 && !(std::abs(slot - value) <= tol))
        throw Error(where + ": pinned sides " + side_name(who) + " and " + side_name(s) + " disagree at control point (" +
                    str(i) + ", " + str(j) + ") coordinate " + str(c) + ": " + num(slot) + " vs " + num(value) +
                    "; expected boundary curves or rows that meet at their common corner");
      if (who < 0) slot = value;
    }
    if (who < 0) who = s;
  }
  auto& lines = s < 2 ? net.pinned_u : net.pinned_v;
  lines[s % 2 == 0 ? 0 : lines.size() - 1] = true;
}

PinnedNet pinned_net(const std::string& where, const SurfacePins& pins, const std::array<KnotVector, 2>& knots,
                     int dim) {
  const int nu = knots[0].size(), nv = knots[1].size();
  PinnedNet net{Matrix::Zero(nu, static_cast<Index>(nv) * dim), std::vector<bool>(sz(nu)),
                std::vector<bool>(sz(nv))};
  std::array<std::vector<double>, 4> rows;
  double scale = 0.0;
  for (int s = 0; s < 4; ++s) {
    rows[sz(s)] = side_row(where, pins, s, knots, dim);
    scale = std::max(scale, max_abs(rows[sz(s)]));
  }
  std::vector<int> owner(sz(nu) * sz(nv), -1);
  for (int s = 0; s < 4; ++s)
    if (!rows[sz(s)].empty()) place_side(where, s, rows[sz(s)], 1e-10 * scale, dim, net, owner);
  return net;
}

// ---------------------------------------------------------------------------------------------
// Surfaces: nets as matrices

/// A grid of n0 x n1 entries of dim values held as n0 x (n1*dim), entry (i, j*dim + c); swapped
/// to n1 x (n0*dim), so that a matrix acting on the rows acts along the other direction.
Matrix transpose_grid(const Matrix& G, int n0, int n1, int dim) {
  Matrix out(n1, static_cast<Index>(n0) * dim);
  for (int i = 0; i < n0; ++i)
    for (int j = 0; j < n1; ++j)
      for (int c = 0; c < dim; ++c) out(j, i * dim + c) = G(i, j * dim + c);
  return out;
}

/// values[(i + n0*j)*dim + c] as the n0 x (n1*dim) grid matrix.
Matrix grid_matrix(std::span<const double> values, int n0, int n1, int dim) {
  Matrix G(n0, static_cast<Index>(n1) * dim);
  for (int j = 0; j < n1; ++j)
    for (int i = 0; i < n0; ++i)
      for (int c = 0; c < dim; ++c) G(i, j * dim + c) = values[(sz(i) + sz(n0) * sz(j)) * sz(dim) + sz(c)];
  return G;
}

/// The inverse of grid_matrix.
std::vector<double> grid_points(const Matrix& G, int dim) {
  const auto n0 = static_cast<int>(G.rows());
  const auto n1 = static_cast<int>(G.cols() / dim);
  std::vector<double> out(sz(G.size()));
  for (int j = 0; j < n1; ++j)
    for (int i = 0; i < n0; ++i)
      for (int c = 0; c < dim; ++c) out[(sz(i) + sz(n0) * sz(j)) * sz(dim) + sz(c)] = G(i, j * dim + c);
  return out;
}

/// Grid matrix (n_u x n_v*dim) as rows of a (n_u*n_v) x dim matrix, row i + n_u*j.
Matrix net_rows(const Matrix& G, int dim) {
  const auto pts = grid_points(G, dim);
  return Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
      pts.data(), static_cast<Index>(pts.size()) / dim, dim);
}

void check_supports(const std::string& where, const std::array<KnotVector, 2>& knots, const BasisRows& bu,
                    const BasisRows& bv, const Columns& cu, const Columns& cv) {
  std::vector<long long> hits(sz(cu.free) * sz(cv.free), 0);
  for (std::size_t j = 0; j < bu.rows(); ++j) {
    const auto [ilo, ihi] = bu.nonzero(j);
    const auto [jlo, jhi] = bv.nonzero(j);
    for (int l = jlo; l <= jhi; ++l)
      for (int i = ilo; i <= ihi; ++i)
        if (cu.index[sz(i)] >= 0 && cv.index[sz(l)] >= 0) ++hits[sz(cu.index[sz(i)] + cu.free * cv.index[sz(l)])];
  }
  for (int l = 0; l < static_cast<int>(cv.index.size()); ++l)
    for (int i = 0; i < static_cast<int>(cu.index.size()); ++i) {
      if (cu.index[sz(i)] < 0 || cv.index[sz(l)] < 0) continue;
      if (hits[sz(cu.index[sz(i)] + cu.free * cv.index[sz(l)])] > 0) continue;
      const auto& ku = knots[0];
      const auto& kv = knots[1];
      throw Error(where + ": no data point lies where control point (" + str(i) + ", " + str(l) +
                  ") acts, u in " + interval(ku[i], ku[i + ku.order()]) + " x v in " +
                  interval(kv[l], kv[l + kv.order()]) +
                  "; expected data in the support of every fitted control point (more data, or fewer knots)");
    }
}


}  // namespace

// ---------------------------------------------------------------------------------------------
// Parameters and knots

std::vector<double> chord_length_params(std::span<const double> points, int dim, double exponent) {
  const std::string where = "chord_length_params";
  check_dim(where, dim);
  if (points.size() % sz(dim) != 0 || points.size() < 2 * sz(dim))
    throw Error(where + ": " + str(static_cast<long long>(points.size())) + " values; expected at least two points of " +
                str(dim) + " coordinates");
  if (!(exponent >= 0.0 && std::isfinite(exponent)))
    throw Error(where + ": exponent " + num(exponent) + "; expected a finite exponent >= 0 (1 chord length, 0.5 "
                "centripetal, 0 uniform)");
  check_finite(where, "point", points, dim);
  const std::size_t m = points.size() / sz(dim);
  std::vector<double> t(m, 0.0);
  for (std::size_t j = 1; j < m; ++j) {
    double d2 = 0.0;
    for (int c = 0; c < dim; ++c) {
      const double d = points[j * sz(dim) + sz(c)] - points[(j - 1) * sz(dim) + sz(c)];
      d2 += d * d;
    }
    t[j] = t[j - 1] + std::pow(std::sqrt(d2), exponent);
  }
  const double total = t.back();
  if (!(total > 0.0) || !std::isfinite(total))
    throw Error(where + ": the " + str(static_cast<long long>(m)) + " points have total length " + num(total) +
                "; expected points that are not all equal");
  for (double& x : t) x /= total;
  t.back() = 1.0;
  return t;
}

KnotVector interpolation_knots(std::span<const double> params, int order) {
  const std::string where = "interpolation_knots";
  if (order < 1) throw Error(where + ": order " + str(order) + "; expected an order (degree + 1) >= 1");
  if (params.size() < sz(order))
    throw Error(where + ": " + str(static_cast<long long>(params.size())) + " parameters for order " + str(order) +
                "; expected at least " + str(order));
  check_finite(where, "parameter", params, 1);
  std::vector<double> s(params.begin(), params.end());
  std::sort(s.begin(), s.end());
  const std::size_t m = s.size(), p = sz(order - 1);
  std::vector<double> k(p + 1, s.front());
  if (p == 0) {
    for (std::size_t j = 1; j < m; ++j) k.push_back(0.5 * (s[j - 1] + s[j]));
  } else {
    for (std::size_t j = 1; j + p < m; ++j) {  // NURBS Book eq. 9.8
      double sum = 0.0;
      for (std::size_t i = j; i < j + p; ++i) sum += s[i];
      k.push_back(sum / static_cast<double>(p));
    }
  }
  k.insert(k.end(), p + 1, s.back());
  try {
    return KnotVector(order, std::move(k));
  } catch (const Error& e) {
    throw e.within(where + " (parameters repeated or all equal?)");
  }
}

KnotVector fitting_knots(std::span<const double> params, int order, int count) {
  const std::string where = "fitting_knots";
  if (order < 1) throw Error(where + ": order " + str(order) + "; expected an order (degree + 1) >= 1");
  if (count < order || sz(count) > params.size())
    throw Error(where + ": " + str(count) + " control points for order " + str(order) + " and " +
                str(static_cast<long long>(params.size())) + " parameters; expected order <= count <= parameters");
  check_finite(where, "parameter", params, 1);
  std::vector<double> s(params.begin(), params.end());
  std::sort(s.begin(), s.end());
  const double d = static_cast<double>(s.size()) / static_cast<double>(count - order + 1);  // eq. 9.68
  // Eq. 9.69 puts knots on parameters when j*d is whole. Order 1 would then get empty spans,
  // so its knots move half a parameter down, between parameters (d = 1: the midpoints).
  const double shift = order == 1 ? 0.5 : 0.0;
  std::vector<double> k(sz(order), s.front());
  for (int j = 1; j <= count - order; ++j) {  // eq. 9.69
    const double x = j * d - shift;
    const auto i = static_cast<std::size_t>(std::floor(x));
    const double alpha = x - static_cast<double>(i);
    k.push_back(order == 1 ? (1.0 - alpha) * s[i] + alpha * s[std::min(i + 1, s.size() - 1)]
                           : (1.0 - alpha) * s[i - 1] + alpha * s[i]);
  }
  k.insert(k.end(), sz(order), s.back());
  try {
    return KnotVector(order, std::move(k));
  } catch (const Error& e) {
    throw e.within(where + " (parameters repeated or all equal?)");
  }
}

// ---------------------------------------------------------------------------------------------
// Curves

CurvePins CurvePins::ends(int count, std::span<const double> first, std::span<const double> last) {
  if (count < 2 || first.size() != last.size())
    throw Error("CurvePins::ends: " + str(count) + " control points, end points of " +
                str(static_cast<long long>(first.size())) + " and " + str(static_cast<long long>(last.size())) +
                " coordinates; expected at least 2 control points and end points of equal dimension");
  CurvePins pins;
  pins.rows = {0, count - 1};
  pins.points.assign(first.begin(), first.end());
  pins.points.insert(pins.points.end(), last.begin(), last.end());
  return pins;
}

Curve interpolate_curve(std::span<const double> params, int dim, std::span<const double> values,
                        const KnotVector& knots) {
  const std::string where = "interpolate_curve";
  if (params.size() != sz(knots.size()))
    throw Error(where + ": " + str(static_cast<long long>(params.size())) + " parameters for " + str(knots.size()) +
                " control points; expected one parameter per control point");
  return solve_curve(where, params, dim, values, knots, {});
}

Curve interpolate_curve(std::span<const double> params, int dim, std::span<const double> values, int order) {
  return interpolate_curve(params, dim, values, interpolation_knots(params, order));
}

Curve fit_curve(std::span<const double> params, int dim, std::span<const double> values, const KnotVector& knots,
                const CurvePins& pins) {
  return solve_curve("fit_curve", params, dim, values, knots, pins);
}

// ---------------------------------------------------------------------------------------------
// Surfaces

Surface fit_surface(std::span<const double> uv, int dim, std::span<const double> values,
                    const std::array<KnotVector, 2>& knots, const SurfacePins& pins) {
  const std::string where = "fit_surface";
  check_dim(where, dim);
  check_surface_knots(where, knots);
  if (uv.size() % 2 != 0)
    throw Error(where + ": " + str(static_cast<long long>(uv.size())) + " parameter values; expected (u, v) pairs");
  const std::size_t m = uv.size() / 2;
  check_values(where, values, m, dim);
  std::vector<double> u(m), v(m);
  for (std::size_t j = 0; j < m; ++j) u[j] = uv[2 * j], v[j] = uv[2 * j + 1];
  check_params(where, "u of data point", u, knots[0]);
  check_params(where, "v of data point", v, knots[1]);

  const PinnedNet net = pinned_net(where, pins, knots, dim);
  const Columns cu = free_columns(net.pinned_u), cv = free_columns(net.pinned_v);
  if (m < sz(cu.free) * sz(cv.free))
    throw Error(where + ": " + str(static_cast<long long>(m)) + " data points for " + str(cu.free * cv.free) +
                " free control points; expected at least one data point per free control point");
  const BasisRows bu = basis_rows(knots[0], u), bv = basis_rows(knots[1], v);
  check_supports(where, knots, bu, bv, cu, cv);

  Matrix rhs = data_rows(values, m, dim);
  if (!pins.empty())
    rhs -= tensor_matrix(bu, bv, all_columns(knots[0].size()), all_columns(knots[1].size())) * net_rows(net.points, dim);
  const auto name = [&](int c) {
    const auto i = std::find(cu.index.begin(), cu.index.end(), c % cu.free) - cu.index.begin();
    const auto j = std::find(cv.index.begin(), cv.index.end(), c / cu.free) - cv.index.begin();
    return "control point (" + str(i) + ", " + str(j) + ")";
  };
  const Matrix X = solve_tensor(bu, bv, cu, cv, rhs,
                                {where, ErrorKind::bad_input,
                                 "data that determine every fitted control point (not all on a few iso-lines)", name});
  Matrix G = net.points;
  for (int j = 0; j < knots[1].size(); ++j)
    for (int i = 0; i < knots[0].size(); ++i) {
      const int ci = cu.index[sz(i)], cj = cv.index[sz(j)];
      if (ci < 0 || cj < 0) continue;
      for (int c = 0; c < dim; ++c) G(i, j * dim + c) = X(ci + cu.free * cj, c);
    }
  return Surface(knots, dim, grid_points(G, dim));
}

Surface fit_surface_grid(std::span<const double> u, std::span<const double> v, int dim,
                         std::span<const double> values, const std::array<KnotVector, 2>& knots,
                         const SurfacePins& pins) {
  const std::string where = "fit_surface_grid";
  check_dim(where, dim);
  check_surface_knots(where, knots);
  check_values(where, values, u.size() * v.size(), dim);
  check_params(where, "u parameter", u, knots[0]);
  check_params(where, "v parameter", v, knots[1]);
  const int mu = static_cast<int>(u.size()), mv = static_cast<int>(v.size());
  const int nu = knots[0].size(), nv = knots[1].size();

  const PinnedNet net = pinned_net(where, pins, knots, dim);
  const Columns cu = free_columns(net.pinned_u), cv = free_columns(net.pinned_v);
  for (int d = 0; d < 2; ++d) {
    const std::size_t m = d == 0 ? u.size() : v.size();
    const int free = d == 0 ? cu.free : cv.free;
    if (m < sz(free))
      throw Error(where + ": " + str(static_cast<long long>(m)) + " " + (d == 0 ? "u" : "v") + " parameters for " +
                  str(free) + " free control points in that direction; expected at least one parameter per "
                  "free control point");
  }
  const BasisRows bu = basis_rows(knots[0], u), bv = basis_rows(knots[1], v);
  check_schoenberg_whitney(where, " in u", knots[0], u, bu, cu);
  check_schoenberg_whitney(where, " in v", knots[1], v, bv, cv);

  // The tensor least-squares problem min |(Bv (x) Bu) X - Y| over the free tensor block, the
  // pinned rows moved to the right-hand side, solved along u and then along v.
  Matrix Y = grid_matrix(values, mu, mv, dim);
  if (!pins.empty()) {
    const Matrix along_u = matrix(bu, all_columns(nu)) * net.points;  // mu x nv*dim
    Y -= transpose_grid(matrix(bv, all_columns(nv)) * transpose_grid(along_u, mu, nv, dim), mv, mu, dim);
  }
  const Matrix Z = solve_1d(bu, cu, Y, {where, ErrorKind::failed, clustered, name_free(cu, " in u")});  // free_u x mv*dim
  const Matrix W = solve_1d(bv, cv, transpose_grid(Z, cu.free, mv, dim),
                            {where, ErrorKind::failed, clustered, name_free(cv, " in v")});  // free_v x free_u*dim
  Matrix G = net.points;
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const int ci = cu.index[sz(i)], cj = cv.index[sz(j)];
      if (ci < 0 || cj < 0) continue;
      for (int c = 0; c < dim; ++c) G(i, j * dim + c) = W(cj, ci * dim + c);
    }
  return Surface(knots, dim, grid_points(G, dim));
}

Surface interpolate_surface_grid(std::span<const double> u, std::span<const double> v, int dim,
                                 std::span<const double> values, std::array<int, 2> orders) {
  return fit_surface_grid(u, v, dim, values, {interpolation_knots(u, orders[0]), interpolation_knots(v, orders[1])});
}

}  // namespace trivox::spline
