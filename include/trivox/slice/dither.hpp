/// @file trivox/slice/dither.hpp
/// @brief Halftoning material fractions into one material per voxel, layer by layer.
///
/// Each voxel of a layer carries a vector of material fractions (MaterialMapper); the printer
/// deposits one material per voxel. LayerDitherer chooses it so that, over any region of
/// constant fractions, each material's share of the voxels matches its fraction:
/// - `fs`: vector error diffusion (Floyd & Steinberg 1976, generalised to a simplex of
///   materials): the voxel takes the material with the largest error-corrected fraction among
///   those present in its own fraction vector (ties: the lowest index), and the difference
///   (corrected - chosen one-hot) goes to the unvisited neighbours with FS weights rescaled
///   for the voxel's aspect ratio (diffusion_weights). Rows are visited in serpentine order
///   (even rows left to right). Void voxels neither receive nor pass error: the weights are
///   renormalised over the neighbours inside the layer that are not void in the current row,
///   and error reaching a void voxel of the next row (whose voids are not known yet when the
///   error is sent) is discarded there.
/// - `stochastic`: the material drawn by inverse CDF from a uniform number hashed from
///   (seed, layer, row, column): independent of banding, threads and visiting order.
/// - `none`: the largest fraction (ties: the lowest index).
/// docs/materials.md gives the maths.
///
/// Bands: a layer's rows arrive in successive dither() calls with increasing row0; error
/// diffusion carries its state across calls, so the output does not depend on how a layer is
/// split into bands. Rows skipped between two calls count as void rows.
///
/// Cost: O(materials) per non-void voxel (about 8 flops per material for `fs`, in 4-wide vectors
/// up to 8 materials, one 8-wide vector with AVX2 on the colour path; dither_paint maps, dithers
/// and paints in one pass), O(1) per void voxel; no allocation after construction; memory for
/// `fs` 2 (nx + 2) s floats, s = materials (rounded up to a multiple of 4 when at most 8). One
/// LayerDitherer per thread: it holds the error state of the layer in progress.
#pragma once
#include <array>
#include <cstdint>
#include <string_view>
#include <vector>

namespace trivox::slice {

class MaterialMapper;

enum class DitherMode { fs, stochastic, none };

/// "fs", "stochastic" or "none".
/// @throws trivox::Error (bad_input) "--dither X: expected fs, stochastic or none"
DitherMode parse_dither_mode(std::string_view text);
/// The option text of a mode (inverse of parse_dither_mode).
std::string_view dither_mode_name(DitherMode mode) noexcept;

/// Error-diffusion weights of the four forward neighbours, summing to 1. Row direction is
/// "forward"; "down" is the next row. Floyd-Steinberg's 7, 3, 5, 1 (/16) for a square voxel,
/// each scaled by (its neighbour's distance on a square grid) / (its distance on this grid),
/// then normalised: on the J750's 42.3 x 84.7 um voxel, 0.582, 0.158, 0.208, 0.053.
struct DiffusionWeights {
  double forward;       ///< (x + dir, y)
  double down_back;     ///< (x - dir, y + 1)
  double down;          ///< (x, y + 1)
  double down_forward;  ///< (x + dir, y + 1)
};
/// @param pitch_x, pitch_y  voxel size along a row and from row to row (any unit, > 0)
/// @throws trivox::Error (bad_input) on non-finite or non-positive pitches
DiffusionWeights diffusion_weights(double pitch_x, double pitch_y);

/// Chooses one material per voxel, a layer at a time (see the file comment).
class LayerDitherer {
public:
  /// @param mode       fs, stochastic or none
  /// @param nx         voxels per row (>= 1)
  /// @param materials  length of each voxel's fraction vector (1..254)
  /// @param pitch_x    voxel size along a row (mm), for the fs weights
  /// @param pitch_y    row-to-row distance (mm)
  /// @param seed       varies the stochastic pattern (fs and none ignore it)
  /// @throws trivox::Error (bad_input) on nx < 1, materials outside 1..254, bad pitches
  LayerDitherer(DitherMode mode, int nx, int materials, double pitch_x, double pitch_y, std::uint64_t seed = 0);

  /// Starts layer `layer` (the stochastic hash uses it): clears the error state.
  void begin_layer(int layer);

