// Property integrals of cells and pieces (property_integrals.hpp).
#include "trivox/slice/property_integrals.hpp"

#include <cmath>

#include "trivox/error.hpp"
#include "trivox/geom/quadrature.hpp"
#include "trivox/spline/refine.hpp"

namespace trivox::slice {

namespace {

using Mat3 = std::array<std::array<double, 3>, 3>;

double det3(const Mat3& a) {
  return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
         a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
}

/// The inverse of a (columns: the partials X_u, X_v, X_w), by the adjugate.
Mat3 inverse3(const Mat3& a, double det) {
  Mat3 r{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const int i1 = (j + 1) % 3, i2 = (j + 2) % 3, j1 = (i + 1) % 3, j2 = (i + 2) % 3;
      r[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)] =
          (a[static_cast<std::size_t>(i1)][static_cast<std::size_t>(j1)] * a[static_cast<std::size_t>(i2)][static_cast<std::size_t>(j2)] -
           a[static_cast<std::size_t>(i1)][static_cast<std::size_t>(j2)] * a[static_cast<std::size_t>(i2)][static_cast<std::size_t>(j1)]) /
          det;
    }
  return r;
}

/// Whether the trivariate's xyz is affine in its parameters: its control points are the affine
/// map X_0 + A (xi - lo) of their Greville abscissae (B-splines reproduce linear functions with
/// those), within 1e-12 of the control box's diagonal. Sets A (A[i][d] = dX_i/du_d) and X_0.
bool affine(const spline::Trivariate& t, Mat3& a, std::array<double, 3>& x0, std::array<double, 3>& lo) {
  for (int d = 0; d < 3; ++d) lo[static_cast<std::size_t>(d)] = t.domain(d)[0];
  std::array<double, 3> mid;
  for (int d = 0; d < 3; ++d) mid[static_cast<std::size_t>(d)] = 0.5 * (t.domain(d)[0] + t.domain(d)[1]);
  const auto der = t.eval_derivatives(mid, 1);
  const auto dim = static_cast<std::size_t>(t.dim());
  const auto p0 = t.eval(lo);
  for (std::size_t i = 0; i < 3; ++i) {
    x0[i] = p0[i];
    for (int d = 0; d < 3; ++d) {
      std::array<int, 3> alpha{};
      alpha[static_cast<std::size_t>(d)] = 1;
      a[i][static_cast<std::size_t>(d)] = der[static_cast<std::size_t>(spline::derivative_slot<3>(alpha)) * dim + i];
    }
  }
  const auto box = t.control_box();
  double diag = 0;
  for (std::size_t i = 0; i < 3; ++i) diag += (box[1][i] - box[0][i]) * (box[1][i] - box[0][i]);
  const double tol = 1e-12 * std::sqrt(diag);
  for (int row = 0; row < t.size(); ++row) {
    const auto idx = t.multi_index(row);
    std::array<double, 3> xi;
    for (int d = 0; d < 3; ++d) {
      const auto& k = t.knots(d);
      const int deg = k.degree(), i = idx[static_cast<std::size_t>(d)];
      double s = 0;
      for (int j = 1; j <= deg; ++j) s += k[i + j];
      xi[static_cast<std::size_t>(d)] = (deg > 0 ? s / deg : k[i]) - lo[static_cast<std::size_t>(d)];
    }
    const auto p = t.point(row);
    for (std::size_t i = 0; i < 3; ++i) {
      const double want = x0[i] + a[i][0] * xi[0] + a[i][1] * xi[1] + a[i][2] * xi[2];
      if (std::abs(p[i] - want) > tol) return false;
    }
  }
  return true;
}

}  // namespace

