/// @file src/slice/row_leaf.hpp
/// @brief (private to src/slice) A locator leaf as the block sampler meets it along one image
/// row: the voxels whose centres lie in its regions, and the warm start of its last Newton run.
#pragma once
#include "trivox/slice/locator.hpp"

namespace trivox::slice::detail {

/// A leaf met by the current row: its voxel interval and warm-start state.
struct RowLeaf {
  int leaf, cell;
  int i0, i1;   ///< voxels whose centres lie in the leaf's regions (grown by the tolerance)
  int last_i;   ///< the voxel this leaf last solved, or -2
  Vec3 last_t;  ///< where that Newton run ended
};

}  // namespace trivox::slice::detail
