/// @file trivox/slice/trim.hpp
/// @brief The Booleans' trimming applied to a sampled band of voxels (seed 003 Sec. 4: the
/// result's cells are mutually exclusive pieces of the inputs' cells; vmodel/boolean.hpp).
///
/// The layer sampler assigns each voxel to the first cell whose trivariate holds its centre.
/// For a model with trimmed cells this pass then corrects every voxel owned by a trimmed cell:
/// where the cell's conditions do not admit the centre (Locator::admits), the voxel goes to the
/// cell that does hold it (Locator::locate, which honours the trimming) or becomes void; where
/// they do, its properties are blended by the cell's rule (Locator::blend_properties). So
/// occupancy is exactly Locator::locate's answer for these voxels, and the properties of an
/// intersection cell are the blend of its inputs' values at the centre.
///
/// Cost: for voxels of trimmed cells only, one point location per condition (a BVH descent
/// and a few Newton steps, about a microsecond); plain cells cost nothing. Deterministic: each
/// voxel's result depends only on its centre.
#pragma once
#include "trivox/slice/grid.hpp"
#include "trivox/slice/locator.hpp"
#include "trivox/slice/sampler.hpp"

namespace trivox::slice {

/// Corrects `band` (sampled by a LayerSampler over loc's model on `grid`) for trimmed cells.
/// band.uvw, when kept, follows the new owners.
void apply_trimming(const Locator& loc, const VoxelGrid& grid, RowBand& band);

}  // namespace trivox::slice
