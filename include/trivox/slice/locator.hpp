/// @file trivox/slice/locator.hpp
/// @brief Point location in a V-model: which cell contains a point xyz, and at which (u,v,w).
///
/// The inverse of the cells' maps X_c(u,v,w) -> xyz, the question every voxel of a print job asks
/// (Masalha, Cirillo & Elber 2021, Masalha et al. 2021, Sec. 8: a V-model is "sliced" by sampling
/// geometry and materials together at every voxel of every layer; their research
/// code took minutes per slice).
///
/// How: every cell is cut into its Bezier pieces (polynomial or rational, kept in Bernstein form
/// for fast evaluation) and each piece is subdivided in parameter space into *leaves* until its
/// control net is nearly affine: deviation from the least-squares affine map below 10% of the
/// leaf's size and, with LocatorOptions::leaf_deviation, below that distance. Two conservative
/// regions hold a leaf's image (convex hull property, also for positive weights): the
/// axis-aligned box of its control points, and the parallelepiped of its control points in the
/// frame of the affine map (tight for rotated or sheared leaves). A bounding-volume hierarchy over
/// the leaf boxes gives, for a point p, the candidate leaves; in each whose regions hold p, point
/// inversion is damped Newton on X(u,v,w) - p = 0 with the Jacobian from the first partials,
/// clamped to the leaf's parameter box (projected Newton: coordinates pinned at a bound whose
/// step points outwards are frozen and the others solved in the least-squares sense):
/// - converged: |X(u,v,w) - p| < tolerance: p is in the cell at (u,v,w);
/// - outside: stationary on the parameter box's boundary with the Newton step pointing outwards
///   and the first-order residual above the tolerance: p is not in this leaf (the leaf being
///   nearly affine, that verdict is sound except within about the tolerance of its boundary);
/// - failed: neither within `max_newton` iterations (a near-singular Jacobian, say). Then the
///   leaf's parameter box is subdivided 3 x 3 x 3 and Newton restarted, clamped to each part,
///   from its centre (parts whose image provably misses p, by a Lipschitz bound from the
///   hodograph's control points, are skipped). Only if some part still fails does the answer
///   report `converged == false`.
/// A hint (a neighbouring point's answer) warm-starts Newton over the whole cell domain first:
/// along a row of voxels that converges in one or two evaluations, and the leaf search runs only
/// when it does not.
///
/// For the layer sampler the locator also exposes its building blocks: the leaves, Newton over a
/// parameter box, an evaluation that checks a predicted (u,v,w), and for polynomial pieces an
/// Expansion (value and first partials of every coordinate) with rigorous bounds on the second
/// partials (StepBounds), from which the sampler certifies whole runs of voxels without
/// evaluating them (sampler.hpp).
///
/// Overlapping cells: the first cell in file order that contains p wins; cells made by Booleans
/// are trimmed so that they do not overlap (vmodel/boolean.hpp), and a trimmed cell contains p
/// only where its conditions admit it. Points within the tolerance of a cell count as inside it.
///
/// Cost: construction O(pieces * leaves per piece * order^3 * dim), parallel over pieces (TBB;
/// the same locator for any thread count). A piece's StepBounds are computed on first use (a
/// job touches only some pieces).
/// A query: a BVH descent plus, per candidate leaf, a few Newton iterations of O(order^3)
/// (geometry only; properties cost one more O(order^3 * m) evaluation at the answer). Orders up
/// to 16; kernels specialised for orders 2, 3 and 4 in all directions.
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <utility>
#include <vector>

#include "trivox/vmodel/vmodel.hpp"