  /// Dithers rows [row0, row0 + rows) of the current layer.
  /// @param row0       first row; for fs at least the end of the previous call's rows
  /// @param rows       number of rows (>= 0)
  /// @param cell       rows * nx values, row-major; < 0 marks a void voxel
  /// @param fractions  rows * nx * materials floats, voxel-major: non-negative, summing to 1
  ///                   (MaterialMapper::fractions); not read for void voxels. A voxel whose
  ///                   fractions are all zero gets material 0.
  /// @param out        rows * nx material indices written; void_material (255) for void voxels
  /// @throws trivox::Error (failed) when fs rows go backwards (row0 below the previous end)
  void dither(int row0, int rows, const std::int32_t* cell, const float* fractions, std::uint8_t* out);

  /// The print job's row: maps the voxels' properties to fractions (`mapper`), dithers them as
  /// dither() does and paints each voxel in its material's colour, with exactly the output of
  /// those three steps one after the other (mapper.fractions, dither, colours[index]). For fs
  /// with a colour-only mapper whose colour materials are indices 0..4 of at most 8, the three
  /// run in one pass (the mapping and painting hide behind the dither's dependency chain, and
  /// no fraction or index buffer makes a round trip through memory); otherwise in turn, through
  /// buffers held here.
  /// @param row      the row (same rules as dither())
  /// @param cell     nx values; < 0 marks a void voxel
  /// @param props    nx * mapper.properties() floats, voxel-major (RowBand::props)
  /// @param mapper   the job's mapper; mapper.materials() == materials()
  /// @param colours  RGBA of each material index, 4 bytes each (index 255: void, the stack's background colour)
  /// @param rgba     nx * 4 bytes written
  /// @param counts   materials() counters: each gets the number of voxels of that material added
  void dither_paint(int row, const std::int32_t* cell, const float* props, const MaterialMapper& mapper,
                    const std::array<std::uint32_t, 256>& colours, std::uint8_t* rgba, std::int64_t* counts);

  DitherMode mode() const noexcept { return mode_; }
  int nx() const noexcept { return nx_; }
  int materials() const noexcept { return materials_; }

private:
  void fs_row(int row, const std::int32_t* cell, const float* fractions, std::uint8_t* out);
  void stochastic_row(int row, const std::int32_t* cell, const float* fractions, std::uint8_t* out) const;
  void none_row(const std::int32_t* cell, const float* fractions, std::uint8_t* out) const;

  DitherMode mode_;
  int nx_, materials_;
  std::uint64_t seed_;
  int layer_ = 0;
  int next_row_ = 0;            // first row the next fs call may start at
  float weights_[8][4] = {};    // per neighbour-availability mask: forward, down_back, down, down_forward
  std::vector<float> error_;    // 2 halves of (nx + 2) * stride: incoming error of a row, and of the next
  std::vector<float> scratch_;  // corrected fractions and the in-row carry (runtime-count kernel)
  std::vector<float> row_fractions_;       // dither_paint's buffers when it runs step by step
  std::vector<std::uint8_t> row_chosen_;
};

/// fs for several layers at once, on the print job's colour path: the layers' voxels at the same
/// (row, column) ride in the lanes of one 8-wide vector per colour material (structure of arrays),
/// so the material choice is a vertical max and compare, not a horizontal reduction within one
/// voxel's vector, and the serial chain from voxel to voxel is shared by up to 8 layers. Layers
/// are independent, and every lane runs LayerDitherer::dither_paint's fused kernel operation for
/// operation (same IEEE floats, same choice among ties), so each layer's pixels and counts are
/// bit-identical to dithering it alone: grouping never changes a job's output.
///
/// Applies where LayerDitherer::dither_paint runs fused (serves()): fs, a colour-only mapper whose
/// five colour materials are indices 0..4 of at most 8 (the others never receive error or get
/// chosen there, so only the five are carried), on an x86-64 CPU with AVX2.
///
/// Cost per row: only the columns from the first to the last where some layer of the group has
/// a live voxel are worked on (each layer's row scanned from both ends, eight cells per compare;
/// outside them every lane is void, so there the kernel would only paint void and pass no
/// error): the layers' cells and properties there transposed into lanes (4 x 4 transposes within
/// 128-bit halves), about 140 vector instructions per column for all the layers together, and
/// the choices transposed back (as RGBA pixels, or as one-byte material indices), void written
/// around them: 4.0 ns per grid voxel of the bench job (docs/materials.md). Memory: 2 (nx + 2) * 40 floats of error and 8 (np + 2) floats per column
/// of transposed rows. One object per thread.
class LayerGroupDitherer {
public:
  static constexpr int max_layers = 8;

