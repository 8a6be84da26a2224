/// @file src/slice/leaves.hpp
/// @brief (private to src/slice) A Bezier piece's parameter box subdivided into nearly affine
/// leaves, each with the two regions that hold its image (LocatorLeaf): the box of its control
/// points and their parallelepiped in the frame of its least-squares affine map. Defined in
/// leaves.cpp.
#pragma once
#include <array>
#include <vector>

#include "trivox/slice/locator.hpp"

namespace trivox::slice::detail {

/// How far a net is from affine, and the regions that hold its control points.
struct Flatness {
  double deviation = 0.0;  ///< max distance of a control point from the least-squares affine map
  double diagonal = 0.0;   ///< of the control points' box
  Vec3 box_lo{}, box_hi{};
  /// The parallelepiped of the affine map's frame that holds every control point (see LocatorLeaf).
  Vec3 origin{}, frame_lo{}, frame_hi{};
  std::array<Vec3, 3> frame{};  ///< rows of the inverse of the affine map's matrix
};

/// A leaf of build_leaves: its box in the piece's local [0,1]^3 and its regions.
struct LeafBox {
  Vec3 lo, hi;
  Flatness f;
};

/// Subdivides a piece's parameter box (local [0,1]^3) into nearly affine leaves: deviation from
/// affine at most 10% of the leaf's diagonal and, when `max_dev` > 0, at most max_dev; then, when
/// 0 < fine_dev < max_dev, on towards fine_dev with at most fine_factor times as many leaves
/// (the most deviating split first, so a budget that runs out leaves the piece evenly refined).
/// Cost per split: one de Casteljau triangle and one or two affine fits per direction tried; the
/// frames only for the leaves. Nets live in one slab of reused slots (no allocation per split).
/// @param net  the piece's geometry net: H coordinates per control point, u fastest
void build_leaves(const double* net, const std::array<int, 3>& ord, int H, double min_diag, double max_dev, double fine_dev,
                  int fine_factor, int max_leaves, std::vector<LeafBox>& out);

}  // namespace trivox::slice::detail