namespace trivox::slice {

using Vec3 = std::array<double, 3>;

/// Where a point lies in a model.
struct LocateResult {
  bool inside = false;  ///< p is in some cell (within the tolerance)
  int cell = -1;        ///< index into VModel::cells, -1 when outside
  Vec3 uvw{};           ///< the cell's parameters with |X(uvw) - p| < tolerance (when inside)
  /// false when some Newton run did not settle even after subdivision; then `inside` is the best
  /// guess: inside at the best iterate when its residual is below 500 x tolerance (half a voxel
  /// at the sampler's tolerance), else outside.
  bool converged = true;
};

struct LocatorOptions {
  /// Absolute xyz tolerance in model units (mm): Newton stops when |X(uvw) - p| < tolerance.
  /// The sampler sets it from the voxel pitch: 1e-3 * min pitch.
  double tolerance = 1e-6;
  /// Newton iterations per start before the subdivision fallback.
  int max_newton = 30;
  /// When > 0, leaves are also subdivided until their control nets deviate at most this much
  /// (model units) from an affine map, so their parallelepipeds hug the cell to within about this
  /// distance (empty space skipped; the sampler uses its largest pitch). 0: only the
  /// relative rule (10% of the leaf's size).
  double leaf_deviation = 0.0;
  /// When 0 < fine_leaf_deviation < leaf_deviation, a second pass splits the leaves on towards
  /// this deviation, with at most fine_leaf_factor times the first pass's leaves per piece (the
  /// most deviating first): tighter regions where they are cheap, without the cost of reaching
  /// it everywhere in finely refined cells (thousands of small pieces).
  double fine_leaf_deviation = 0.0;
  int fine_leaf_factor = 4;
  /// Upper bound on the leaves of one Bezier piece (the most deviating are split first).
  int max_leaves_per_piece = 4096;
};

/// The outcome of one Newton run (see the file comment).
enum class NewtonStatus : std::uint8_t { converged, outside, failed };

struct NewtonResult {
  NewtonStatus status = NewtonStatus::failed;
  Vec3 uvw{};              ///< the last iterate (the answer when converged)
  double residual = 0.0;   ///< |X(uvw) - p|
  /// When converged: uvw plus one more Newton step, not evaluated (closer to the exact inverse
  /// than uvw, whose residual is only below the tolerance): the warm start for neighbours.
  /// Otherwise uvw.
  Vec3 polished{};
  /// The Jacobian at uvw, column after column (dX/du, dX/dv, dX/dw).
  std::array<Vec3, 3> jacobian{};
};

/// A leaf of a cell's subdivision: a parameter box and two conservative regions holding its
/// image (convex hull property): the axis-aligned box of its control points, and the
/// parallelepiped of its control points in the frame of the least-squares affine approximation of
/// the leaf (tight for rotated or sheared leaves, where the box is not).
struct LocatorLeaf {
  int cell = -1;   ///< index into VModel::cells
  int piece = -1;  ///< the Bezier piece it lies in (index into the locator's pieces of all cells)
  Vec3 lo{}, hi{};          ///< parameter box, in the cell's own (u,v,w)
  Vec3 box_lo{}, box_hi{};  ///< xyz box containing the leaf's image
  /// Parallelepiped: {x : frame_lo <= F (x - frame_origin) <= frame_hi}, F with rows `frame`.
  Vec3 frame_origin{};
  std::array<Vec3, 3> frame{};
  Vec3 frame_lo{}, frame_hi{};
  Vec3 frame_scale{};  ///< |row k of F|: a distance d in xyz is at most d * frame_scale[k] along k

