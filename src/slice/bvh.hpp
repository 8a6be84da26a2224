/// @file src/slice/bvh.hpp
/// @brief (private to src/slice) The locator's bounding-volume hierarchy over its leaves' xyz
/// boxes: built here (bvh.cpp), searched by Locator::query for the leaves near a box.
#pragma once
#include "locator_data.hpp"

namespace trivox::slice::detail {

/// Median-split BVH over the leaf boxes (D.nodes, D.items): the longest axis of a node's box is
/// split at the median of the leaves' centres, down to four leaves per node.
void build_bvh(Locator::Data& D);

}  // namespace trivox::slice::detail
