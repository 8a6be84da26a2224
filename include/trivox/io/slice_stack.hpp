/// @file trivox/io/slice_stack.hpp
/// @brief A Voxel Print slice stack, all of it: its `ConfigFile.xml` (stack_config.hpp), its PNG
/// slices (png_image.hpp), the `.gcvf` archive (gcvf.hpp), reading it back (stack_inspect.hpp)
/// and its preview picture (preview.hpp).
#pragma once
#include "trivox/io/gcvf.hpp"
#include "trivox/io/png_image.hpp"
#include "trivox/io/preview.hpp"
#include "trivox/io/stack_config.hpp"
#include "trivox/io/stack_inspect.hpp"
