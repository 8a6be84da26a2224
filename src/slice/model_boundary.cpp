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
  for (auto& f : out.faces) {
    int found = 0, patches = 0;
    for (const auto& p : f.patches.patches) {
      ++patches;
      // The middle of the patch; its normal, or a nearby point's where the patch degenerates.
      std::vector<double> buf(static_cast<std::size_t>(3 * p.dim()));
      double n[3] = {0, 0, 0}, len = 0;
      Vec3 x{};
      for (const double t : {0.5, 0.4, 0.6, 0.3}) {
        p.eval_derivatives({t, t}, 1, buf.data());
        const double* xs = buf.data() + p.dim();
        const double* xt = xs + p.dim();
        n[0] = xs[1] * xt[2] - xs[2] * xt[1], n[1] = xs[2] * xt[0] - xs[0] * xt[2], n[2] = xs[0] * xt[1] - xs[1] * xt[0];
        len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        x = {buf[0], buf[1], buf[2]};
        if (len > 0) break;
      }
      if (!(len > 0)) continue;  // a degenerate patch (zero area) decides nothing
      const double s = f.orientation * delta / len;
      const LocateResult r = loc.locate({x[0] + s * n[0], x[1] + s * n[1], x[2] + s * n[2]});
      if (r.inside && r.cell != f.cell) {
        ++found;
        if (f.glued_to < 0) f.glued_to = r.cell;
      }
    }
    f.glued = found > 0 && found == patches;
    if (f.glued_to < 0) out.outer_area += f.area;
    if (f.glued) out.glued_area += f.area;
    if (f.glued_to >= 0 && !f.glued) ++out.partly_glued;
  }
  return out;
}

}  // namespace trivox::slice
