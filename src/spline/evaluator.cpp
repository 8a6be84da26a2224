#include "trivox/spline/evaluator.hpp"

#include <algorithm>
#include <cmath>

namespace trivox::spline {

namespace {

/// One point on a cached line: out = sum_a N[a] c[a] (and the partials from dN and the other
/// lines). O: order along the line, H: coordinates; 0 = known only at run time.
template <int O, int H>
void line_kernel(int order, int dim, int lines, const double* N, const double* dN, const double* const* c, double* out) {
  const int o = O ? O : order;
  const int D = H ? H : dim;
  const double* c0 = c[0];
  for (int h = 0; h < D; ++h) {
    double acc = 0.0;
    for (int a = 0; a < o; ++a) acc += N[a] * c0[a * D + h];
    out[h] = acc;
  }
  if (!dN) return;
  for (int h = 0; h < D; ++h) {
    double acc = 0.0;
    for (int a = 0; a < o; ++a) acc += dN[a] * c0[a * D + h];
    out[D + h] = acc;
  }
  for (int k = 1; k < lines; ++k) {
    const double* ck = c[k];
    double* dk = out + (1 + k) * D;
    for (int h = 0; h < D; ++h) {
      double acc = 0.0;
      for (int a = 0; a < o; ++a) acc += N[a] * ck[a * D + h];
      dk[h] = acc;
    }
  }
}

using LineKernel = void (*)(int, int, int, const double*, const double*, const double* const*, double*);

template <int O>
LineKernel pick_dim(int dim) {
  switch (dim) {
    case 1: return line_kernel<O, 1>;
    case 3: return line_kernel<O, 3>;
    case 4: return line_kernel<O, 4>;
    case 6: return line_kernel<O, 6>;
    default: return line_kernel<O, 0>;
  }
}

LineKernel pick_line_kernel(int order, int dim) {
  switch (order) {
    case 2: return pick_dim<2>(dim);
    case 3: return pick_dim<3>(dim);
    case 4: return pick_dim<4>(dim);
    default: return pick_dim<0>(dim);
  }
}

}  // namespace

template <int P>
Evaluator<P>::Evaluator(const TensorSpline<P>& s)
    : s_(&s), dim_(s.dim()), line_kernel_(pick_line_kernel(s.knots(0).order(), s.dim())) {}

template <int P>
bool Evaluator<P>::cacheable() const noexcept {
  if (P == 1 || s_->rational()) return false;
  for (int d = 0; d < P; ++d)
    if (s_->knots(d).order() > 16) return false;
  return true;
}

template <int P>
void Evaluator<P>::basis_at(int d, double t, bool derivs, Basis1& b) {
  const KnotVector& kv = s_->knots(d);
  t = std::isnan(t) ? kv.front() : std::clamp(t, kv.front(), kv.back());
  const int span = kv.find_span(t, hint_[d]);
  hint_[d] = span;
  b.first = span - kv.order() + 1;
  if (derivs)
    kv.basis_derivatives(span, t, 1, &b.N[0][0]);  // rows of `order` values: N[0][0..o), then derivs
  else
    kv.basis(span, t, b.N[0]);
}

template <int P>
void Evaluator<P>::build_slab(double w, bool derivs) {
  // P == 3 only. slab_[0](i, j) = sum_c N_w[c] P(i, j, k0 + c); slab_[1] with N_w'.
  Basis1 bw;
  basis_at(2, w, derivs, bw);
  const int o = s_->knots(2).order();
  const double* dN = &bw.N[0][0] + o;  // basis_derivatives packs rows of length `order`
  const int n01 = s_->count(0) * (P > 1 ? s_->count(1) : 1);
  const std::size_t len = static_cast<std::size_t>(n01) * static_cast<std::size_t>(dim_);
  for (int k = 0; k < (derivs ? 2 : 1); ++k) slab_[k].assign(len, 0.0);
  const double* pts = s_->points().data();
  for (int c = 0; c < o; ++c) {
    const double* src = pts + static_cast<std::size_t>(bw.first + c) * len;
    const double n0 = bw.N[0][c];
    for (std::size_t i = 0; i < len; ++i) slab_[0][i] += n0 * src[i];
    if (derivs) {
      const double n1 = dN[c];
      for (std::size_t i = 0; i < len; ++i) slab_[1][i] += n1 * src[i];
    }
  }
  slab_valid_ = true;
  slab_derivs_ = derivs;
  slab_key_ = w;
}

template <int P>
void Evaluator<P>::build_line(const Params& t, bool derivs) {
  const int n0 = s_->count(0);
  const std::size_t len = static_cast<std::size_t>(n0) * static_cast<std::size_t>(dim_);
  const int lines = derivs ? P : 1;  // value, d/dt_1, d/dt_2
  for (int k = 0; k < lines; ++k) line_[k].assign(len, 0.0);
  Basis1 bv;
  basis_at(1, t[1 % P], derivs, bv);
  const int ov = s_->knots(1 % P).order();
  const double* dNv = &bv.N[0][0] + ov;
  const double* pts = s_->points().data();
  if constexpr (P == 2) {
    for (int b = 0; b < ov; ++b) {
      const double* src = pts + static_cast<std::size_t>(bv.first + b) * len;
      for (std::size_t i = 0; i < len; ++i) line_[0][i] += bv.N[0][b] * src[i];
      if (derivs)
        for (std::size_t i = 0; i < len; ++i) line_[1][i] += dNv[b] * src[i];
    }
  } else if constexpr (P == 3) {
    const double w = t[2];
    // A second line on the same w makes the slab worth building.
    const bool slab_ok = slab_valid_ && slab_key_ == w && (slab_derivs_ || !derivs);
    if (!slab_ok && have_prev_line_w_ && prev_line_w_ == w) build_slab(w, derivs);
    prev_line_w_ = w;
    have_prev_line_w_ = true;
    const std::size_t plane = len * static_cast<std::size_t>(s_->count(1));
    if (slab_valid_ && slab_key_ == w && (slab_derivs_ || !derivs)) {
      for (int b = 0; b < ov; ++b) {
        const std::size_t off = static_cast<std::size_t>(bv.first + b) * len;
        const double* s0 = slab_[0].data() + off;
        for (std::size_t i = 0; i < len; ++i) line_[0][i] += bv.N[0][b] * s0[i];
        if (derivs) {
          const double* s1 = slab_[1].data() + off;
          for (std::size_t i = 0; i < len; ++i) {
            line_[1][i] += dNv[b] * s0[i];
            line_[2][i] += bv.N[0][b] * s1[i];
          }
        }
      }
    } else {
      Basis1 bw;
      basis_at(2, w, derivs, bw);
      const int ow = s_->knots(2).order();
      const double* dNw = &bw.N[0][0] + ow;
      for (int c = 0; c < ow; ++c)
        for (int b = 0; b < ov; ++b) {
          const double* src = pts + static_cast<std::size_t>(bw.first + c) * plane +
                              static_cast<std::size_t>(bv.first + b) * len;
          const double c0 = bv.N[0][b] * bw.N[0][c];
          for (std::size_t i = 0; i < len; ++i) line_[0][i] += c0 * src[i];
          if (derivs) {
            const double cv = dNv[b] * bw.N[0][c], cw = bv.N[0][b] * dNw[c];
            for (std::size_t i = 0; i < len; ++i) {
              line_[1][i] += cv * src[i];
              line_[2][i] += cw * src[i];
            }
          }
        }
    }
  }
  line_valid_ = true;
  line_derivs_ = derivs;
  line_key_ = {P > 1 ? t[1 % P] : 0.0, P > 2 ? t[2 % P] : 0.0};
}

template <int P>
void Evaluator<P>::eval_on_line(double u, bool derivs, double* out) {
  Basis1 bu;
  basis_at(0, u, derivs, bu);
  const int o = s_->knots(0).order();
  const auto off = static_cast<std::size_t>(bu.first) * static_cast<std::size_t>(dim_);
  const double* c[3] = {line_[0].data() + off, derivs && P > 1 ? line_[1].data() + off : nullptr,
                        derivs && P > 2 ? line_[2].data() + off : nullptr};
  line_kernel_(o, dim_, P, bu.N[0], derivs ? &bu.N[0][0] + o : nullptr, c, out);
}

namespace {
template <int P>
std::array<double, 2> slow_key(const std::array<double, P>& t) {
  return {P > 1 ? t[1 % P] : 0.0, P > 2 ? t[2 % P] : 0.0};
}
}  // namespace

template <int P>
void Evaluator<P>::eval(const Params& t, double* out) {
  if (cacheable()) {
    const auto key = slow_key<P>(t);
    if (line_valid_ && line_key_ == key) return eval_on_line(t[0], false, out);
    if (have_prev_line_key_ && prev_line_key_ == key) {
      build_line(t, false);
      return eval_on_line(t[0], false, out);
    }
    prev_line_key_ = key;
    have_prev_line_key_ = true;
  }
  s_->eval(t, out);
}

template <int P>
void Evaluator<P>::eval_first(const Params& t, double* out) {
  if (cacheable()) {
    const auto key = slow_key<P>(t);
    if (line_valid_ && line_derivs_ && line_key_ == key) return eval_on_line(t[0], true, out);
    if (have_prev_line_key_ && prev_line_key_ == key) {
      build_line(t, true);
      return eval_on_line(t[0], true, out);
    }
    prev_line_key_ = key;
    have_prev_line_key_ = true;
  }
  s_->eval_derivatives(t, 1, out);
}

template class Evaluator<1>;
template class Evaluator<2>;
template class Evaluator<3>;

}  // namespace trivox::spline
