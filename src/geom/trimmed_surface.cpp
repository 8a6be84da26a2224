#include "trivox/geom/trimmed_surface.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "patch_quadrature.hpp"
#include "trivox/error.hpp"
#include "trivox/geom/planar_crossing.hpp"
#include "trivox/geom/quadrature.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::geom {

namespace {

std::string num(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", x);
  return buf;
}

std::string point_text(double u, double v) { return "(" + num(u) + ", " + num(v) + ")"; }

std::string where(int loop, int piece) {
  return "trimming loop " + std::to_string(loop) + ", piece " + std::to_string(piece);
}

// ---------------------------------------------------------------------------------------------
// Univariate Bernstein polynomials on [0, 1]: coefficients c_0..c_n of degree n = size - 1.

using Poly = std::vector<double>;

double bern_eval(const Poly& c, double s) {
  thread_local std::vector<double> w;
  w.assign(c.begin(), c.end());
  for (std::size_t r = 1; r < w.size(); ++r)
    for (std::size_t i = 0; i + r < w.size(); ++i) w[i] = (1.0 - s) * w[i] + s * w[i + 1];
  return w[0];
}

/// de Casteljau subdivision at s: the parts on [0, s] and [s, 1], each on [0, 1].
std::pair<Poly, Poly> bern_split(const Poly& c, double s) {
  const std::size_t n = c.size();
  Poly w = c, left(n), right(n);
  left[0] = w[0];
  right[n - 1] = w[n - 1];
  for (std::size_t r = 1; r < n; ++r) {
    for (std::size_t i = 0; i + r < n; ++i) w[i] = (1.0 - s) * w[i] + s * w[i + 1];
    left[r] = w[0];
    right[n - 1 - r] = w[n - 1 - r];
  }
  return {left, right};
}

Poly bern_derivative(const Poly& c) {
  const int n = static_cast<int>(c.size()) - 1;
  if (n == 0) return {0.0};
  Poly d(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) d[static_cast<std::size_t>(i)] = n * (c[static_cast<std::size_t>(i) + 1] - c[static_cast<std::size_t>(i)]);
  return d;
}

/// The same polynomial in degree `to` >= its degree.
Poly bern_elevate(Poly c, int to) {
  while (static_cast<int>(c.size()) - 1 < to) {
    const int n = static_cast<int>(c.size()) - 1;
    Poly e(static_cast<std::size_t>(n + 2));
    e[0] = c[0];
    e[static_cast<std::size_t>(n + 1)] = c[static_cast<std::size_t>(n)];
    for (int i = 1; i <= n; ++i) {
      const double a = static_cast<double>(i) / (n + 1);
      e[static_cast<std::size_t>(i)] = a * c[static_cast<std::size_t>(i - 1)] + (1.0 - a) * c[static_cast<std::size_t>(i)];
    }
    c = std::move(e);
  }
  return c;
}

/// Roots of c in the open interval (lo, hi) of the original parameter, by Bezier clipping to
/// the control polygon's sign pattern: a sub-interval whose coefficients all exceed `tol` in
/// absolute value with one sign holds none, one whose coefficients are all within `tol` of zero
/// is where the polynomial vanishes (no cut), and a monotone one with a sign change holds one
/// root found by bisection. Depth and count are bounded by the degree.
void bern_roots(const Poly& c, double lo, double hi, double tol, int depth, std::vector<double>& out) {
  double mn = c[0], mx = c[0];
  for (double x : c) mn = std::min(mn, x), mx = std::max(mx, x);
  if (mn > tol || mx < -tol) return;
  if (mn >= -tol && mx <= tol) return;
  const double a = c.front(), b = c.back();
  bool monotone = b != a;
  for (std::size_t i = 1; i < c.size() && monotone; ++i)
    monotone = (c[i] - c[i - 1]) * (b - a) >= 0.0;
  if (monotone || depth >= 40 || hi - lo < 1e-14) {
    if ((a > 0.0) == (b > 0.0) && a != 0.0 && b != 0.0) {
      if (monotone) return;  // monotone without a sign change (within tol of zero only)
      // At the depth limit with a small value but no sign change: a touching point.
      if (std::abs(bern_eval(c, 0.5)) <= tol) out.push_back(0.5 * (lo + hi));
      return;
    }
    double l = 0.0, r = 1.0;
    const bool rising = b > a;
    for (int it = 0; it < 60; ++it) {
      const double m = 0.5 * (l + r);
      if ((bern_eval(c, m) < 0.0) == rising) l = m; else r = m;
    }
    out.push_back(lo + 0.5 * (l + r) * (hi - lo));
    return;
  }
  auto [left, right] = bern_split(c, 0.5);
  const double mid = 0.5 * (lo + hi);
  bern_roots(left, lo, mid, tol, depth + 1, out);
  bern_roots(right, mid, hi, tol, depth + 1, out);
}

/// Whether c <= tol on [0, 1]: the convex hull, refined by subdivision where it is not tight.
bool bern_at_most(const Poly& c, double tol, int depth = 0) {
  if (*std::max_element(c.begin(), c.end()) <= tol) return true;
  if (c.front() > tol || c.back() > tol || depth >= 12) return false;
  if (bern_eval(c, 0.5) > tol) return false;
  auto [l, r] = bern_split(c, 0.5);
  return bern_at_most(l, tol, depth + 1) && bern_at_most(r, tol, depth + 1);
}

/// The parameter s in [0, 1] where the increasing polynomial u reaches x.
double solve_increasing(const Poly& u, double x) {
  double l = 0.0, r = 1.0;
  if (x <= u.front()) return 0.0;
  if (x >= u.back()) return 1.0;
  for (int it = 0; it < 60 && r - l > 1e-17; ++it) {
    const double m = 0.5 * (l + r);
    if (bern_eval(u, m) < x) l = m; else r = m;
  }
  return 0.5 * (l + r);
}

// ---------------------------------------------------------------------------------------------
// Bivariate Bernstein polynomials on [0, 1]^2 with k coordinates: degrees (m, n), coefficient
// (i, j, c) at ((j (m + 1) + i) k + c), s fastest.

struct BPoly {
  int m = 0, n = 0, k = 1;
  std::vector<double> c;
  BPoly() = default;
  BPoly(int m_, int n_, int k_) : m(m_), n(n_), k(k_), c(static_cast<std::size_t>((m_ + 1) * (n_ + 1) * k_), 0.0) {}
  double& at(int i, int j, int d) { return c[static_cast<std::size_t>(((j * (m + 1)) + i) * k + d)]; }
  double at(int i, int j, int d) const { return c[static_cast<std::size_t>(((j * (m + 1)) + i) * k + d)]; }
};

std::vector<double> binomial_row(int n) {
  std::vector<double> b(static_cast<std::size_t>(n + 1), 1.0);
  for (int i = 1; i <= n; ++i) b[static_cast<std::size_t>(i)] = b[static_cast<std::size_t>(i - 1)] * (n - i + 1) / i;
  return b;
}

/// f (scalar) times g (k coordinates): the product of Bernstein forms,
/// h_K = sum_{I + J = K} C(m, I) C(n, J) / C(m + n, K) f_I g_J per direction.
BPoly multiply(const BPoly& f, const BPoly& g) {
  BPoly h(f.m + g.m, f.n + g.n, g.k);
  const auto bfm = binomial_row(f.m), bfn = binomial_row(f.n), bgm = binomial_row(g.m), bgn = binomial_row(g.n);
  const auto bhm = binomial_row(h.m), bhn = binomial_row(h.n);
  for (int j1 = 0; j1 <= f.n; ++j1)
    for (int i1 = 0; i1 <= f.m; ++i1) {
      const double fv = f.at(i1, j1, 0) * bfm[static_cast<std::size_t>(i1)] * bfn[static_cast<std::size_t>(j1)];
      if (fv == 0.0) continue;
      for (int j2 = 0; j2 <= g.n; ++j2)
        for (int i2 = 0; i2 <= g.m; ++i2) {
          const double w = fv * bgm[static_cast<std::size_t>(i2)] * bgn[static_cast<std::size_t>(j2)];
          for (int d = 0; d < g.k; ++d) h.at(i1 + i2, j1 + j2, d) += w * g.at(i2, j2, d);
        }
    }
  for (int j = 0; j <= h.n; ++j)
    for (int i = 0; i <= h.m; ++i) {
      const double den = bhm[static_cast<std::size_t>(i)] * bhn[static_cast<std::size_t>(j)];
      for (int d = 0; d < h.k; ++d) h.at(i, j, d) /= den;
    }
  return h;
}

void add_to(BPoly& a, const BPoly& b) {
  for (std::size_t i = 0; i < a.c.size(); ++i) a.c[i] += b.c[i];
}

/// S(u(s, t), v(s, t)) for a Bezier piece `piece` of S on [a0, a1] x [b0, b1]: de Casteljau on
/// Bernstein polynomials, first along u in every row of the control net, then along v.
BPoly compose(const spline::Surface& piece, const BPoly& u, const BPoly& v) {
  const auto du = piece.domain(0), dv = piece.domain(1);
  const int p = piece.orders()[0] - 1, q = piece.orders()[1] - 1, k = piece.dim();
  BPoly uh = u, vh = v, omu = u, omv = v;
  for (std::size_t i = 0; i < u.c.size(); ++i) {
    uh.c[i] = (u.c[i] - du[0]) / (du[1] - du[0]);
    omu.c[i] = 1.0 - uh.c[i];
  }
  for (std::size_t i = 0; i < v.c.size(); ++i) {
    vh.c[i] = (v.c[i] - dv[0]) / (dv[1] - dv[0]);
    omv.c[i] = 1.0 - vh.c[i];
  }
  std::vector<BPoly> rows;
  rows.reserve(static_cast<std::size_t>(q + 1));
  for (int j = 0; j <= q; ++j) {
    std::vector<BPoly> w;
    for (int i = 0; i <= p; ++i) {
      BPoly c(0, 0, k);
      const auto pt = piece.point(i + (p + 1) * j);
      std::copy(pt.begin(), pt.end(), c.c.begin());
      w.push_back(std::move(c));
    }
    for (int r = 1; r <= p; ++r)
      for (int i = 0; i + r <= p; ++i) {
        BPoly a = multiply(omu, w[static_cast<std::size_t>(i)]);
        add_to(a, multiply(uh, w[static_cast<std::size_t>(i) + 1]));
        w[static_cast<std::size_t>(i)] = std::move(a);
      }
    rows.push_back(std::move(w[0]));
  }
  for (int r = 1; r <= q; ++r)
    for (int j = 0; j + r <= q; ++j) {
      BPoly a = multiply(omv, rows[static_cast<std::size_t>(j)]);
      add_to(a, multiply(vh, rows[static_cast<std::size_t>(j) + 1]));
      rows[static_cast<std::size_t>(j)] = std::move(a);
    }
  return std::move(rows[0]);
}

// ---------------------------------------------------------------------------------------------
// The slab decomposition.

/// One Bezier piece of a monotone side, u increasing from u.front() to u.back().
struct Seg {
  Poly u, v;
  double len = 1.0;  ///< its share of the side's parameter (of the trimming curve's own)
};

/// A u-monotone piece of a trimming curve: the consecutive Bezier pieces of one trimming curve
/// between two of its events (its ends, its vertical tangents, its crossings with knot lines of
/// S in v), oriented so that u increases along it. It is one side of every quad it bounds, however
/// many Bezier pieces (marched points) it has, so the slabs are cut at its events only.
struct Mono {
  std::vector<Seg> segs;
  int sign = 1;  ///< +1 when the loop runs towards +u here, -1 when it runs towards -u
  int loop = 0, piece = 0;
  double u0() const { return segs.front().u.front(); }
  double u1() const { return segs.back().u.back(); }
  /// The first piece whose end reaches u = x.
  std::size_t seg_at(double x) const {
    std::size_t lo = 0, hi = segs.size() - 1;
    while (lo < hi) {
      const std::size_t m = (lo + hi) / 2;
      if (segs[m].u.back() < x) lo = m + 1; else hi = m;
    }
    return lo;
  }
  double v_at(double x) const {
    const Seg& g = segs[seg_at(x)];
    return bern_eval(g.v, solve_increasing(g.u, x));
  }
  /// Whether every control point lies within tol of the line v = alpha + beta u through the
  /// side's ends (a straight edge: the rectangle's sides, straight cuts).
  bool straight(double tol, double& alpha, double& beta) const {
    const double ua = u0(), ub = u1(), va = segs.front().v.front(), vb = segs.back().v.back();
    if (!(ub > ua)) return false;
    beta = (vb - va) / (ub - ua);
    alpha = va - beta * ua;
    for (const auto& g : segs)
      for (std::size_t i = 0; i < g.u.size(); ++i)
        if (!(std::abs(g.v[i] - (alpha + beta * g.u[i])) <= tol)) return false;
    return true;
  }
};

/// A boundary between regions inside a slab: a curve piece or a horizontal knot line.
struct Item {
  const Mono* mono = nullptr;  ///< null: the knot line v = h
  double h = 0.0;
  double v_mid = 0.0;  ///< v at the slab's middle, for ordering
  int order_key = 0;
  int sign() const { return mono ? mono->sign : 0; }
  double v_at(double x) const { return mono ? mono->v_at(x) : h; }
  std::string name() const {
    return mono ? where(mono->loop, mono->piece) : "the knot line v = " + num(h);
  }
};

/// Bezier patches of one degree side by side in s, as one B-spline surface on [0, 1]^2: knots in
/// s at the pieces' cumulative shares `lens`, each of multiplicity m (C0 joins), so the surface is
/// exactly the pieces; the shared column of two neighbours is their mean (they agree to rounding).
spline::Surface join_in_s(const std::vector<BPoly>& parts, const std::vector<double>& lens) {
  const BPoly& f = parts.front();
  if (parts.size() == 1)
    return spline::Surface({spline::KnotVector::bezier(f.m + 1), spline::KnotVector::bezier(f.n + 1)}, f.k, f.c);
  const int m = f.m, n = f.n, k = f.k;
  double total = 0.0;
  for (double l : lens) total += l;
  // Any increasing knots give the same surface; the shares keep the parameter close to the
  // curve's (even samples along it), with no piece shorter than 1e-9 of the whole.
  std::vector<double> share(lens.size());
  double sum = 0.0;
  for (std::size_t i = 0; i < lens.size(); ++i) sum += share[i] = std::max(lens[i], 1e-9 * total);
  std::vector<double> knots(static_cast<std::size_t>(m + 1), 0.0);
  double acc = 0.0;
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
    acc += share[i];
    for (int r = 0; r < m; ++r) knots.push_back(acc / sum);
  }
  for (int r = 0; r <= m; ++r) knots.push_back(1.0);
  const int cs = static_cast<int>(parts.size()) * m + 1;
  std::vector<double> pts(static_cast<std::size_t>(cs * (n + 1) * k), 0.0);
  auto at = [&](int i, int j, int d) -> double& { return pts[static_cast<std::size_t>((j * cs + i) * k + d)]; };
  for (std::size_t p = 0; p < parts.size(); ++p)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= m; ++i)
        for (int d = 0; d < k; ++d) {
          const int col = static_cast<int>(p) * m + i;
          const double x = parts[p].at(i, j, d);
          at(col, j, d) = (i == 0 && p > 0) ? 0.5 * (at(col, j, d) + x) : x;
        }
  return spline::Surface({spline::KnotVector(m + 1, std::move(knots)), spline::KnotVector::bezier(n + 1)}, k,
                         std::move(pts));
}

