/// @file src/slice/block_sampler.hpp
/// @brief (private to src/slice) One block of image rows of a layer sampled cell by cell
/// (sampler.hpp): per row the leaves that meet it and their voxel intervals, certified runs from
/// anchors (anchor.hpp) claimed voxel after voxel, and the voxels off the runs (exclusion.hpp,
/// voxel_solve.hpp). Defined in block_sampler.cpp; the properties of a certified run in
/// run_interpolation.cpp.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "trivox/slice/grid.hpp"
#include "trivox/slice/locator.hpp"

#include "anchor.hpp"
#include "exclusion.hpp"
#include "row_leaf.hpp"
#include "run_writers.hpp"
#include "voxel_solve.hpp"

namespace trivox::slice::detail {

/// Where a block's results go: rows of nx voxels, straight into the caller's band when the block
/// lies inside it, else into scratch.
struct BlockOut {
  std::int32_t* owner = nullptr;  ///< rows x nx
  float* props = nullptr;         ///< rows x nx x m
  double* uvw = nullptr;          ///< rows x nx x 3, or null
  bool zero_props = true;         ///< clear props first (else void voxels' are left as they are)
  std::array<std::int64_t, block_rows> failures{}, inverted{};
};

/// Samples image rows [r0, r0 + nr) of layer `layer` (one block) into `out`.
class BlockSampler {
public:
  BlockSampler(const Locator& loc, const VoxelGrid& grid)
      : loc_(loc), grid_(grid), m_(static_cast<int>(loc.model().properties.size())), write_(pick_write(m_)),
        write_quad_(pick_write_quadratic(m_)) {}

  /// Image rows [r0, r0 + nr) of layer `layer` (nr <= block_rows), into `out`.
  void run(int layer, int r0, int nr, BlockOut& out);

private:
  /// The voxels of row l that cell `cell`'s leaves reach, in x order.
  void walk_row(int cell, int l);

  /// Gives `cell` the voxels i, i + 1, ... up to iend that no earlier cell took (owner -1), and
  /// returns the first one it did not give (a taken voxel, or iend + 1): eight at a time, as the
  /// AND of their owners is negative exactly when all eight are -1.
  static int claim_run(std::int32_t* owner, int i, int iend, int cell);

  /// Voxels i0 .. i1 - 1 of block row l from anchor a (their owners set by claim_run): uvw and
  /// properties (Anchor's comment): from the first-order model, or exact at the run's first and
  /// last voxels and every a.step-th between and linear in between.
  void fill(const Anchor& a, int l, int i0, int i1, float* props, double* uvw);

  /// fill's quadratic form (Anchor::quad): the n voxels from i0 in segments of at most 2 step
  /// voxels, each with exact samples at its ends and at its middle (so both halves are at most
  /// step long, as sample_step's bound needs), the quadratic through the three in between; a
  /// segment of one voxel takes its two ends alone. The last voxel is its exact sample.
  void fill_quadratic(const Anchor& a, int l, int i0, int n, float* out);

  /// One voxel off the stepping runs: an anchor at a prediction (its certification covers the
  /// voxel, or its exact residual does), else the slow path (then an anchor at the answer).
  /// @param span_end   the last voxel of the row's current run of leaf intervals
  /// @param check_run  voxels left to try by a residual check alone (along a boundary, where
  ///                   anchors certify nothing)
  void visit(int cell, int l, int i, int span_end, const std::array<Vec3, 2>& dom, int& cur, Chain& chain, int& check_run,
             RowLeaf* lb, RowLeaf* le, std::int32_t& owner, float* vp, double* vt);

  const Locator& loc_;
  const VoxelGrid& grid_;
  int m_;
  WriteLinear write_;
  WriteQuadratic write_quad_;
  BlockOut* out_ = nullptr;
  double tol_ = 0.0, z_ = 0.0;
  int nr_ = 0;  ///< the block's rows
  std::array<double, block_rows> y_{};
  std::vector<int> cand_;
  std::array<std::vector<RowLeaf>, block_rows> act_;
  std::array<std::size_t, block_rows> pos_{};
  std::vector<Anchor> anchors_;
  std::array<Exclusion, 4> excl_;  ///< the last few made for this cell and block
  std::size_t excl_next_ = 0;
  std::vector<int> cover_;
  AnchorMaker* maker_ = nullptr;
  Expansion exp_;
  std::vector<Vec3> pts_;      ///< fill's sample points
  std::vector<int> offs_;      ///< fill_quadratic's sample offsets in the run
  std::vector<double> vals_;   ///< and their properties
};

}  // namespace trivox::slice::detail
