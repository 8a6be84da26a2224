// Trimmed boundary faces of Boolean pieces (slice/boundary_faces.hpp). Truths, for the box
// A = [0, 2]^2 x [0, 1] and the box B = [0.5, 1.5]^2 x [-1, 2] passing through it along z:
// - A - B is A with a square through-hole: its top and bottom faces are 4 - 1 = 3 each, its
//   four sides 2 each, the hole's four walls 1 x 1 each: 18 in all;
// - A n B is the unit cube [0.5, 1.5]^2 x [0, 1]: 6;
// - the boundary of A - B and of A n B together are the boundary of A plus the part of B's
//   boundary inside A counted twice (once as the hole's wall, once as the cube's sides):
//   area(d(A - B)) + area(d(A n B)) = area(dA) + 2 area(dB n A) = 16 + 2 x 4.
// Planar faces: the areas are polygon areas, exact to 1e-8.
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "trivox/error.hpp"
#include "trivox/slice/boundary_faces.hpp"
#include "trivox/vmodel/boolean.hpp"

using namespace trivox;
using spline::KnotVector;
using vmodel::BooleanOp;
using vmodel::VModel;

namespace {

VModel box(const std::string& name, std::array<double, 3> lo, std::array<double, 3> hi) {
  std::vector<double> pts;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) pts.insert(pts.end(), {i ? hi[0] : lo[0], j ? hi[1] : lo[1], k ? hi[2] : lo[2], 0.5});
  const KnotVector b = KnotVector::bezier(2);
  VModel m;
  m.properties = {"r"};
  m.cells.push_back({name, spline::Trivariate({b, b, b}, 4, pts)});
  return m;
}

double model_boundary(const VModel& m, std::vector<slice::BoundaryFace>* all = nullptr) {
  double a = 0;
  for (int c = 0; c < static_cast<int>(m.cells.size()); ++c) {
    auto f = slice::boundary_faces(m, c);
    a += slice::boundary_area(f);
    if (all) all->insert(all->end(), f.begin(), f.end());
  }
  return a;
}

}  // namespace

TEST_CASE("boundary faces of a box minus a box through it", "[boundary_faces]") {
  const VModel A = box("A", {0, 0, 0}, {2, 2, 1}), B = box("B", {0.5, 0.5, -1}, {1.5, 1.5, 2});
  const VModel D = vmodel::boolean(A, B, BooleanOp::subtraction);
  std::vector<slice::BoundaryFace> faces;
  const double d = model_boundary(D, &faces);
  std::printf("box minus box: boundary area %.15g (expected 18), %zu faces\n", d, faces.size());
  CHECK(std::abs(d - 18) <= 1e-8 * 18);
  // The top face (z = 1) of A: 4 - 1.
  int tops = 0;
  for (const auto& f : faces)
    if (f.source == -1 && f.face == spline::Face::w1) {
      ++tops;
      CHECK(std::abs(f.area - 3) <= 1e-8 * 3);
    }
  CHECK(tops == 1);
  // The hole's walls: faces of B (source >= 0), 1 each.
  double walls = 0;
  for (const auto& f : faces)
    if (f.source >= 0) walls += f.area;
  CHECK(std::abs(walls - 4) <= 1e-8 * 4);

  const VModel I = vmodel::boolean(A, B, BooleanOp::intersection);
  const double i = model_boundary(I);
  std::printf("box and box: boundary area %.15g (expected 6)\n", i);
  CHECK(std::abs(i - 6) <= 1e-8 * 6);
  CHECK(std::abs(d + i - (16 + 2 * 4)) <= 1e-8 * 24);
}

TEST_CASE("boundary faces refuse a cell out of range", "[boundary_faces]") {
  const VModel A = box("A", {0, 0, 0}, {2, 2, 1});
  CHECK_THROWS_AS(slice::boundary_faces(A, 1), Error);
  // A plain cell's boundary is its six faces.
  CHECK(std::abs(slice::boundary_area(slice::boundary_faces(A, 0)) - 16) <= 1e-8 * 16);
}