struct Builder {
  const TrimmedSurface& ts;
  const UntrimOptions& opt;
  double tol;
  std::vector<double> ubreaks, vbreaks;
  std::vector<spline::Surface> pieces;  // Bezier pieces of S, u fastest
  Untrimmed out;

  Builder(const TrimmedSurface& t, const UntrimOptions& o) : ts(t), opt(o), tol(t.tolerance()) {
    const auto& s = ts.surface();
    for (const auto& b : s.knots(0).breakpoints()) ubreaks.push_back(b.value);
    for (const auto& b : s.knots(1).breakpoints()) vbreaks.push_back(b.value);
    pieces = spline::bezier_pieces(s);
  }

  static int span_of(const std::vector<double>& br, double x) {
    auto it = std::upper_bound(br.begin(), br.end(), x);
    int i = static_cast<int>(it - br.begin()) - 1;
    return std::clamp(i, 0, static_cast<int>(br.size()) - 2);
  }

  /// Elevates a bivariate polynomial to degrees (qm, qn), direction by direction.
  static BPoly elevate(const BPoly& src, int qm, int qn) {
    BPoly e(qm, qn, src.k);
    for (int c = 0; c < src.k; ++c) {
      std::vector<Poly> cols;
      for (int j = 0; j <= src.n; ++j) {
        Poly row(static_cast<std::size_t>(src.m + 1));
        for (int i = 0; i <= src.m; ++i) row[static_cast<std::size_t>(i)] = src.at(i, j, c);
        cols.push_back(bern_elevate(row, qm));
      }
      for (int i = 0; i <= qm; ++i) {
        Poly col(static_cast<std::size_t>(src.n + 1));
        for (int j = 0; j <= src.n; ++j) col[static_cast<std::size_t>(j)] = cols[static_cast<std::size_t>(j)][static_cast<std::size_t>(i)];
        const Poly x = bern_elevate(col, qn);
        for (int j = 0; j <= qn; ++j) e.at(i, j, c) = x[static_cast<std::size_t>(j)];
      }
    }
    return e;
  }