  /// False when p is farther than `pad` from both regions (then it is not in the leaf's image).
  bool may_contain(const Vec3& p, double pad) const noexcept {
    for (std::size_t d = 0; d < 3; ++d)
      if (p[d] < box_lo[d] - pad || p[d] > box_hi[d] + pad) return false;
    for (std::size_t k = 0; k < 3; ++k) {
      const double c = frame[k][0] * (p[0] - frame_origin[0]) + frame[k][1] * (p[1] - frame_origin[1]) +
                       frame[k][2] * (p[2] - frame_origin[2]);
      const double g = pad * frame_scale[k];
      if (c < frame_lo[k] - g || c > frame_hi[k] + g) return false;
    }
    return true;
  }
  /// The x-interval [x0, x1] of the row line {(x, y, z)} within `pad` of both regions; false
  /// when it misses them.
  bool row_range(double y, double z, double pad, double& x0, double& x1) const noexcept {
    if (y < box_lo[1] - pad || y > box_hi[1] + pad || z < box_lo[2] - pad || z > box_hi[2] + pad) return false;
    x0 = box_lo[0] - pad;
    x1 = box_hi[0] + pad;
    for (std::size_t k = 0; k < 3; ++k) {
      // c(x) = c0 + x * frame[k][0] along the line
      const double c0 = frame[k][0] * (0.0 - frame_origin[0]) + frame[k][1] * (y - frame_origin[1]) +
                        frame[k][2] * (z - frame_origin[2]);
      const double g = pad * frame_scale[k], slope = frame[k][0];
      const double lo = frame_lo[k] - g - c0, hi = frame_hi[k] + g - c0;
      if (slope == 0.0) {
        if (lo > 0.0 || hi < 0.0) return false;
        continue;
      }
      double a = lo / slope, b = hi / slope;
      if (a > b) std::swap(a, b);
      x0 = std::max(x0, a);
      x1 = std::min(x1, b);
    }
    return x0 <= x1;
  }
};

/// Rigorous bounds on a polynomial Bezier piece's second partial derivatives (in the cell's
/// global parameters), from the convex hull of the second differences of its control points: what
/// certified first-order stepping needs (LayerSampler).
struct StepBounds {
  bool valid = false;  ///< false for rational pieces and pieces with too many properties
  Vec3 lo{}, hi{};     ///< the piece's parameter box
  /// b2[d][e] >= |d^2 X / dt_d dt_e| (xyz, Euclidean norm) anywhere in the piece
  std::array<Vec3, 3> b2{};
  /// b2v[d][e][k] >= |d^2 X_k / dt_d dt_e| per coordinate k: bounds that survive a linear map
  /// (J^-1 applied to them), for affine-invariant certificates
  std::array<std::array<Vec3, 3>, 3> b2v{};
  double lip = 0.0;    ///< max_d sqrt(sum_e b2[d][e]^2): |J(a) - J(b)|_F <= lip |a - b|_1
  /// p2[d][e] >= |d^2 P_h / dt_d dt_e| for every property h
  std::array<Vec3, 3> p2{};
  /// p3[d][e][f] >= |d^3 P_h / dt_d dt_e dt_f| for every property h (symmetric)
  std::array<std::array<Vec3, 3>, 3> p3{};
  Vec3 slope{};                   ///< slope[d] >= |dX / dt_d| (xyz, Euclidean norm) in the piece
  std::array<int, 3> degree{};    ///< polynomial degree per direction
};

/// An exact evaluation of a cell at t with the first partials of every coordinate: the anchor of
/// first-order stepping along a row (LayerSampler).
struct Expansion {
  static constexpr int max_props = 7;
  int piece = -1;                   ///< the piece evaluated (its StepBounds apply)
  Vec3 t{};                         ///< parameters
  Vec3 x{};                         ///< X(t)
  std::array<Vec3, 3> jac{};        ///< dX/dt_d, column after column
  std::array<double, max_props> props{};               ///< P_h(t)
  std::array<std::array<double, 3>, max_props> grad{};  ///< dP_h/dt_d
};

class Locator {
public:
  /// Splits every cell into Bezier pieces and leaves and builds the BVH over the leaf boxes.
  /// @param model  the V-model; must outlive the locator and stay unchanged
  /// @param opt    tolerance and iteration limits
  /// @throws Error (bad_input) when a cell's dimension is not model.dim(), an order exceeds 16,
  ///         or the tolerance is not positive and finite
  Locator(const vmodel::VModel& model, LocatorOptions opt = {});
  ~Locator();
  Locator(Locator&&) noexcept;
  Locator& operator=(Locator&&) noexcept;

  /// Which cell contains p and where; the first cell in file order wins on overlap. A trimmed
  /// cell (a Boolean's, vmodel::VCell::within / without) contains p only when its trivariate
  /// does and its conditions admit p (admits()).
  /// Thread-safe (const, no mutable state).
  /// @param p     the point, xyz in model units (not finite: outside, with converged == false)
  /// @param hint  optional: a previous answer near p (same cell, its uvw) to warm-start Newton
  LocateResult locate(const Vec3& p, const LocateResult* hint = nullptr) const;

  const vmodel::VModel& model() const noexcept;

  // ---- Booleans (Massarwi & Elber 2016, Sec. 4): trimmed cells ----
  /// True when some cell is trimmed (not VCell::plain()).
  bool has_trims() const noexcept;
  /// True when cell c is trimmed.
  bool trimmed(int cell) const noexcept;
  /// Whether p (inside cell c's trivariate) satisfies c's trimming: inside every `within` cell
  /// and in no cell of any `without` solid, each decided by its own locator (so exactly, up to
  /// the tolerance). Always true for plain cells. When `props` is not null it holds the
  /// trivariate's own m values on entry and, if p is admitted, leaves with c's blended
  /// properties: combined with the within cells' values at p (their own blends applied) by the
  /// cell's rule (sum clipped to [0, 1], the mean, or Massarwi & Elber 2016, Eq. 2's distance
  /// weights: one closest-point query per boundary surface of each input). Unchanged for plain
  /// cells and BlendRule::first. One point location per condition, whether or not props are wanted.
  bool admits(int cell, const Vec3& p, double* props = nullptr) const;
  const LocatorOptions& options() const noexcept;

