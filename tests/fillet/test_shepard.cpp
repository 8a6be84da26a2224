// Shepard (Euclidean-distance) property blending of fillets (fillet/shepard.hpp; Masalha et al.
// 2021 Sec. 7.2). Truths, from the mathematics alone:
// - the weights: alpha_1 + alpha_2 = 1 (Eq. 9b), alpha_i = 1 where d_i = 0 (Eq. 9a), both in
//   [0, 1] (Eq. 9c), alpha_1 = d_1^-q / (d_1^-q + d_2^-q);
// - a planar corner (floor z = 0, x in [2, 3]; wall x = 2, z in [0, 1]; constant colours): the
//   distances are z and x - 2, so f is analytic;
// - a real fillet (models/fillet_spheres.json, blend shepard): f = g_i on S^_i; the encoded half's
//   face w = 0 is the parametric half's, bit for bit; f is continuous (no jump between
//   neighbouring points beyond a Lipschitz bound, across the two halves too); warm and cold
//   queries agree; the encoding's errors are small and the same for any thread count.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include <tbb/global_control.h>

#include "trivox/fillet/shepard.hpp"
#include "trivox/io/model_json.hpp"
#include "trivox/scene/scene.hpp"
#include "trivox/spline/extract.hpp"

using namespace trivox;
using spline::KnotVector;
using spline::Surface;

namespace {

/// A bilinear patch through four corners (u fastest), in R^dim, elevated to bicubic so that
/// evaluation is not trivially linear.
Surface patch(const std::vector<double>& c00, const std::vector<double>& c10, const std::vector<double>& c01,
              const std::vector<double>& c11) {
  std::vector<double> pts;
  for (const auto* c : {&c00, &c10, &c01, &c11}) pts.insert(pts.end(), c->begin(), c->end());
  return Surface({KnotVector::bezier(2), KnotVector::bezier(2)}, static_cast<int>(c00.size()), pts);
}

double ipow(double x, int q) {
  double r = 1.0;
  for (int k = 0; k < q; ++k) r *= x;
  return r;
}

const scene::SceneBuild& spheres(bool shepard) {
  static const auto build = [](bool s) {
    auto scene = scene::load_scene(std::string(TRIVOX_SOURCE_DIR) + "/models/fillet_spheres.json");
    for (auto& op : scene.operations)
      if (op.op == "fillet") op.shepard = s;
    return scene::build_scene(scene);
  };
  static const scene::SceneBuild parametric = build(false), with_shepard = build(true);
  return shepard ? with_shepard : parametric;
}

}  // namespace

TEST_CASE("Shepard weights: partition of unity, feature preservation, positivity", "[shepard]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(0.0, 3.0);
  for (int q = 1; q <= 16; ++q) {
    for (int n = 0; n < 2000; ++n) {
      const double d1 = U(rng), d2 = U(rng);
      const auto a = vmodel::shepard_weights(d1, d2, q);
      CHECK(a[0] + a[1] == Approx(1.0).margin(1e-15));
      CHECK(a[0] >= 0.0);
      CHECK(a[1] >= 0.0);
      CHECK(a[0] <= 1.0);
      // The paper's form, where it is well defined.
      const double e1 = std::pow(d1, -q), e2 = std::pow(d2, -q);
      if (std::isfinite(e1) && std::isfinite(e2) && std::isfinite(e1 + e2)) CHECK(a[0] == Approx(e1 / (e1 + e2)).epsilon(1e-13));
      // Symmetry.
      const auto b = vmodel::shepard_weights(d2, d1, q);
      CHECK(b[0] == Approx(a[1]).margin(1e-15));
    }
    // On S^_i: alpha_i = 1 exactly.
    CHECK(vmodel::shepard_weights(0.0, 0.7, q)[0] == 1.0);
    CHECK(vmodel::shepard_weights(0.7, 0.0, q)[1] == 1.0);
    CHECK(vmodel::shepard_weights(1e-300, 1.0, q)[0] == 1.0);
    // On C both vanish: the mean.
    CHECK(vmodel::shepard_weights(0.0, 0.0, q)[0] == 0.5);
    // Continuity: alpha_1 is monotone in d_1 and continuous (small steps, small changes).
    double prev = vmodel::shepard_weights(0.0, 1.0, q)[0];
    for (int k = 1; k <= 1000; ++k) {
      const double a1 = vmodel::shepard_weights(k * 0.003, 1.0, q)[0];
      CHECK(a1 <= prev);
      CHECK(prev - a1 < 0.003 * q);  // |d alpha / d d_1| <= q / (4 d_1) * ... < q near d_1 ~ 1
      prev = a1;
    }
  }
}

