// Evaluation throughput of the spline kernel on one thread (issue 2's benchmark).
//
// A tricubic trivariate with 10 x 10 x 10 control points in R^6 (xyz + rgb), evaluated at 1M
// parameters: random, and coherent (scanlines: u varies fastest on a 100 x 100 x 100 grid).
// Prints evaluations per second for position only and for position with the three first
// partials, for the plain per-point evaluation (the reference, TensorSpline::eval*) and for the
// coherent Evaluator, with their ratio. A checksum keeps the compiler from dropping work and
// shows both paths compute the same values.
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <algorithm>
#include <cstdio>
#include <random>
#include <vector>

#include "trivox/spline/evaluator.hpp"
#include "trivox/spline/tensor_spline.hpp"

using namespace trivox::spline;
using Clock = std::chrono::steady_clock;

namespace {

Trivariate make_spline() {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  const int n = 10, dim = 6;
  std::vector<double> pts(static_cast<std::size_t>(n * n * n * dim));
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        double* p = &pts[static_cast<std::size_t>(((k * n + j) * n + i) * dim)];
        p[0] = i + 0.1 * U(rng);
        p[1] = j + 0.1 * U(rng);
        p[2] = k + 0.1 * U(rng);
        for (int h = 3; h < dim; ++h) p[h] = 0.5 + 0.5 * U(rng);
      }
  const KnotVector kv = KnotVector::uniform(4, n - 3);
  return Trivariate({kv, kv, kv}, dim, std::move(pts));
}

template <class F>
double measure(std::size_t count, F&& f) {
  // Best of three runs, in evaluations per second.
  double best = 0.0;
  for (int rep = 0; rep < 3; ++rep) {
    const auto t0 = Clock::now();
    f();
    const double s = std::chrono::duration<double>(Clock::now() - t0).count();
    best = std::max(best, count / s);
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  const Trivariate s = make_spline();
  // Optional argument: points per grid direction (default 100, i.e. 10^6 parameters).
  const int g = argc > 1 ? std::max(2, std::atoi(argv[1])) : 100;
  const std::size_t N = static_cast<std::size_t>(g) * g * g;
  std::vector<std::array<double, 3>> coherent(N), random(N);
  for (int k = 0, r = 0; k < g; ++k)
    for (int j = 0; j < g; ++j)
      for (int i = 0; i < g; ++i, ++r)
        coherent[static_cast<std::size_t>(r)] = {(i + 0.5) / g, (j + 0.5) / g, (k + 0.5) / g};
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (auto& p : random) p = {U(rng), U(rng), U(rng)};

  double sink = 0.0;
  std::vector<double> out(4 * 6);
  auto plain = [&](const std::vector<std::array<double, 3>>& ps, int order) {
    return measure(N, [&] {
      for (const auto& p : ps) {
        s.eval_derivatives(p, order == 0 ? 0 : 1, out.data());
        sink += out[0] + out[order == 0 ? 1 : 9];
      }
    });
  };
  auto cached = [&](const std::vector<std::array<double, 3>>& ps, int order) {
    return measure(N, [&] {
      Evaluator<3> ev(s);
      for (const auto& p : ps) {
        if (order == 0) ev.eval(p, out.data()); else ev.eval_first(p, out.data());
        sink += out[0] + out[order == 0 ? 1 : 9];
      }
    });
  };
  std::printf("trivox bench_eval: tricubic trivariate, 10^3 control points in R^6, %zu parameters, 1 thread\n", N);
  std::printf("%-12s %-18s %16s %16s %8s\n", "parameters", "what", "reference [1/s]", "Evaluator [1/s]", "ratio");
  for (int order = 0; order <= 1; ++order)
    for (int which = 0; which < 2; ++which) {
      const auto& ps = which == 0 ? coherent : random;
      const double ref = plain(ps, order), fast = cached(ps, order);
      std::printf("%-12s %-18s %16.3e %16.3e %8.2f\n", which == 0 ? "coherent" : "random",
                  order == 0 ? "position" : "position+d1", ref, fast, fast / ref);
    }
  std::printf("(checksum %.6e)\n", sink);
  return 0;
}