PropertyIntegrals property_integrals(const vmodel::VModel& model, int cell, const BoundaryFaceOptions& options) {
  if (cell < 0 || cell >= static_cast<int>(model.cells.size()))
    throw Error("cell " + std::to_string(cell) + ": out of range; expected 0.." + std::to_string(model.cells.size()) + " - 1");
  const vmodel::VCell& c = model.cells[static_cast<std::size_t>(cell)];
  const spline::Trivariate& t = c.volume;
  const int nprop = t.dim() - 3;
  PropertyIntegrals r;
  if (c.plain()) {
    for (int k = 0; k < nprop; ++k) r.values.push_back(geom::integrate_coordinate(t, 3 + k));
    r.volume = geom::volume(t);
    r.exact = !t.rational();
    r.method = "quadrature";
    return r;
  }
  // Trimmed: the divergence theorem in the trivariate's parameter space (file comment).
  if (c.blend != vmodel::BlendRule::first) {
    r.note = "its properties blend its inputs' (an intersection's cell), not a polynomial of its trivariate";
    return r;
  }
  if (t.rational()) {
    r.note = "its trivariate is rational";
    return r;
  }
  for (int d = 0; d < 3; ++d)
    if (t.count(d) != t.orders()[static_cast<std::size_t>(d)]) {
      r.note = "its trivariate has several knot spans (the faces are not split at its knots)";
      return r;
    }
  Mat3 a;
  std::array<double, 3> x0, lo;
  if (!affine(t, a, x0, lo)) {
    r.note = "its trivariate is not affine, so its faces are not polynomial in its parameters (needs the untrimming "
             "of trimmed V-cells, which trivox does not build)";
    return r;
  }
  const double det = det3(a);
  if (!(std::abs(det) > 0)) {
    r.note = "its trivariate is degenerate (det J = 0)";
    return r;
  }
  const Mat3 m = inverse3(a, det);
  const auto faces = boundary_faces(model, cell, options);
  const auto order = t.orders();
  const int pu = order[0] - 1, pv = order[1] - 1, pw = order[2] - 1;
  const geom::GaussRule ru = geom::gauss_legendre(std::max(1, (pu + 2) / 2));
  const auto dim = static_cast<std::size_t>(t.dim());
  std::vector<double> sum(static_cast<std::size_t>(nprop) + 1, 0.0);  // properties, then rho = 1
  std::vector<double> rho(dim), acc(static_cast<std::size_t>(nprop) + 1);
  const int s_slot = spline::derivative_slot<2>(std::array<int, 2>{1, 0}), t_slot = spline::derivative_slot<2>(std::array<int, 2>{0, 1});
  for (const auto& f : faces)
    for (const auto& patch : f.patches.patches)
      for (const auto& b : spline::bezier_pieces(patch)) {
        const int qs = b.orders()[0] - 1, qt = b.orders()[1] - 1;
        const geom::GaussRule gs = geom::gauss_legendre(std::max(1, ((pu + pv + pw + 3) * qs + 1) / 2));
        const geom::GaussRule gt = geom::gauss_legendre(std::max(1, ((pu + pv + pw + 3) * qt + 1) / 2));
        const auto ds = b.domain(0), dt = b.domain(1);
        const auto bdim = static_cast<std::size_t>(b.dim());
        for (std::size_t i = 0; i < gs.nodes.size(); ++i)
          for (std::size_t j = 0; j < gt.nodes.size(); ++j) {
            const double s = 0.5 * (ds[0] + ds[1]) + 0.5 * (ds[1] - ds[0]) * gs.nodes[i];
            const double tt = 0.5 * (dt[0] + dt[1]) + 0.5 * (dt[1] - dt[0]) * gt.nodes[j];
            const double w = gs.weights[i] * gt.weights[j] * 0.25 * (ds[1] - ds[0]) * (dt[1] - dt[0]);
            const auto der = b.eval_derivatives({s, tt}, 1);
            std::array<double, 3> u, us, ut;
            for (std::size_t r0 = 0; r0 < 3; ++r0) {
              u[r0] = lo[r0];
              us[r0] = ut[r0] = 0;
              for (std::size_t k = 0; k < 3; ++k) {
                u[r0] += m[r0][k] * (der[k] - x0[k]);
                us[r0] += m[r0][k] * der[static_cast<std::size_t>(s_slot) * bdim + k];
                ut[r0] += m[r0][k] * der[static_cast<std::size_t>(t_slot) * bdim + k];
              }
            }
            const double nu = us[1] * ut[2] - us[2] * ut[1];  // (U_s x U_t)_u
            // R(u, v, w) = int_{lo_u}^{u} rho du', by the Gauss rule ru on that interval.
            std::fill(acc.begin(), acc.end(), 0.0);
            const double h = u[0] - lo[0];
            for (std::size_t g = 0; g < ru.nodes.size(); ++g) {
              t.eval({lo[0] + 0.5 * h * (1 + ru.nodes[g]), u[1], u[2]}, rho.data());
              for (int k = 0; k < nprop; ++k) acc[static_cast<std::size_t>(k)] += ru.weights[g] * rho[3 + static_cast<std::size_t>(k)];
              acc[static_cast<std::size_t>(nprop)] += ru.weights[g];
            }
            for (std::size_t k = 0; k < acc.size(); ++k) sum[k] += f.orientation * w * 0.5 * h * acc[k] * nu;
          }
      }
  for (int k = 0; k < nprop; ++k) r.values.push_back(det * sum[static_cast<std::size_t>(k)]);
  r.volume = det * sum[static_cast<std::size_t>(nprop)];
  r.exact = true;
  r.method = "boundary";
  return r;
}

}  // namespace trivox::slice