  // ---- Building blocks for the layer sampler (and anyone walking many coherent points) ----

  /// All leaves, grouped by cell in file order.
  std::span<const LocatorLeaf> leaves() const noexcept;
  /// Calls f(leaf index) for every leaf whose box, grown by `pad`, meets the box [lo, hi].
  template <class F>
  void for_each_leaf_in_box(const Vec3& lo, const Vec3& hi, double pad, F&& f) const;

  /// The parameter domain of cell c: {min corner, max corner}.
  std::array<Vec3, 2> domain(int cell) const noexcept;

  /// Damped, clamped Newton for X_c(uvw) = p over the parameter box [lo, hi] (inside the cell's
  /// domain), from `start` (clamped into the box). No subdivision fallback.
  /// @param max_iter  iteration limit (the options' max_newton when <= 0)
  NewtonResult newton(int cell, const Vec3& p, const Vec3& start, const Vec3& lo, const Vec3& hi,
                      int max_iter = 0) const;

  /// Newton in one leaf from `start` (or the leaf's centre when null), with the subdivision
  /// fallback when it fails (see the file comment).
  NewtonResult solve_in_leaf(int leaf, const Vec3& p, const Vec3* start = nullptr) const;

  /// The point X_c(uvw) (3 values) and, when `props` is not null, the m properties
  /// (VModel::properties.size() values) of cell c at uvw.
  void eval(int cell, const Vec3& uvw, double* xyz, double* props) const;
  /// The properties only, as floats (what the sampler stores).
  void eval_properties(int cell, const Vec3& uvw, float* props) const;
  /// One evaluation of cell c at uvw (geometry and properties in one pass over the net): true
  /// when |X_c(uvw) - p| < tolerance. The properties are written to `props` (m floats) either
  /// way, and p - X_c(uvw) to `residual` when not null. The sampler's fast path for
  /// well-predicted parameters.
  bool check(int cell, const Vec3& p, const Vec3& uvw, float* props, Vec3* residual = nullptr) const;

  /// Evaluates cell c at t (clamped to the domain) with every coordinate's first partials.
  /// @return false (nothing written) for a rational piece or more than Expansion::max_props
  ///         properties: then only the exact path applies
  bool expand(int cell, const Vec3& t, Expansion& out) const;
  /// The m properties of Bezier piece `piece` (Expansion::piece) at the n parameter points t
  /// (the cell's global parameters), out[j * m + h] for point j: the piece's own polynomial, not
  /// clamped to its box, so that along a line of parameters the values are one polynomial (the
  /// sampler interpolates it). Points are evaluated eight at a time, the same floats whatever
  /// the vector width. A rational piece is not one polynomial: each point is then evaluated
  /// clamped to the piece, its weight divided out (as eval()); the sampler never asks for one.
  void piece_properties(int piece, const Vec3* t, int n, double* out) const;
  /// The second-derivative bounds of a piece (Expansion::piece). Computed on first use
  /// (thread-safe; the values do not depend on the caller); the reference stays valid.
  const StepBounds& step_bounds(int piece) const noexcept;

  /// Implementation data (Bernstein nets, BVH); opaque.
  struct Data;

private:
  void query(const Vec3& lo, const Vec3& hi, double pad, std::vector<int>& out) const;

  const vmodel::VModel* model_;
  LocatorOptions opt_;
  std::unique_ptr<Data> data_;
};

/// The axis-aligned xyz bounding box {min, max} of the model's cells, from the control points of
/// their Bezier pieces (spline::bounding_box): what the voxel grid covers (grid.hpp).
/// @throws Error (bad_input) for a model without cells
std::array<Vec3, 2> model_bounds(const vmodel::VModel& model);

/// The diagonal of model_bounds: the model's size, for tolerances relative to it (> 0: at least
/// the smallest positive double).
/// @throws Error (bad_input) for a model without cells
double model_diagonal(const vmodel::VModel& model);

// ---- definitions ----

template <class F>
void Locator::for_each_leaf_in_box(const Vec3& lo, const Vec3& hi, double pad, F&& f) const {
  std::vector<int> hits;
  query(lo, hi, pad, hits);
  for (int i : hits) f(i);
}

}  // namespace trivox::slice
