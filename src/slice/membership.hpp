/// @file src/slice/membership.hpp
/// @brief (private to src/slice) The Booleans' trimmed cells in the locator (Massarwi & Elber
/// 2016, Sec. 4): per trimmed cell one locator per condition, built here (membership.cpp) and
/// asked by Locator::admits.
#pragma once
#include "trivox/slice/locator.hpp"

#include "locator_data.hpp"

namespace trivox::slice::detail {

/// D.trims and D.any_trim for the model's cells: for each cell that is not plain, a locator
/// over each `within` cell and each `without` solid (with the options `opt`; built recursively,
/// their cells may be trimmed too), its blend rule, and for the distance blend the boundary
/// surfaces of its inputs (the plain mean when they are not one list per blended value).
void build_trims(Locator::Data& D, const vmodel::VModel& model, const LocatorOptions& opt);

}  // namespace trivox::slice::detail
