/// @file trivox/slice/trim.hpp
/// @brief The Booleans' trimming applied to a sampled band of voxels (Massarwi & Elber 2016, Sec.
/// 4: the result's cells are mutually exclusive pieces of the inputs' cells; vmodel/boolean.hpp).
///
/// The layer sampler assigns each voxel to the first cell whose trivariate holds its centre.
/// For a model with trimmed cells this pass then corrects every voxel owned by a trimmed cell:
/// where the cell's conditions do not admit the centre (Locator::admits), the voxel goes to the
/// cell that does hold it (Locator::locate, which honours the trimming) or becomes void; where
/// they do, its properties are blended by the cell's rule (in the same Locator::admits). So
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

/// The volume of a trimmed cell: the integral of |det J| over the parameters whose image its
/// conditions admit, by a tensor Gauss rule (2^3 points) on `divisions`^3 equal sub-boxes of
/// the domain. Not exact where the trimming boundary crosses a sub-box (error about the
/// boundary's area times a sub-box's size); exact, like geom::volume, for a plain cell and for
/// trimming along the sub-boxes' faces. Cost: divisions^3 * 8 evaluations and membership tests.
double trimmed_volume(const Locator& loc, int cell, int divisions = 16);

/// The model with every trimmed cell whose admitted part is the image of a parameter box
/// restricted to that box (spline::restrict_to), so that its trivariate's faces are the piece's
/// faces: two boxes united give three box cells glued face to face (Massarwi & Elber 2016, Fig. 3),
/// a cylinder cut across its axis keeps a shorter cylinder. The box is found on a 17^3 grid of
/// parameters (the admitted ones must fill an index box exactly), its faces by bisection along
/// lines through its centre to 1e-13 of the domain, then checked at 9^3 points inside and at points
/// just outside every cut face. The trimming conditions are kept, so membership stays exact
/// even where this reading of the region were wrong; cells whose region is not such a box are
/// returned unchanged. Cost per trimmed cell: about 6,000 membership tests.
vmodel::VModel untrim(const vmodel::VModel& model);

}  // namespace trivox::slice
