// `trivox construct INPUT`: one constructor (Boolean sum, half Boolean sum, ruling, extrusion,
// revolution, sweep) on given curves or surfaces, regular or kernel-based (Fadila et al. 2023, Alg.
// 1), with its Jacobian validity. Exit 1 when the result is not a valid parametrisation (then -o
// writes nothing unless --keep-invalid).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>

#include "common.hpp"
#include "trivox/construct/constructors.hpp"
#include "trivox/construct/kernel_construct.hpp"
#include "trivox/error.hpp"
#include "trivox/geom/planar_crossing.hpp"
#include "trivox/geom/surface_intersection.hpp"
#include "trivox/geom/validity.hpp"
#include "trivox/io/construct_file.hpp"
#include "trivox/io/model_file.hpp"
#include "trivox/spline/calculus.hpp"
#include "trivox/spline/extract.hpp"

namespace trivox::cli {

namespace {

struct Options {
  std::string input;
  std::string output;
  bool force = false;
  bool kernel = false;
  std::string add_dof = "refine";
  int max_dof = 20;
  double spread = 0.0;
  bool strict = false;
  bool keep_invalid = false;
};

/// Validity of the result, when it is defined: trivariates (xyz) and planar surfaces (xy, or
/// xyz with one z).
struct Verdict {
  bool defined = false;
  bool valid = false;
  double min_jacobian = 0.0, max_jacobian = 0.0;
};

/// xy only, or xyz with one z for every control point.
template <int P>
bool planar(const spline::TensorSpline<P>& s) {
  if (s.dim() < 2) return false;
  if (s.dim() == 2) return true;
  for (int i = 1; i < s.size(); ++i)
    if (s.point(i)[2] != s.point(0)[2]) return false;
  return true;
}

Verdict verdict_of(const spline::Surface& s) {
  if (!planar(s)) return {};
  const auto r = geom::check_validity(s);
  return {true, r.verdict == geom::Validity::valid, r.min_bound, r.max_bound};
}
Verdict verdict_of(const spline::Trivariate& t) {
  if (t.dim() < 3) return {};
  const auto r = geom::check_validity(t);
  return {true, r.verdict == geom::Validity::valid, r.min_bound, r.max_bound};
}

/// Planar boundary curves must meet only at their shared ends (Fadila et al. 2023, Sec. 4: input
/// "intersection and self-intersection free"), checked to 1e-5 of their extent.
void check_simple(const io::ConstructInput& in, const std::string& file) {
  if (in.curves.empty() || in.op == "extrude" || in.op == "revolve" || in.op == "sweep") return;
  for (const auto& c : in.curves)
    if (!planar(c)) return;
  double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
  for (const auto& c : in.curves)
    for (int i = 0; i < c.size(); ++i)
      for (int d = 0; d < 2; ++d) {
        lo[d] = std::min(lo[d], c.point(i)[static_cast<std::size_t>(d)]);
        hi[d] = std::max(hi[d], c.point(i)[static_cast<std::size_t>(d)]);
      }
  const double extent = std::hypot(hi[0] - lo[0], hi[1] - lo[1]);
  if (!(extent > 0)) return;
  const auto x = geom::first_crossing(in.curves, 1e-5 * extent);
  if (!x) return;
  const std::string where = "near (" + fmt(x->point[0], 8) + ", " + fmt(x->point[1], 8) + ")";
  if (x->curve_a == x->curve_b)
    throw Error(file + ": /curves/" + std::to_string(x->curve_a) + ": the curve crosses itself " + where +
                "; expected curves free of self-intersections");
  throw Error(file + ": /curves/" + std::to_string(x->curve_a) + " and /curves/" + std::to_string(x->curve_b) +
              " cross " + where + "; expected boundary curves that meet only at their shared ends");
}

/// Input surfaces of a trivariate constructor may meet only along their boundaries (shared
/// edges): any intersection point inside both (surface-surface intersection) is a crossing.
void check_surfaces_apart(const io::ConstructInput& in, const std::string& file) {
  if (in.surfaces.size() < 2 || in.op == "sweep" || in.op == "extrude" || in.op == "revolve") return;
  std::vector<spline::Surface> xyz;
  for (const auto& s : in.surfaces) xyz.push_back(s.dim() > 3 ? spline::coordinates(s, 0, 3) : s);
  const auto interior = [](const spline::Surface& s, const std::array<double, 2>& t) {
    for (int d = 0; d < 2; ++d) {
      const auto dom = s.domain(d);
      const double w = 1e-6 * (dom[1] - dom[0]);
      if (t[static_cast<std::size_t>(d)] <= dom[0] + w || t[static_cast<std::size_t>(d)] >= dom[1] - w) return false;
    }
    return true;
  };
  double size = 0.0;
  for (const auto& s : xyz) {
    const auto b = spline::bounding_box(s, 3);
    size = std::max(size, std::hypot(b[1][0] - b[0][0], b[1][1] - b[0][1], b[1][2] - b[0][2]));
  }
  for (std::size_t i = 0; i < xyz.size(); ++i)
    for (std::size_t j = i + 1; j < xyz.size(); ++j)
      for (const auto& c : geom::intersect_surfaces(xyz[i], xyz[j], {.tolerance = 1e-9 * std::max(size, 1e-300)}))
        for (const auto& p : c.points)
          if (interior(xyz[i], p.uv1) && interior(xyz[j], p.uv2))
            throw Error(file + ": /surfaces/" + std::to_string(i) + " and /surfaces/" + std::to_string(j) + " cross near (" +
                        fmt(p.xyz[0], 8) + ", " + fmt(p.xyz[1], 8) + ", " + fmt(p.xyz[2], 8) +
                        "); expected surfaces that meet only along their shared boundaries");
}

template <int P>
spline::TensorSpline<P> regular(const io::ConstructInput& in);

template <>
spline::Surface regular<2>(const io::ConstructInput& in) {
  const auto& c = in.curves;
  if (in.op == "boolean_sum") return construct::boolean_sum(c[0], c[1], c[2], c[3], in.match);
  if (in.op == "half_boolean_sum") return construct::half_boolean_sum(c[0], c[1], in.match);
  if (in.op == "ruled") return construct::ruled(c[0], c[1], in.ruling_order);
  if (in.op == "extrude") return construct::extrude(c[0], in.vector);
  if (in.op == "revolve") return construct::revolve(c[0], in.revolution);
  return construct::sweep(c, in.params, in.order);
}

template <>
spline::Trivariate regular<3>(const io::ConstructInput& in) {
  const auto& s = in.surfaces;
  if (in.op == "boolean_sum") return construct::boolean_sum(s, in.match);
  if (in.op == "half_boolean_sum")
    return s.size() == 2 ? construct::half_boolean_sum(s[0], s[1], in.match)
                         : construct::half_boolean_sum(s[0], s[1], s[2], in.match);
  if (in.op == "ruled") return construct::ruled(s[0], s[1], in.ruling_order);
  if (in.op == "extrude") return construct::extrude(s[0], in.vector);
  if (in.op == "revolve") return construct::revolve(s[0], in.revolution);
  return construct::sweep(s, in.params, in.order);
}

template <int P>
void run(const Options& opt, const io::ConstructInput& in, Common& common) {
  using Spline = spline::TensorSpline<P>;
  const std::string what = std::string(P == 2 ? "surface" : "trivariate");
  Spline result;
  Verdict regular_verdict, final_verdict;
  std::optional<std::vector<double>> kernel_point;
  int iterations = 0;
  bool valid = false;
  std::string reason;
  if (!opt.kernel) {
    try {
      result = regular<P>(in);
    } catch (const Error& e) {
      throw e.within(opt.input);
    }
    regular_verdict = final_verdict = verdict_of(result);
    valid = !final_verdict.defined || final_verdict.valid;
    if (!valid) reason = "the " + what + "'s Jacobian determinant is not of one strict sign (try --kernel)";
  } else {
    if (in.op != "boolean_sum" && in.op != "half_boolean_sum" && in.op != "ruled")
      throw Error(opt.input + ": /op: \"" + in.op + "\" with --kernel; expected boolean_sum, half_boolean_sum or ruled "
                  "(the kernel-based constructors of Fadila et al. 2023)");
    construct::KernelConstructOptions ko;
    if (opt.add_dof == "refine") ko.add_dof = construct::AddDof::refine;
    else if (opt.add_dof == "elevate") ko.add_dof = construct::AddDof::elevate;
    else throw Error("--add-dof " + opt.add_dof + "; expected refine or elevate");
    ko.max_dof = opt.max_dof;
    ko.spread = opt.spread;
    ko.acceptance = opt.strict ? construct::Acceptance::positive : construct::Acceptance::nonnegative;
    ko.ruling_order = in.ruling_order;
    ko.match = in.match;
    construct::KernelResult<P> r;
    try {
      const construct::KernelOp op = construct::kernel_op_from_name(in.op);
      if constexpr (P == 2) {
        for (std::size_t i = 0; i < in.curves.size(); ++i)
          if (!planar(in.curves[i]))
            throw Error("/curves/" + std::to_string(i) + ": a curve that leaves the plane z = const; expected planar "
                        "curves for a kernel-based surface");
        r = construct::kernel_construct(op, in.curves, ko);
      } else {
        r = construct::kernel_construct(op, in.surfaces, ko);
      }
    } catch (const Error& e) {
      throw e.within(opt.input);
    }
    result = r.spline;
    regular_verdict = {true, r.regular_valid, 0.0, 0.0};
    if (r.kernel) kernel_point = std::vector<double>(r.kernel->begin(), r.kernel->end());
    iterations = r.iterations;
    valid = r.valid;
    reason = r.reason;
    final_verdict = verdict_of(result);
    if (r.regular_valid) regular_verdict = final_verdict;
  }
  const auto orders = result.orders();
  const auto counts = result.counts();

  bool written = false;
  if (!opt.output.empty() && (valid || opt.keep_invalid)) {
    io::write_file_atomically(opt.output, io::write_construct_output(result));
    written = true;
  }

  if (common.json) {
    nlohmann::ordered_json j;
    j["op"] = in.op;
    j["result"] = what;
    j["regular_valid"] = regular_verdict.defined ? nlohmann::ordered_json(regular_verdict.valid) : nullptr;
    j["kernel"] = kernel_point ? nlohmann::ordered_json(*kernel_point) : nullptr;
    j["valid"] = final_verdict.defined || opt.kernel ? nlohmann::ordered_json(valid) : nullptr;
    j["strictly_valid"] = final_verdict.defined ? nlohmann::ordered_json(final_verdict.valid) : nullptr;
    j["iterations"] = iterations;
    j["orders"] = orders;
    j["counts"] = counts;
    if (final_verdict.defined) {
      j["min_jacobian"] = final_verdict.min_jacobian;
      j["max_jacobian"] = final_verdict.max_jacobian;
    }
    if (!reason.empty() && !valid) j["reason"] = reason;
    j["output"] = written ? nlohmann::ordered_json(opt.output) : nullptr;
    print_json(j);
  } else {
    std::string shape = "orders (";
    for (int d = 0; d < P; ++d) shape += (d ? ", " : "") + std::to_string(orders[static_cast<std::size_t>(d)]);
    shape += "), ";
    for (int d = 0; d < P; ++d) shape += (d ? " x " : "") + std::to_string(counts[static_cast<std::size_t>(d)]);
    std::printf("%s: %s -> %s of %s control points\n", opt.input.c_str(), in.op.c_str(), what.c_str(), shape.c_str());
    if (opt.kernel) {
      std::printf("  regular construction: %s\n", regular_verdict.valid ? "valid" : "invalid");
      if (kernel_point) {
        std::string k;
        for (std::size_t i = 0; i < kernel_point->size(); ++i) k += (i ? ", " : "") + fmt((*kernel_point)[i], 8);
        std::printf("  kernel point: (%s)\n", k.c_str());
      }
      if (!regular_verdict.valid)
        std::printf("  kernel-based: %s after %d %s\n", valid ? "valid" : "NOT valid", iterations,
                    opt.add_dof == "refine" ? "knot(s) per span" : "degree raising(s)");
    }
    if (final_verdict.defined)
      std::printf("  det J in [%s, %s]: %s\n", fmt(final_verdict.min_jacobian, 8).c_str(),
                  fmt(final_verdict.max_jacobian, 8).c_str(),
                  final_verdict.valid ? "valid" : valid ? "non-negative (vanishes somewhere)" : "NOT valid");
    else
      std::printf("  validity: not defined for a non-planar surface\n");
    if (written) std::printf("  written to %s\n", opt.output.c_str());
    else if (!opt.output.empty()) std::printf("  not written (invalid; --keep-invalid writes it anyway)\n");
  }
  if (!valid) {
    std::fprintf(stderr, "trivox: construct failed: %s: %s\n", opt.input.c_str(),
                 reason.empty() ? "the result is not valid" : reason.c_str());
    common.exit_code = 1;
  }
}

}  // namespace

void add_construct(CLI::App& app, Common& common) {
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "construct", "Run one constructor (Boolean sum, half Boolean sum, ruled, extrude, revolve, sweep), regular or "
                   "kernel-based, and report its validity (exit 1 if not valid)");
  sub->add_option("INPUT", opt->input, "Constructor input (.json: op, curves or surfaces)")->required();
  sub->add_option("-o,--output", opt->output, "Write the result (.json: surfaces or trivariates)");
  sub->add_flag("--force", opt->force, "Overwrite an existing output file");
  sub->add_flag("--kernel", opt->kernel, "Kernel-based construction (Fadila et al. 2023, Alg. 1) when the regular one is invalid");
  sub->add_option("--add-dof", opt->add_dof, "How --kernel adds freedom: refine (knots per span) or elevate (degree)")
      ->check(CLI::IsMember({"refine", "elevate"}));
  sub->add_option("--max-dof", opt->max_dof, "Largest number of knots per span or degree raisings tried (0..64)")
      ->check(CLI::Range(0, 64));
  sub->add_option("--spread", opt->spread,
                  "Fadila et al. 2023, Sec. 6: spread interior points on a grid this fraction of the kernel's size (0..1)")
      ->check(CLI::Range(0.0, 1.0));
  sub->add_flag("--strict", opt->strict, "With --kernel, accept only det J > 0 everywhere (not just >= 0)");
  sub->add_flag("--keep-invalid", opt->keep_invalid, "Write the output even when the result is not valid");
  sub->add_flag("--json", common.json, "Print one JSON object instead of the summary");
  sub->callback([opt, &common] {
    if (!opt->output.empty() && !opt->force && std::filesystem::exists(opt->output))
      throw Error(opt->output + ": the output file exists; expected a new path (or --force to overwrite)");
    const io::ConstructInput in = io::read_construct_input(io::read_file(opt->input), opt->input);
    check_simple(in, opt->input);
    check_surfaces_apart(in, opt->input);
    if (!in.curves.empty()) run<2>(*opt, in, common);
    else run<3>(*opt, in, common);
  });
}

}  // namespace trivox::cli
