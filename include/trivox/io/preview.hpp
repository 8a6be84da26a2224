/// @file trivox/io/preview.hpp
/// @brief A picture of a slice stack for a person (`trivox preview`): a contact sheet of slices
/// and a vertical cross-section.
#pragma once
#include <filesystem>
#include <vector>

namespace trivox::io {

/// What write_preview drew.
struct PreviewSummary {
  int width = 0, height = 0;      ///< of the picture
  int every = 0;                  ///< slice step of the contact sheet
  std::vector<int> shown;         ///< slice numbers on the contact sheet
  std::vector<int> unreadable;    ///< slices missing or corrupt, ascending: those on the sheet (crossed
                                  ///< out) and those the cross-section needed (red rows)
  int section_row = 0;            ///< image row of the slices the cross-section goes through
  int section_width = 0, section_height = 0;  ///< size of the cross-section in the picture
  int section_z_scale = 1;        ///< vertical exaggeration of the section (1: true proportions)
};

/// A picture of a stack for a person: a contact sheet of every `every`-th slice (labelled with
/// the slice number), then a vertical cross-section (XZ plane through the middle image row,
/// x to the right, the top layer at the top), both scaled so voxels keep their physical
/// proportions (a 600 x 300 dpi slice is drawn half as tall per pixel row as it is wide per
/// column); a section that would be under 48 pixels tall (a thin job on a wide tray) is stretched
/// along z by a whole factor, labelled "XZ Z n:1". Colours are box-filtered (a dithered region shows its mean colour) and composited
/// over a dark grey checkerboard, so void shows as the checkerboard; missing or corrupt slices
/// are crossed out in red. Written as an opaque RGBA PNG (zlib level 6), atomically.
/// Cost: one decode of each shown slice, plus decoding each slice the cross-section samples up
/// to the middle row (at most one per picture row of the section), in parallel.
/// @param every  slice step; 0 picks ceil(slices / 16) (about 16 thumbnails)
/// @param width  picture width in pixels (64..16384)
/// @throws trivox::Error (bad_input) for an unusable folder or ConfigFile.xml, `every` < 0,
///         `width` out of range, more than 1024 thumbnails, or a picture over 32768 pixels tall;
///         (failed) when the PNG module cannot be loaded
PreviewSummary write_preview(const std::filesystem::path& dir, const std::filesystem::path& png, int every = 0,
                             int width = 1600);

}  // namespace trivox::io
