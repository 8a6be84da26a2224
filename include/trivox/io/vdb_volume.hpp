/// @file trivox/io/vdb_volume.hpp
/// @brief Building and writing a print job's OpenVDB file from plain per-voxel values: a fog
/// volume `density`, a colour grid `color` with its copy `Cd`, then float grids (material
/// fractions, properties), every grid with the active voxels of `density` (docs/vdb.md).
///
/// Use: a VdbVolume made from a VdbVolumeSpec (voxel size and position, the float grids' names
/// and metadata, the file's metadata); in parallel, each piece of work fills a VdbLeafValues per
/// 8^3 block and adds it to its own VdbLeaves, which builds the OpenVDB leaf nodes there and then
/// (no locks, no shared tree); serially, in a fixed order, VdbVolume::adopt takes each VdbLeaves'
/// nodes over; then VdbVolume::write. Leaves rather than a tree per piece of work: a tree of its
/// own per piece and grid would allocate internal nodes (256 KB and more each) only to free them
/// when merged, and the allocator hands such blocks back to the system, so that every piece's
/// would be faulted in afresh.
///
/// The file: OpenVDB streams it to a temporary name in the folder (`.<name>.tmp-<pid>-<n>`); its
/// random header UUID is replaced in place by one derived from the SHA-256 of the file with the
/// UUID zeroed; then fsync and a rename. The same leaves, adopted in the same order, give
/// byte-identical files whatever the thread count, and a reader never sees a partial file.
///
/// Cost: VdbLeaves::add copies (4 + float grids) x 512 values into new leaf nodes; adopt is one
/// tree descent per leaf node. Memory: the grids, 4 x (4 + float grids) bytes per voxel of every
/// leaf (512 voxels) plus OpenVDB's node overhead; `Cd` shares `color`'s tree, in memory and in
/// the file. write streams the grids (OpenVDB drops the inactive values it can), then reads the
/// file twice to hash it (about 1 s per GB).
#pragma once
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <variant>
#include <vector>

namespace trivox::io {

/// Voxels along an edge of a leaf, and in a leaf (OpenVDB's leaf nodes are 8^3 voxels).
inline constexpr int vdb_leaf_dim = 8;
inline constexpr int vdb_leaf_voxels = 512;

/// A metadata value: text, a double or a 32-bit integer (OpenVDB's string, double and int32).
using VdbMetaValue = std::variant<std::string, double, std::int32_t>;

/// A named metadata value.
struct VdbMetaEntry {
  std::string name;
  VdbMetaValue value;
};

/// A float grid after `density`, `color` and `Cd`: a material's fraction or a property.
struct VdbFloatGrid {
  std::string name;                    ///< the grid's name, unique in the file
  std::vector<VdbMetaEntry> metadata;  ///< its own metadata (the file's is added to every grid)
};

/// What a volume is: where its voxels lie, its float grids and the file's metadata.
struct VdbVolumeSpec {
  double voxel_size = 1.0;                   ///< edge of a voxel in world units, above 0
  std::array<double, 3> first_centre{};      ///< world position of the centre of voxel (0, 0, 0):
                                             ///< voxel (i, j, k) is at first_centre + (i, j, k) voxel_size
  std::vector<VdbFloatGrid> float_grids;     ///< in file order, after density, color and Cd
  std::vector<VdbMetaEntry> metadata;        ///< the file's metadata, given to every grid too
};

/// The values of one leaf: the 8^3 voxels from `origin` (index coordinates, each a multiple of
/// 8). Voxel origin + (x, y, z), x, y, z in 0..7, is at offset n = offset(x, y, z) = 64 x + 8 y + z
/// (OpenVDB's order). Inactive voxels hold 0 (the grids' background): clear sets every value to 0.
struct VdbLeafValues {
  std::array<int, 3> origin{};
  std::array<std::uint64_t, 8> active{};  ///< bit n % 64 of word n / 64: voxel n is active
  std::vector<float> density;             ///< 512: voxel n at n
  std::vector<float> color;               ///< 3 x 512: r, g, b of voxel n at 3 n, 3 n + 1, 3 n + 2
  std::vector<float> floats;              ///< 512 per float grid, in the spec's order: grid g's
                                          ///< voxel n at 512 g + n

  /// Makes this the leaf at `leaf_origin` for `float_grids` float grids: no voxel active, every
  /// value 0 (the vectors keep their capacity).
  void clear(const std::array<int, 3>& leaf_origin, int float_grids);
  static constexpr int offset(int x, int y, int z) { return 64 * x + 8 * y + z; }
  void set_active(int n) { active[static_cast<std::size_t>(n >> 6)] |= std::uint64_t{1} << (n & 63); }
};

/// OpenVDB leaf nodes, one per grid and leaf, built from VdbLeafValues, waiting for a VdbVolume to
/// adopt them. One per piece of parallel work: add is not thread-safe on one object.
class VdbLeaves {
public:
  /// Leaves for a volume with `float_grids` float grids.
  explicit VdbLeaves(int float_grids);
  VdbLeaves(VdbLeaves&&) noexcept;
  VdbLeaves& operator=(VdbLeaves&&) noexcept;
  ~VdbLeaves();

  /// Builds the leaf nodes of `values`' leaf: its density, colour and float grids' values, with its
  /// active voxels in every grid.
  /// @throws Error (failed) when `values` does not hold 512 values per grid (1 + 3 + float grids)
  void add(const VdbLeafValues& values);

  /// Leaves added and not yet adopted.
  std::size_t size() const;

private:
  friend class VdbVolume;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// What VdbVolume::write wrote.
struct VdbFileWritten {
  std::int64_t bytes = 0;  ///< file size
  std::string sha256;      ///< of the file's bytes (hex)
};

/// A print job's grids: `density` (class fog volume), `color` (vector type invariant), `Cd` (a
/// second grid on color's tree), then the spec's float grids; all with the linear transform of
/// the spec's voxel size and position, the grids' names and metadata and the file's metadata.
class VdbVolume {
public:
  /// Empty grids. Initialises OpenVDB (once per process).
  explicit VdbVolume(const VdbVolumeSpec& spec);
  VdbVolume(const VdbVolume&) = delete;
  VdbVolume& operator=(const VdbVolume&) = delete;
  ~VdbVolume();

  /// Moves `leaves`' nodes into the grids (leaves is left empty). Their positions must be new:
  /// a leaf at a position taken before replaces the earlier one. Adopting the same leaves in the
  /// same order gives the same trees.
  /// @throws Error (failed) when `leaves` was made for another number of float grids
  void adopt(VdbLeaves& leaves);

  /// Grid names in file order: density, color, Cd, the float grids.
  std::vector<std::string> grid_names() const;

  /// Writes the grids and the file's metadata to `path` (the folder must exist), atomically and
  /// with the UUID derived from the file's content (see above).
  /// @throws Error (bad_input) when the folder is not writable or lacks room; (failed) when
  ///         OpenVDB fails to write
  VdbFileWritten write(const std::filesystem::path& path) const;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace trivox::io
