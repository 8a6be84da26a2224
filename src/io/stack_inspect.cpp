// Reading a slice stack back: which slices are missing or corrupt, and how many voxels of each
// material the readable ones hold (stack_inspect.hpp).
#include "trivox/io/stack_inspect.hpp"

#include <tbb/parallel_for.h>

#include <climits>
#include <cstring>

#include "png_rows.hpp"
#include "trivox/io/stack_config.hpp"

namespace trivox::io {

namespace fs = std::filesystem;

namespace {

/// What one slice holds.
struct SliceCount {
  bool present = false;
  std::string problem;                 // empty: readable and clean
  std::vector<std::int64_t> voxels;    // per material
  std::int64_t void_voxels = 0;
  std::int64_t foreign = 0;
};

std::uint32_t key_of(const std::uint8_t* p) {
  std::uint32_t k;
  std::memcpy(&k, p, 4);
  return k;
}

/// Counts one slice's pixels by colour. Runs of one colour are the rule (void, or a material's
/// region), so the last colour's index is tried first.
SliceCount count_slice(const fs::path& file, const StackConfig& c, const std::vector<std::uint32_t>& keys) {
  SliceCount out;
  out.voxels.assign(keys.size(), 0);
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) return out;
  out.present = true;
  detail::PngRowReader png(file);
  if (!png.ok()) {
    out.problem = png.error();
    return out;
  }
  if (std::string p = png.format_problem(); !p.empty()) {
    out.problem = p;
    return out;
  }
  if (png.width() != c.width || png.height() != c.height) {
    out.problem = std::to_string(png.width()) + " x " + std::to_string(png.height()) + " pixels; expected " +
                  std::to_string(c.width) + " x " + std::to_string(c.height) + " (SliceWidth x SliceHeight)";
    return out;
  }
  const std::uint32_t background = key_of(c.background.data());
  std::string first_foreign;
  std::size_t last = 0;
  for (int y = 0; y < png.height(); ++y) {
    const std::uint8_t* row = png.row(y);
    if (!row) {
      out.problem = png.error();
      return out;
    }
    for (int x = 0; x < png.width(); ++x, row += 4) {
      const std::uint32_t k = key_of(row);
      if (row[3] == 0 || k == background) {
        ++out.void_voxels;
        continue;
      }
      if (last < keys.size() && keys[last] == k) {
        ++out.voxels[last];
        continue;
      }
      std::size_t m = 0;
      while (m < keys.size() && keys[m] != k) ++m;
      if (m < keys.size()) {
        ++out.voxels[m];
        last = m;
      } else {
        if (out.foreign++ == 0)
          // Appended piecewise: GCC 12 warns falsely (-Wrestrict) on "(" + std::string.
          first_foreign.append("(").append(std::to_string(x)).append(", ").append(std::to_string(y)).append(") = ").append(detail::rgba_text(row));
      }
    }
  }
  if (out.foreign > 0)
    out.problem = std::to_string(out.foreign) + " pixel" + (out.foreign == 1 ? "" : "s") +
                  " of foreign colours, first at (column, row) " + first_foreign +
                  "; expected only MaterialList colours and void (alpha 0)";
  return out;
}

}  // namespace

StackReport inspect_stack(const fs::path& dir) {
  StackReport r;
  r.config = read_stack_config(dir);
  const StackConfig& c = r.config;
  const auto files = detail::list_slices(dir, c.prefix);
  std::vector<std::uint32_t> keys;
  for (const auto& m : c.materials) keys.push_back(key_of(m.rgba.data()));

  const auto n = static_cast<std::size_t>(c.slices);
  std::vector<std::string> names(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto it = files.find(static_cast<long long>(c.start_index) + static_cast<long long>(i));
    names[i] = it != files.end() ? it->second : c.slice_name(static_cast<int>(i));
  }
  std::vector<SliceCount> counts(n);
  tbb::parallel_for(std::size_t{0}, n, [&](std::size_t i) { counts[i] = count_slice(dir / names[i], c, keys); });

  r.voxels_per_material.assign(keys.size(), 0);
  for (std::size_t i = 0; i < n; ++i) {
    const SliceCount& s = counts[i];
    const int number = c.start_index + static_cast<int>(i);
    if (!s.present) {
      r.missing.push_back(number);
      r.problems.push_back({number, names[i], "missing"});
      continue;
    }
    ++r.present;
    r.foreign_pixels += s.foreign;
    if (!s.problem.empty()) {
      r.corrupt.push_back(number);
      r.problems.push_back({number, names[i], s.problem});
    }
    // Foreign colours leave the rest of the slice readable: its material voxels still count.
    if (s.problem.empty() || s.foreign > 0) {
      for (std::size_t m = 0; m < keys.size(); ++m) r.voxels_per_material[m] += s.voxels[m];
      r.void_voxels += s.void_voxels;
    }
  }
  for (const auto& [number, name] : files)
    if (number < c.start_index || number >= static_cast<long long>(c.start_index) + c.slices)
      r.extra.push_back(static_cast<int>(std::min<long long>(number, INT_MAX)));

  r.voxel_volume_mm3 = c.voxel_volume_mm3();
  for (std::size_t m = 0; m < keys.size(); ++m) {
    r.voxels += r.voxels_per_material[m];
    r.volume_per_material_mm3.push_back(static_cast<double>(r.voxels_per_material[m]) * r.voxel_volume_mm3);
    // Only a complete read can contradict the recorded counts.
    if (r.missing.empty() && r.corrupt.empty() && r.voxels_per_material[m] != c.materials[m].voxel_count)
      r.count_mismatch.push_back(static_cast<int>(m));
  }
  r.volume_mm3 = static_cast<double>(r.voxels) * r.voxel_volume_mm3;
  return r;
}

}  // namespace trivox::io