TEST_CASE("Shepard blend of a planar corner is the analytic formula", "[shepard]") {
  // Floor S^_1: z = 0, x in [2, 3], y in [0, 4], red; wall S^_2: x = 2, z in [0, 1], blue.
  const Surface floor_ = patch({2, 0, 0, 1, 0, 0}, {3, 0, 0, 1, 0, 0}, {2, 4, 0, 1, 0, 0}, {3, 4, 0, 1, 0, 0});
  const Surface wall = patch({2, 0, 0, 0, 0, 1}, {2, 4, 0, 0, 0, 1}, {2, 0, 1, 0, 0, 1}, {2, 4, 1, 0, 0, 1});
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (int q : {1, 2, 3, 8}) {
    const vmodel::ShepardField field({floor_, wall}, q);
    vmodel::ShepardWalk walk;
    double worst = 0.0;
    std::array<double, 3> p{2.5, 0.3, 0.4};
    for (int n = 0; n < 3000; ++n) {
      // A random walk (warm starts) with occasional jumps.
      if (n % 100 == 0) p = {2.0 + U(rng), 4.0 * U(rng), U(rng)};
      p = {std::clamp(p[0] + 0.01 * (U(rng) - 0.5), 2.001, 2.999), std::clamp(p[1] + 0.01 * (U(rng) - 0.5), 0.0, 4.0),
           std::clamp(p[2] + 0.01 * (U(rng) - 0.5), 0.001, 0.999)};
      const double dz = p[2], dx = p[0] - 2.0;
      const double a1 = (1 / ipow(dz, q)) / (1 / ipow(dz, q) + 1 / ipow(dx, q));  // the paper's form
      double f[3], g[3];
      const auto v = field.eval(p, f, &walk);
      field.eval(p, g);  // cold
      CHECK(v.distance[0] == Approx(dz).margin(1e-12));
      CHECK(v.distance[1] == Approx(dx).margin(1e-12));
      const double e = std::max({std::abs(f[0] - a1), std::abs(f[2] - (1 - a1)), std::abs(f[1]), std::abs(f[0] - g[0])});
      if (e > 1e-12 && worst <= 1e-12)
        WARN("q " << q << " p " << p[0] << " " << p[1] << " " << p[2] << " f " << f[0] << " " << f[2] << " cold " << g[0]
                  << " a1 " << a1 << " d " << v.distance[0] << " " << v.distance[1]);
      worst = std::max(worst, e);
    }
    CHECK(worst < 1e-12);
    CHECK(walk.warm > 5000);  // nearly every query warm
  }
  // On the floor f is red, on the wall blue (feature preservation), on C the mean.
  const vmodel::ShepardField field({floor_, wall}, 2);
  double f[3];
  field.eval({2.5, 1.0, 0.0}, f);
  CHECK(f[0] == 1.0);
  CHECK(f[2] == 0.0);
  field.eval({2.0, 1.0, 0.5}, f);
  CHECK(f[2] == 1.0);
  field.eval({2.0, 1.0, 0.0}, f);
  CHECK(f[0] == 0.5);
  CHECK_THROWS_WITH(vmodel::ShepardField({floor_, wall}, 17), Catch::Contains("1..16"));
  CHECK_THROWS_WITH(vmodel::ShepardField({floor_, spline::Surface({KnotVector::bezier(2), KnotVector::bezier(2)}, 3,
                                                                    std::vector<double>(12, 0.0))},
                                          2),
                    Catch::Contains("the same"));
}