  /// Emits the patch S(q) for the quad map q = (u, v), given piece by piece in s (one degree for
  /// all, shares `lens` of the parameter), lying in the Bezier piece of S containing (um, vm).
  void emit(const std::vector<BPoly>& us, const std::vector<BPoly>& vs, const std::vector<double>& lens, double um,
            double vm) {
    const auto& s = ts.surface();
    const int iu = span_of(ubreaks, um), iv = span_of(vbreaks, vm);
    const auto& piece = pieces[static_cast<std::size_t>(iu + (static_cast<int>(ubreaks.size()) - 1) * iv)];
    const int p = s.orders()[0] - 1, q = s.orders()[1] - 1;
    const BPoly &u = us.front(), &v = vs.front();
    const int ds = p * u.m + q * v.m, dt = p * u.n + q * v.n;
    if (ds + 1 > opt.limits.max_order || dt + 1 > opt.limits.max_order)
      throw Error("untrim: a patch of orders (" + std::to_string(ds + 1) + ", " + std::to_string(dt + 1) +
                  ") (surface orders (" + std::to_string(p + 1) + ", " + std::to_string(q + 1) +
                  ") composed with a quad map of degrees (" + std::to_string(std::max(u.m, v.m)) + ", " +
                  std::to_string(std::max(u.n, v.n)) + ")); expected orders of at most " +
                  std::to_string(opt.limits.max_order) + limit_hint("max_order"));
    auto& r = out.report;
    if (static_cast<std::int64_t>(out.patches.size()) >= opt.max_patches ||
        r.spans + static_cast<std::int64_t>(us.size()) > opt.max_patches)
      throw Error("untrim: more than " + std::to_string(opt.max_patches) +
                  " patches or Bezier pieces of patches; expected at most that many (UntrimOptions::max_patches)");
    // The quad map as a 2-coordinate surface, both coordinates in one degree.
    const int qm = std::max(u.m, v.m), qn = std::max(u.n, v.n);
    std::vector<BPoly> parts, maps;
    for (std::size_t i = 0; i < us.size(); ++i) {
      parts.push_back(compose(piece, us[i], vs[i]));
      const BPoly eu = elevate(us[i], qm, qn), ev = elevate(vs[i], qm, qn);
      BPoly qd(qm, qn, 2);
      for (int j = 0; j <= qn; ++j)
        for (int a = 0; a <= qm; ++a) qd.at(a, j, 0) = eu.at(a, j, 0), qd.at(a, j, 1) = ev.at(a, j, 0);
      maps.push_back(std::move(qd));
    }
    spline::Surface ps = join_in_s(parts, lens), qs = join_in_s(maps, lens);
    // The composition checked against S at 5 x 5 points.
    double err = 0.0;
    std::vector<double> a(static_cast<std::size_t>(s.dim())), b(static_cast<std::size_t>(s.dim()));
    double uv[2];
    for (int j = 0; j < 5; ++j)
      for (int i = 0; i < 5; ++i) {
        const std::array<double, 2> st{0.1 + 0.2 * i, 0.1 + 0.2 * j};
        qs.eval(st, uv);
        s.eval({uv[0], uv[1]}, a.data());
        ps.eval(st, b.data());
        for (std::size_t d = 0; d < a.size(); ++d) err = std::max(err, std::abs(a[d] - b[d]));
      }
    r.max_composition_error = std::max(r.max_composition_error, err);
    r.max_order_s = std::max(r.max_order_s, ds + 1);
    r.max_order_t = std::max(r.max_order_t, dt + 1);
    r.spans += static_cast<std::int64_t>(us.size());
    r.max_spans = std::max(r.max_spans, static_cast<int>(us.size()));
    out.patches.push_back(std::move(ps));
    out.domains.push_back(std::move(qs));
    r.patches = static_cast<std::int64_t>(out.patches.size());
  }

