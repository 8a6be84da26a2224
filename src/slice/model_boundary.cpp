#include "trivox/slice/model_boundary.hpp"

#include <cmath>
#include <string>

#include "trivox/error.hpp"
#include "trivox/slice/locator.hpp"

namespace trivox::slice {

ModelBoundary model_boundary(const vmodel::VModel& model, const ModelBoundaryOptions& options) {
  if (!(options.offset > 0 && options.offset <= 1e-2))
    throw Error("model_boundary: offset " + std::to_string(options.offset) + "; expected a value in (0, 1e-2]");
  const double diag = model_diagonal(model);  // throws for a model without cells
  const double delta = options.offset * diag;
  const Locator loc(model, {.tolerance = 1e-3 * delta});
  ModelBoundary out;
  for (int c = 0; c < static_cast<int>(model.cells.size()); ++c) {
    std::vector<BoundaryFace> f;
    try {
      f = boundary_faces(model, c, options.faces);
    } catch (const Error& e) {
      throw e.within("model_boundary: cell " + std::to_string(c) + " (" + model.cells[static_cast<std::size_t>(c)].name + ")");
    }
    for (auto& b : f) out.faces.push_back(std::move(b));
  }
  std::vector<double> buf;
  for (auto& f : out.faces) {
    int found = 0, tested = 0;
    for (const auto& p : f.patches.patches) {
      buf.resize(static_cast<std::size_t>(3 * p.dim()));
      // 3 x 3 points of the patch, at the middles of its thirds.
      for (const double s : {1.0 / 6, 0.5, 5.0 / 6})
        for (const double t : {1.0 / 6, 0.5, 5.0 / 6}) {
          p.eval_derivatives({s, t}, 1, buf.data());
          const double* xs = buf.data() + p.dim();
          const double* xt = xs + p.dim();
          const double n[3] = {xs[1] * xt[2] - xs[2] * xt[1], xs[2] * xt[0] - xs[0] * xt[2], xs[0] * xt[1] - xs[1] * xt[0]};
          const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
          if (!(len > 0)) continue;  // a degenerate point (a collapsed side) decides nothing
          ++tested;
          const double h = f.orientation * delta / len;
          const LocateResult r = loc.locate({buf[0] + h * n[0], buf[1] + h * n[1], buf[2] + h * n[2]});
          if (r.inside && r.cell != f.cell) {
            ++found;
            if (f.glued_to < 0) f.glued_to = r.cell;
          }
        }
    }
    f.glued = found > 0 && found == tested;
    if (f.glued_to < 0) out.outer_area += f.area;
    if (f.glued) out.glued_area += f.area;
    if (f.glued_to >= 0 && !f.glued) ++out.partly_glued;
  }
  return out;
}

}  // namespace trivox::slice