TEST_CASE("Shepard fillet of two spheres: reproduction on S^_i, pinned face, continuity, fit", "[shepard]") {
  const auto& par = spheres(false).model;
  const auto& shp = spheres(true).model;
  REQUIRE(shp.cells.size() == 4);
  const auto* a = shp.find_cell("fillet.1a");
  const auto* b = shp.find_cell("fillet.1b");
  REQUIRE(a);
  REQUIRE(b);
  REQUIRE(a->shepard);
  REQUIRE(b->shepard);
  CHECK(a->shepard->power == 2);
  CHECK(*a->shepard == *b->shepard);
  const vmodel::ShepardField field(*a->shepard);
  for (int h = 0; h < 2; ++h) {
    const auto& enc = shp.cells[static_cast<std::size_t>(2 + h)].volume;
    const auto& half = par.cells[static_cast<std::size_t>(2 + h)].volume;
    // The pinned face: the encoded half's face w = 0 is S^_i with g_i, the Shepard data's source,
    // control point for control point; as a function it is the parametric half's face (refined
    // across C), to rounding.
    const Surface e0 = spline::boundary_face(enc, spline::Face::w0), p0 = spline::boundary_face(half, spline::Face::w0);
    CHECK(e0 == a->shepard->sources[static_cast<std::size_t>(h)]);
    double face_gap = 0.0;
    for (int i = 0; i <= 50; ++i)
      for (int j = 0; j <= 20; ++j) {
        const auto x = e0.eval({i / 50.0, j / 20.0}), y = p0.eval({i / 50.0, j / 20.0});
        for (std::size_t k = 0; k < x.size(); ++k) face_gap = std::max(face_gap, std::abs(x[k] - y[k]));
      }
    CHECK(face_gap < 1e-13);
    // The unpinned control points differ (the fit moved them); the pinned layer is g_i exactly.
    const auto dims = enc.counts();
    for (int j = 0; j < dims[1]; j += 3)
      for (int i = 0; i < dims[0]; i += 97) {
        const auto cp = enc.point(enc.row({i, j, 0}));
        const auto sp = e0.point(e0.row({i, j}));
        CHECK(std::equal(cp.begin(), cp.end(), sp.begin(), sp.end()));
      }
    // f = g_i on S^_i: the exact blend at points of the face reproduces the face's properties.
    double worst = 0.0;
    for (int i = 0; i <= 40; ++i)
      for (int j = 0; j <= 8; ++j) {
        const double u = i / 40.0, v = 0.05 + 0.9 * j / 8.0;  // off C (v = 1 of a, v = 0 of b) and the rail
        const auto x = e0.eval({u, h == 0 ? v * 0.95 : 0.05 + v * 0.95});
        double f[3];
        field.eval({x[0], x[1], x[2]}, f);
        for (int k = 0; k < 3; ++k) worst = std::max(worst, std::abs(f[k] - x[static_cast<std::size_t>(3 + k)]));
      }
    CHECK(worst < 1e-9);
    // The geometry is the parametric half's (w refined only).
    double gap = 0.0;
    for (int n = 0; n < 200; ++n) {
      const std::array<double, 3> t{(n % 10) / 9.0, ((n / 10) % 5) / 4.0, (n / 50) / 3.0};
      const auto xe = enc.eval(t), xp = half.eval(t);
      for (int k = 0; k < 3; ++k) gap = std::max(gap, std::abs(xe[static_cast<std::size_t>(k)] - xp[static_cast<std::size_t>(k)]));
    }
    CHECK(gap < 1e-12);
  }
  // The fit report: f is discontinuous at C (g_1 != g_2 there), so the least-squares error is
  // largest next to C; on average it is small.
  const auto& fits = spheres(true).fillets.front().shepard;
  REQUIRE(fits.size() == 2);
  for (const auto& f : fits) {
    INFO("max " << f.max_error << " rms " << f.rms_error << " check " << f.check_error << " samples " << f.samples
                << " s " << f.seconds);
    CHECK(f.samples > 1000);
    CHECK(f.rms_error < 0.05);
    CHECK(f.max_error < 0.6);
  }
  // Continuity of the exact f along a segment from deep in half a to deep in half b (across
  // their shared face), warm and cold: neighbouring values differ by at most a Lipschitz bound.
  const auto pa = a->volume.eval({0.3, 0.8, 0.5}), pb = b->volume.eval({0.3, 0.2, 0.5});
  vmodel::ShepardWalk walk;
  double prev[3] = {0, 0, 0}, jump = 0.0, warm_cold = 0.0;
  const int n = 2000;
  for (int k = 0; k <= n; ++k) {
    const double s = static_cast<double>(k) / n;
    const std::array<double, 3> p{pa[0] + s * (pb[0] - pa[0]), pa[1] + s * (pb[1] - pa[1]), pa[2] + s * (pb[2] - pa[2])};
    double f[3], g[3];
    field.eval(p, f, &walk);
    field.eval(p, g);
    for (int c = 0; c < 3; ++c) {
      warm_cold = std::max(warm_cold, std::abs(f[c] - g[c]));
      if (k) jump = std::max(jump, std::abs(f[c] - prev[c]));
      prev[c] = f[c];
    }
  }
  CHECK(warm_cold < 1e-12);
  CHECK(jump < 0.01);  // 2000 steps across the whole colour change: no jump
  CHECK(walk.cold <= 2);
}

TEST_CASE("Shepard encoding is independent of the thread count", "[shepard]") {
  const auto& par = spheres(false).model;
  const auto& shp = spheres(true).model;
  // As the scene builds it: f from the parametric halves' faces w = 0.
  const vmodel::ShepardField field({spline::boundary_face(par.cells[2].volume, spline::Face::w0),
                                    spline::boundary_face(par.cells[3].volume, spline::Face::w0)},
                                   shp.cells[2].shepard->power);
  tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  const auto e1 = fillet::encode_shepard(par.cells[2].volume, field);
  CHECK(e1.half == shp.cells[2].volume);
  CHECK_THROWS_WITH(fillet::encode_shepard(par.cells[2].volume, field, {.w_spans = 0}), Catch::Contains("out of range"));
}

TEST_CASE("Shepard data round-trips through the model file", "[shepard]") {
  const auto& shp = spheres(true).model;
  const std::string text = io::write_model_json(shp);
  CHECK(text.find("\"shepard\": {\"power\": 2, \"surfaces\": ") != std::string::npos);
  const auto back = io::read_model_json(text, "x.json");
  CHECK(back == shp);  // bit-exact, Shepard data included
  // Bad Shepard data is refused with the place and what was expected.
  std::string bad = text;
  bad.replace(bad.find("\"power\": 2"), 10, "\"power\": 0");
  CHECK_THROWS_WITH(io::read_model_json(bad, "x.json"), Catch::Contains("/cells/2/shepard/power") && Catch::Contains("1..16"));
  auto m = shp;
  m.cells[2].shepard->power = 20;
  CHECK_THROWS_WITH(io::write_model_json(m), Catch::Contains("Shepard power 20"));
}