  /// A bivariate polynomial in s only (degree 0 in t) from univariate coefficients.
  static BPoly in_s(const Poly& c) {
    BPoly b(static_cast<int>(c.size()) - 1, 0, 1);
    for (std::size_t i = 0; i < c.size(); ++i) b.c[i] = c[i];
    return b;
  }
  /// (1 - t) lo(s) + t hi(s), lo and hi of one degree.
  static BPoly ruled(const Poly& lo, const Poly& hi) {
    BPoly b(static_cast<int>(lo.size()) - 1, 1, 1);
    for (std::size_t i = 0; i < lo.size(); ++i) {
      b.at(static_cast<int>(i), 0, 0) = lo[i];
      b.at(static_cast<int>(i), 1, 0) = hi[i];
    }
    return b;
  }

  /// Ruled quad with vertical rulings over the pieces of the side `c`: per piece g,
  /// q = (U_g(s), (1 - t) vb_g(s) + t vt_g(s)) with (vb_g, vt_g) = sides(index, g).
  template <class Sides>
  void vertical_quad(const Mono& c, Sides sides, double um, double vm) {
    std::vector<Poly> vb, vt;
    for (std::size_t i = 0; i < c.segs.size(); ++i) {
      auto [b, t] = sides(i, c.segs[i]);
      vb.push_back(std::move(b));
      vt.push_back(std::move(t));
    }
    // A horizontal side (all coefficients equal) is a constant: the patch's degree does not grow
    // with it. v in its own degree: between two knot lines it is constant in s and the patch is
    // the Bezier piece itself, of the surface's degrees.
    auto flat = [](const std::vector<Poly>& cs) {
      return std::all_of(cs.begin(), cs.end(), [](const Poly& c) {
        return std::all_of(c.begin(), c.end(), [&](double x) { return x == c.front(); });
      });
    };
    for (auto* side : {&vb, &vt})
      if (flat(*side))
        for (Poly& c : *side) c.resize(1);
    int n = 0;
    for (std::size_t i = 0; i < vb.size(); ++i)
      n = std::max({n, static_cast<int>(vb[i].size()) - 1, static_cast<int>(vt[i].size()) - 1});
    std::vector<BPoly> us, vs;
    std::vector<double> lens;
    for (std::size_t i = 0; i < c.segs.size(); ++i) {
      us.push_back(in_s(c.segs[i].u));
      vs.push_back(ruled(bern_elevate(std::move(vb[i]), n), bern_elevate(std::move(vt[i]), n)));
      lens.push_back(c.segs[i].len);
    }
    emit(us, vs, lens, um, vm);
  }

  /// The quad between side c and the line v = alpha + beta u (beta = 0: a knot line), c below
  /// the line or above it.
  void line_quad(const Mono& c, double alpha, double beta, bool c_below, double um, double vm) {
    vertical_quad(c, [&](std::size_t, const Seg& g) {
      Poly l;
      if (beta == 0.0) {
        l = {alpha};
      } else {
        l.resize(g.u.size());
        for (std::size_t i = 0; i < g.u.size(); ++i) l[i] = alpha + beta * g.u[i];
      }
      return c_below ? std::make_pair(g.v, l) : std::make_pair(l, g.v);
    }, um, vm);
  }

  static bool same_poly(Poly a, Poly b, double tol) {
    const int n = std::max(static_cast<int>(a.size()), static_cast<int>(b.size())) - 1;
    a = bern_elevate(std::move(a), n);
    b = bern_elevate(std::move(b), n);
    for (int i = 0; i <= n; ++i)
      if (std::abs(a[static_cast<std::size_t>(i)] - b[static_cast<std::size_t>(i)]) > tol) return false;
    return true;
  }

  /// The region of slab [e0, e1] between bottom and top (their v at the middle: vm).
  void region(const Item& bot, const Item& top, double e0, double e1, double vm) {
    const double um = 0.5 * (e0 + e1);
    if (!bot.mono && !top.mono) {
      Mono m;
      m.segs.push_back({{e0, e1}, {bot.h, bot.h}, 1.0});
      line_quad(m, top.h, 0.0, true, um, vm);
    } else if (!bot.mono) {
      line_quad(*top.mono, bot.h, 0.0, false, um, vm);
    } else if (!top.mono) {
      line_quad(*bot.mono, top.h, 0.0, true, um, vm);
    } else {
      two_curves(*bot.mono, *top.mono, e0, e1, vm, 0, bot, top);
    }
  }