  /// Whether the grouped kernel applies to a job with this mode and mapper (see the class comment).
  static bool serves(DitherMode mode, const MaterialMapper& mapper) noexcept;

  /// @param nx       voxels per row (>= 1)
  /// @param mapper   the job's mapper (serves() must hold; its property indices are copied)
  /// @param pitch_x  voxel size along a row (mm), for the fs weights
  /// @param pitch_y  row-to-row distance (mm)
  /// @throws trivox::Error (bad_input) on nx < 1 or bad pitches; (failed) when !serves()
  LayerGroupDitherer(int nx, const MaterialMapper& mapper, double pitch_x, double pitch_y);

  /// Starts a group of `layers` layers (1..max_layers): clears the error state.
  void begin(int layers);

  /// LayerDitherer::dither_paint of image row `row` for each layer l < layers of the group.
  /// @param row      the row: increasing from call to call (skipped rows count as void rows)
  /// @param cell     per layer: nx cell ids (< 0: void)
  /// @param props    per layer: nx * mapper.properties() floats, voxel-major
  /// @param colours  RGBA of each material index (index 255: void)
  /// @param rgba     per layer: nx * 4 bytes written
  /// @param counts   per layer: materials() counters, each voxel of material m adds 1 to [m]
  /// @throws trivox::Error (failed) when rows go backwards
  void dither_paint(int row, const std::int32_t* const* cell, const float* const* props,
                    const std::array<std::uint32_t, 256>& colours, std::uint8_t* const* rgba,
                    std::int64_t* const* counts);
  /// The same choices as material indices (LayerDitherer::dither of the mapper's fractions):
  /// one byte per voxel instead of four, what the print job keeps of a group's layers until they
  /// are encoded (io::encode_png_indexed paints them).
  /// @param index  per layer: nx material indices written (void_material for void voxels)
  /// Other parameters and errors as dither_paint.
  void dither(int row, const std::int32_t* const* cell, const float* const* props, std::uint8_t* const* index,
              std::int64_t* const* counts);

  int layers() const noexcept { return layers_; }
  int nx() const noexcept { return nx_; }

private:
  /// One row of the group through the kernel: table[choice] (choice 0..4, 7 for void) per
  /// column and lane into chosen_ for the columns lo..hi where some layer has a live voxel
  /// (every other column is void in every layer), the counts added; lo > hi when there are none.
  void row_(int row, const std::int32_t* const* cell, const float* const* props, const std::int32_t (&table)[8],
            std::int64_t* const* counts, int& lo, int& hi);
  /// Zero error in both halves.
  void clear_errors();
  int nx_, np_, ir_ = 0, ig_ = 0, ib_ = 0;
  int layers_ = 0;
  int next_row_ = 0;
  // Per half of error_, the columns (-1 and nx: the pads) written into it last; zero elsewhere.
  std::array<std::array<int, 2>, 2> written_{{{0, -1}, {0, -1}}};
  // The fs weights per neighbour mask, each broadcast to 8 lanes (an AVX register each).
  alignas(32) float weights_[8][4][8] = {};
  // Column-major buffers (per column one vector, lane l = layer l of the group):
  std::vector<float> error_;          // 2 halves of (nx + 2) * 40: [column][material][lane]
  std::vector<float> props_;          // nx * np * 8: [column][property][lane], the row in progress
  std::vector<std::int32_t> cell_;    // (nx + 2) * 8: [column + 1][lane], pads void
  std::vector<std::int32_t> chosen_;  // nx * 8: [column][lane], the painted RGBA or the index
  std::vector<float> no_props_;       // nx * np zeros, and nx void cells: lanes without a layer
  std::vector<std::int32_t> no_cells_;
};

}  // namespace trivox::slice