  /// The region between two monotone sides spanning [e0, e1] (restricted copies).
  void two_curves(const Mono& b, const Mono& t, double e0, double e1, double vm, int depth,
                  const Item& bi, const Item& ti) {
    const double um = 0.5 * (e0 + e1);
    const double side = 0.01 * tol;
    // Both with the same u-polynomials piece by piece (straight edges with one parameter, say).
    bool same = b.segs.size() == t.segs.size();
    for (std::size_t i = 0; same && i < b.segs.size(); ++i) same = same_poly(b.segs[i].u, t.segs[i].u, tol);
    if (same) {
      vertical_quad(b, [&](std::size_t i, const Seg& g) { return std::make_pair(g.v, t.segs[i].v); }, um, vm);
      return;
    }
    // A straight side (to rounding: it replaces the curve) is a function of u: the other side's
    // u parametrises it.
    double alpha = 0.0, beta = 0.0;
    const auto du = ts.surface().domain(0), dv = ts.surface().domain(1);
    const double flat = std::min(side, 1e-13 * std::max(du[1] - du[0], dv[1] - dv[0]));
    if (t.straight(flat, alpha, beta)) {
      line_quad(b, alpha, beta, true, um, vm);
      return;
    }
    if (b.straight(flat, alpha, beta)) {
      line_quad(t, alpha, beta, false, um, vm);
      return;
    }
    // Separator v = alpha + beta u through the midpoints of the left and right sides.
    const double l = 0.5 * (b.segs.front().v.front() + t.segs.front().v.front());
    const double r = 0.5 * (b.segs.back().v.back() + t.segs.back().v.back());
    beta = (r - l) / (e1 - e0);
    alpha = l - beta * e0;
    bool between = true;
    for (const auto* c : {&b, &t})
      for (std::size_t k = 0; between && k < c->segs.size(); ++k) {
        const Seg& g = c->segs[k];
        Poly d(g.u.size());
        for (std::size_t i = 0; i < g.u.size(); ++i)
          d[i] = (c == &b ? 1.0 : -1.0) * (g.v[i] - (alpha + beta * g.u[i]));
        between = bern_at_most(d, side);
      }
    if (between) {
      line_quad(b, alpha, beta, true, um, vm);
      line_quad(t, alpha, beta, false, um, vm);
      return;
    }
    if (depth >= opt.max_splits)
      throw Error("untrim: no straight separator between " + bi.name() + " and " + ti.name() +
                      " for u in [" + num(e0) + ", " + num(e1) + "] after " + std::to_string(depth) +
                      " halvings; expected trimming curves that do not touch",
                  ErrorKind::failed);
    const double mid = 0.5 * (e0 + e1);
    const auto [bl, br] = split_at(b, mid);
    const auto [tl, tr] = split_at(t, mid);
    const double vml = 0.5 * (bl.v_at(0.5 * (e0 + mid)) + tl.v_at(0.5 * (e0 + mid)));
    const double vmr = 0.5 * (br.v_at(0.5 * (mid + e1)) + tr.v_at(0.5 * (mid + e1)));
    two_curves(bl, tl, e0, mid, vml, depth + 1, bi, ti);
    two_curves(br, tr, mid, e1, vmr, depth + 1, bi, ti);
  }

  /// The side m cut at u = x (inside its range): the parts before and after. A cut within 1e-12
  /// of the parameter of a piece's end is made there, so no piece of no length is left.
  static std::pair<Mono, Mono> split_at(const Mono& m, double x) {
    const std::size_t k = m.seg_at(x);
    const Seg& g = m.segs[k];
    const double s = solve_increasing(g.u, x);
    Mono a = m, b = m;
    a.segs.assign(m.segs.begin(), m.segs.begin() + static_cast<std::ptrdiff_t>(k));
    b.segs.assign(m.segs.begin() + static_cast<std::ptrdiff_t>(k) + 1, m.segs.end());
    if (s <= 1e-12 && k > 0) {
      b.segs.insert(b.segs.begin(), g);
    } else if (s >= 1.0 - 1e-12 && k + 1 < m.segs.size()) {
      a.segs.push_back(g);
    } else {
      Seg l = g, r = g;
      std::tie(l.u, r.u) = bern_split(g.u, s);
      std::tie(l.v, r.v) = bern_split(g.v, s);
      l.len = g.len * s;
      r.len = g.len * (1.0 - s);
      a.segs.push_back(std::move(l));
      b.segs.insert(b.segs.begin(), std::move(r));
    }
    a.segs.back().u.back() = x;
    b.segs.front().u.front() = x;
    return {a, b};
  }

  void run() {
    const auto& s = ts.surface();
    const auto du = s.domain(0), dv = s.domain(1);
    // The loops, or the rectangle when there are none.
    std::vector<TrimLoop> loops = ts.loops();
    if (loops.empty()) {
      auto line = [](double x0, double y0, double x1, double y1) {
        return spline::Curve({spline::KnotVector::bezier(2)}, 2, std::vector<double>{x0, y0, x1, y1});
      };
      loops.push_back({{line(du[0], dv[0], du[1], dv[0]), line(du[1], dv[0], du[1], dv[1]),
                        line(du[1], dv[1], du[0], dv[1]), line(du[0], dv[1], du[0], dv[0])}});
    }
    // 1. u-monotone sides: each trimming curve's Bezier pieces cut at the roots of u' and at
    // the crossings with interior knot lines, consecutive parts joined into one side until an
    // event (a cut, a change of direction, a vertical part, a knot line in v reached at a piece's
    // end, the curve's end).
    std::vector<Mono> monos;
    std::int64_t segs = 0;
    for (std::size_t li = 0; li < loops.size(); ++li)
      for (std::size_t pi = 0; pi < loops[li].pieces.size(); ++pi) {
        Mono cur;
        auto flush = [&] {
          if (!cur.segs.empty()) {
            if (cur.sign < 0) {
              std::reverse(cur.segs.begin(), cur.segs.end());
              for (auto& g : cur.segs) {
                std::reverse(g.u.begin(), g.u.end());
                std::reverse(g.v.begin(), g.v.end());
              }
            }
            monos.push_back(std::move(cur));
          }
          cur = Mono{};
        };
        for (const auto& bz : spline::bezier_pieces(loops[li].pieces[pi])) {
          Poly u(static_cast<std::size_t>(bz.size())), v(u.size());
          for (int i = 0; i < bz.size(); ++i) {
            u[static_cast<std::size_t>(i)] = bz.point(i)[0];
            v[static_cast<std::size_t>(i)] = bz.point(i)[1];
          }
          const double span = bz.domain(0)[1] - bz.domain(0)[0];
          // A piece starting on an interior knot line in v ends the side before it.
          const auto on_v = std::upper_bound(vbreaks.begin() + 1, vbreaks.end() - 1, v.front() - tol);
          if (on_v != vbreaks.end() - 1 && *on_v <= v.front() + tol) flush();
          std::vector<double> cuts;
          bern_roots(bern_derivative(u), 0.0, 1.0, 1e-3 * tol, 0, cuts);
          // Crossings with the interior knot lines within the piece's control box only, so the
          // cost follows the crossings rather than the knot count.
          for (const auto* c : {&u, &v}) {
            const auto& br = c == &u ? ubreaks : vbreaks;
            const auto [lo, hi] = std::minmax_element(c->begin(), c->end());
            auto it = std::upper_bound(br.begin() + 1, br.end() - 1, *lo - tol);
            for (; it != br.end() - 1 && *it <= *hi + tol; ++it) {
              Poly d = *c;
              for (double& x : d) x -= *it;
              bern_roots(d, 0.0, 1.0, 1e-3 * tol, 0, cuts);
            }
          }
          std::sort(cuts.begin(), cuts.end());
          std::vector<double> at{0.0};
          for (double c : cuts)
            if (c > at.back() + 1e-12 && c < 1.0 - 1e-12) at.push_back(c);
          at.push_back(1.0);
          Poly ru = u, rv = v;
          double done = 0.0;
          for (std::size_t i = 1; i < at.size(); ++i) {
            Poly pu, pv;
            if (i + 1 < at.size()) {
              const double loc = (at[i] - done) / (1.0 - done);
              std::tie(pu, ru) = bern_split(ru, loc);
              std::tie(pv, rv) = bern_split(rv, loc);
              done = at[i];
            } else {
              pu = ru;
              pv = rv;
            }
            if (i > 1) flush();  // a cut inside the piece: an event
            if (std::abs(pu.back() - pu.front()) <= tol) {  // vertical: no area
              flush();
              continue;
            }
            const int sign = pu.back() > pu.front() ? 1 : -1;
            if (!cur.segs.empty() && sign != cur.sign) flush();
            if (cur.segs.empty()) {
              cur.sign = sign;
              cur.loop = static_cast<int>(li);
              cur.piece = static_cast<int>(pi);
            }
            cur.segs.push_back({std::move(pu), std::move(pv), span * (at[i] - at[i - 1])});
            if (++segs > opt.max_patches)
              throw Error("untrim: more than " + std::to_string(opt.max_patches) +
                          " monotone curve pieces; expected at most that many (UntrimOptions::max_patches)");
          }
        }
        flush();
      }
    // 2. Events: knot lines of S in u (domain ends included) and the sides' ends, merged
    // within the tolerance (a knot value wins over a curve end).
    std::vector<std::pair<double, int>> ev;
    for (double b : ubreaks) ev.push_back({b, 0});
    for (const auto& m : monos) {
      ev.push_back({m.u0(), 1});
      ev.push_back({m.u1(), 1});
    }
    std::sort(ev.begin(), ev.end());
    std::vector<double> events;
    for (std::size_t i = 0; i < ev.size();) {
      std::size_t j = i;
      double rep = ev[i].first;
      bool knot = ev[i].second == 0;
      while (j + 1 < ev.size() && ev[j + 1].first - ev[i].first <= tol) {
        ++j;
        if (!knot && ev[j].second == 0) rep = ev[j].first, knot = true;
      }
      events.push_back(rep);
      i = j + 1;
    }
    // 3. Every side cut at the events it spans, each part filed under its slab.
    const std::size_t slabs = events.size() - 1;
    std::vector<std::vector<Mono>> in_slab(slabs);
    std::int64_t parts = 0;
    auto file = [&](Mono&& m) {
      const std::size_t k = static_cast<std::size_t>(span_of(events, 0.5 * (m.u0() + m.u1())));
      parts += static_cast<std::int64_t>(m.segs.size());
      if (parts > opt.max_patches)
        throw Error("untrim: more than " + std::to_string(opt.max_patches) +
                    " curve pieces in slabs; expected at most that many (UntrimOptions::max_patches)");
      in_slab[k].push_back(std::move(m));
    };
    for (const auto& m : monos) {
      Mono rest = m;
      auto it = std::upper_bound(events.begin(), events.end(), m.u0() + tol);
      for (; it != events.end() && *it < m.u1() - tol; ++it) {
        auto [a, b] = split_at(rest, *it);
        file(std::move(a));
        rest = std::move(b);
      }
      file(std::move(rest));
    }
    // 4. Per slab: items ordered bottom to top, winding numbers, quads where it is 1.
    std::int64_t work = 0;
    for (std::size_t k = 0; k < slabs; ++k) {
      const double e0 = events[k], e1 = events[k + 1], um = 0.5 * (e0 + e1);
      // Knot lines between the lowest and highest curve point of the slab: below and above
      // them the winding number is 0.
      double vlo = 1e300, vhi = -1e300;
      for (const auto& m : in_slab[k])
        for (const auto& g : m.segs) {
          const auto [lo, hi] = std::minmax_element(g.v.begin(), g.v.end());
          vlo = std::min(vlo, *lo);
          vhi = std::max(vhi, *hi);
        }
      std::vector<Item> items;
      for (auto bi = std::lower_bound(vbreaks.begin(), vbreaks.end(), vlo - tol);
           bi != vbreaks.end() && *bi <= vhi + tol; ++bi) {
        const double b = *bi;
        Item it;
        it.h = b;
        it.v_mid = b;
        it.order_key = 0;
        items.push_back(it);
      }
      for (const auto& m : in_slab[k]) {
        Item it;
        it.mono = &m;
        it.v_mid = it.v_at(um);
        it.order_key = 1;
        items.push_back(it);
      }
      work += static_cast<std::int64_t>(items.size());
      if (work > 100 * opt.max_patches)
        throw Error("untrim: more than " + std::to_string(100 * opt.max_patches) +
                    " curve pieces and knot lines over all slabs; expected at most 100 x "
                    "UntrimOptions::max_patches");
      if (items.empty()) continue;
      std::stable_sort(items.begin(), items.end(), [](const Item& a, const Item& b) {
        if (a.v_mid != b.v_mid) return a.v_mid < b.v_mid;
        return a.order_key < b.order_key;
      });
      int w = 0;
      for (std::size_t i = 0; i + 1 < items.size(); ++i) {
        w += items[i].sign();
        if (w == 0) continue;
        const Item& lo = items[i];
        const Item& hi = items[i + 1];
        double height = 0.0;
        for (int j = 1; j <= 7; ++j) {
          const double x = e0 + (e1 - e0) * j / 8.0;
          height = std::max(height, hi.v_at(x) - lo.v_at(x));
        }
        if (height <= tol) continue;
        if (w != 1)
          throw Error("untrim: the region between " + lo.name() + " and " + hi.name() + " near " +
                      point_text(um, 0.5 * (lo.v_mid + hi.v_mid)) + " has winding number " +
                      std::to_string(w) +
                      "; expected 0 or 1 (outer loops counter-clockwise, holes clockwise inside "
                      "them, loops not overlapping)");
        region(lo, hi, e0, e1, 0.5 * (lo.v_mid + hi.v_mid));
      }
      w += items.back().sign();
      if (w != 0)
        throw Error("untrim: winding number " + std::to_string(w) + " above " + items.back().name() +
                    " at u = " + num(um) + "; expected 0 (closed loops inside the parameter rectangle)");
    }
  }
};

/// Signed area enclosed by a planar curve, 1/2 int (x y' - y x') dt, exact with `order` Gauss
/// points per span (the integrand has degree 2 (order - 1) - 1).
double signed_area(const spline::Curve& c) {
  double a = 0.0;
  for (const auto& bz : spline::bezier_pieces(c)) {
    const auto dom = bz.domain(0);
    const auto rule = gauss_legendre(bz.orders()[0]);
    for (std::size_t i = 0; i < rule.nodes.size(); ++i) {
      const double t = 0.5 * (dom[0] + dom[1]) + 0.5 * (dom[1] - dom[0]) * rule.nodes[i];
      const auto d = bz.eval_derivatives({t}, 1);
      a += 0.5 * rule.weights[i] * 0.5 * (dom[1] - dom[0]) * (d[0] * d[static_cast<std::size_t>(bz.dim()) + 1] - d[1] * d[static_cast<std::size_t>(bz.dim())]);
    }
  }
  return a;
}

/// Whether the Bezier curve (control points x, y) stays in the rectangle within tol; on a point
/// of the curve outside it, that point.
bool inside_rectangle(const Poly& x, const Poly& y, const std::array<double, 4>& box, double tol, int depth,
                      std::array<double, 2>& bad) {
  auto in = [&](double a, double b) {
    return a >= box[0] - tol && a <= box[1] + tol && b >= box[2] - tol && b <= box[3] + tol;
  };
  bool all = true;
  for (std::size_t i = 0; i < x.size(); ++i) all = all && in(x[i], y[i]);
  if (all) return true;
  for (double s : {0.0, 0.5, 1.0}) {
    const double a = bern_eval(x, s), b = bern_eval(y, s);
    if (!in(a, b)) {
      bad = {a, b};
      return false;
    }
  }
  if (depth >= 20) return true;  // within rounding of the rectangle
  auto [xl, xr] = bern_split(x, 0.5);
  auto [yl, yr] = bern_split(y, 0.5);
  return inside_rectangle(xl, yl, box, tol, depth + 1, bad) && inside_rectangle(xr, yr, box, tol, depth + 1, bad);
}

double area_rule(const spline::Surface& s, int coord, int extra) {
  if (s.rational()) throw Error("surface area: a rational surface; expected a polynomial one");
  if (s.dim() < 3) throw Error("surface area: " + std::to_string(s.dim()) + " coordinates; expected xyz first");
  if (coord >= s.dim()) throw Error("integrate_coordinate: coordinate " + std::to_string(coord) + " of a surface with " + std::to_string(s.dim()) + "; expected one of its coordinates");
  const auto lim = default_limits();
  check_order(s.orders()[0], lim, "surface of orders (" + std::to_string(s.orders()[0]) + ", " + std::to_string(s.orders()[1]) + ")");
  check_order(s.orders()[1], lim, "surface of orders (" + std::to_string(s.orders()[0]) + ", " + std::to_string(s.orders()[1]) + ")");
  extra = std::clamp(extra, 0, 64);
  if (coord < 3) {
    // Area and the xyz integrals: the Gauss points of detail::patch_points (Bernstein tables on
    // Bezier patches, as untrim makes them).
    detail::PatchRules rules;
    std::vector<detail::PatchPoint> pts;
    detail::patch_points(s, [extra](int order) { return order + extra; }, rules, pts);
    double total = 0.0;
    for (const auto& q : pts) {
      const auto &a = q.xs, &b = q.xt;
      const double f = coord < 0 ? 1.0 : q.x[static_cast<std::size_t>(coord)];
      total += q.w * f * std::hypot(a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]);
    }
    return total;
  }
  // A property coordinate: evaluated per Gauss point.
  const auto ru = gauss_legendre(s.orders()[0] + extra), rv = gauss_legendre(s.orders()[1] + extra);
  const int k = s.dim();
  double total = 0.0;
  std::vector<double> d(static_cast<std::size_t>(3 * k));
  const auto bu = s.knots(0).breakpoints(), bv = s.knots(1).breakpoints();
  for (std::size_t jv = 0; jv + 1 < bv.size(); ++jv)
    for (std::size_t iu = 0; iu + 1 < bu.size(); ++iu) {
      const double u0 = bu[iu].value, u1 = bu[iu + 1].value, v0 = bv[jv].value, v1 = bv[jv + 1].value;
      double el = 0.0;
      for (std::size_t j = 0; j < rv.nodes.size(); ++j)
        for (std::size_t i = 0; i < ru.nodes.size(); ++i) {
          const double u = 0.5 * (u0 + u1) + 0.5 * (u1 - u0) * ru.nodes[i];
          const double v = 0.5 * (v0 + v1) + 0.5 * (v1 - v0) * rv.nodes[j];
          s.eval_derivatives({u, v}, 1, d.data());
          const double* a = d.data() + k;
          const double* b = d.data() + 2 * k;
          const double cx = a[1] * b[2] - a[2] * b[1], cy = a[2] * b[0] - a[0] * b[2], cz = a[0] * b[1] - a[1] * b[0];
          const double f = coord < 0 ? 1.0 : d[static_cast<std::size_t>(coord)];
          el += ru.weights[i] * rv.weights[j] * f * std::sqrt(cx * cx + cy * cy + cz * cz);
        }
      total += el * 0.25 * (u1 - u0) * (v1 - v0);
    }
  return total;
}

}  // namespace

TrimmedSurface::TrimmedSurface(spline::Surface surface, std::vector<TrimLoop> loops, double tolerance,
                               const Limits& limits)
    : surface_(std::move(surface)), loops_(std::move(loops)) {
  const auto& s = surface_;
  if (s.rational()) throw Error("trimmed surface: a rational surface; expected a polynomial B-spline surface");
  if (s.dim() < 3)
    throw Error("trimmed surface: " + std::to_string(s.dim()) + " coordinates; expected at least 3 (xyz)");
  const std::string sw = "trimmed surface of orders (" + std::to_string(s.orders()[0]) + ", " + std::to_string(s.orders()[1]) + ")";
  check_order(s.orders()[0], limits, sw);
  check_order(s.orders()[1], limits, sw);
  if (!(tolerance > 0.0) || !(tolerance < 1e-3))
    throw Error("trimmed surface: tolerance " + num(tolerance) + "; expected a relative tolerance in (0, 1e-3)");
  const auto du = s.domain(0), dv = s.domain(1);
  const double size = std::max(du[1] - du[0], dv[1] - dv[0]);
  tolerance_ = tolerance * size;
  const std::array<double, 4> box{du[0], du[1], dv[0], dv[1]};
  if (static_cast<std::int64_t>(loops_.size()) > limits.max_cells)
    throw Error("trimmed surface: " + std::to_string(loops_.size()) + " trimming loops; expected at most " +
                std::to_string(limits.max_cells) + limit_hint("max_cells"));
  std::vector<spline::Curve> all;
  std::vector<std::pair<int, int>> owner;
  for (std::size_t li = 0; li < loops_.size(); ++li) {
    const auto& lp = loops_[li].pieces;
    if (lp.empty()) throw Error("trimming loop " + std::to_string(li) + ": no pieces; expected a closed chain of curves");
    for (std::size_t pi = 0; pi < lp.size(); ++pi) {
      const auto& c = lp[pi];
      const std::string w = where(static_cast<int>(li), static_cast<int>(pi));
      if (c.rational()) throw Error(w + ": a rational curve; expected a polynomial B-spline curve");
      if (c.dim() != 2) throw Error(w + ": " + std::to_string(c.dim()) + " coordinates; expected 2 (u, v)");
      check_order(c.orders()[0], limits, w + ", a curve of order " + std::to_string(c.orders()[0]));
      if (c.size() > limits.max_points)
        throw Error(w + ": " + std::to_string(c.size()) + " control points; expected at most " +
                    std::to_string(limits.max_points) + limit_hint("max_points"));
      if (static_cast<std::int64_t>(all.size()) >= limits.max_cells)
        throw Error("trimmed surface: more than " + std::to_string(limits.max_cells) + " trimming curves; expected at most that many" + limit_hint("max_cells"));
      // Closed: this piece's end is the next piece's start.
      const auto& next = lp[(pi + 1) % lp.size()];
      const auto e = c.eval({c.domain(0)[1]}), b = next.eval({next.domain(0)[0]});
      const double gap = std::hypot(e[0] - b[0], e[1] - b[1]);
      if (!(gap <= tolerance_))
        throw Error(w + ": ends at " + point_text(e[0], e[1]) + " but piece " +
                    std::to_string((pi + 1) % lp.size()) + " starts at " + point_text(b[0], b[1]) +
                    " (gap " + num(gap) + "); expected a closed loop (gap at most " + num(tolerance_) + ")");
      for (const auto& bz : spline::bezier_pieces(c)) {
        Poly x(static_cast<std::size_t>(bz.size())), y(x.size());
        for (int i = 0; i < bz.size(); ++i) x[static_cast<std::size_t>(i)] = bz.point(i)[0], y[static_cast<std::size_t>(i)] = bz.point(i)[1];
        std::array<double, 2> bad{};
        if (!inside_rectangle(x, y, box, tolerance_, 0, bad))
          throw Error(w + ": the point " + point_text(bad[0], bad[1]) + " lies outside the parameter rectangle [" +
                      num(du[0]) + ", " + num(du[1]) + "] x [" + num(dv[0]) + ", " + num(dv[1]) +
                      "]; expected trimming curves inside it");
      }
      all.push_back(c);
      owner.push_back({static_cast<int>(li), static_cast<int>(pi)});
    }
  }
  if (!all.empty()) {
    if (const auto x = first_crossing(all, std::max(1e-6 * size, 10.0 * tolerance_))) {
      const auto [la, pa] = owner[static_cast<std::size_t>(x->curve_a)];
      const auto [lb, pb] = owner[static_cast<std::size_t>(x->curve_b)];
      throw Error(where(la, pa) + " meets " + (x->curve_a == x->curve_b ? std::string("itself") : where(lb, pb)) +
                  " near " + point_text(x->point[0], x->point[1]) +
                  "; expected trimming loops that neither cross nor touch");
    }
  }
  bool outer = loops_.empty();
  for (std::size_t li = 0; li < loops_.size(); ++li) {
    double a = 0.0;
    for (const auto& c : loops_[li].pieces) a += signed_area(c);
    if (!(std::abs(a) > tolerance_ * size))
      throw Error("trimming loop " + std::to_string(li) + ": encloses an area of " + num(a) +
                  "; expected a loop around a region");
    loop_areas_.push_back(a);
    outer = outer || a > 0.0;
  }
  if (!outer)
    throw Error("trimmed surface: every trimming loop is clockwise; expected a counter-clockwise outer loop "
                "(holes clockwise inside it)");
}

Untrimmed untrim(const TrimmedSurface& trimmed, const UntrimOptions& options) {
  if (options.max_patches < 1 || options.max_splits < 0)
    throw Error("untrim: max_patches " + std::to_string(options.max_patches) + ", max_splits " +
                std::to_string(options.max_splits) + "; expected at least 1 and 0");
  Builder b(trimmed, options);
  b.run();
  return std::move(b.out);
}

double surface_area(const spline::Surface& s, int extra_points) { return area_rule(s, -1, extra_points); }

double integrate_coordinate(const spline::Surface& s, int coord, int extra_points) {
  if (coord < 0) throw Error("integrate_coordinate: coordinate " + std::to_string(coord) + "; expected 0 or more");
  return area_rule(s, coord, extra_points);
}

double area(const Untrimmed& untrimmed) {
  double a = 0.0;
  for (const auto& p : untrimmed.patches) a += surface_area(p);
  return a;
}

double area(const TrimmedSurface& trimmed, const UntrimOptions& options) { return area(untrim(trimmed, options)); }

double integrate_coordinate(const Untrimmed& untrimmed, int coord) {
  double a = 0.0;
  for (const auto& p : untrimmed.patches) a += integrate_coordinate(p, coord);
  return a;
}

}  // namespace trivox::geom
