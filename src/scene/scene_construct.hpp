/// @file src/scene/scene_construct.hpp
/// @brief Private to scene: the parts of scenes that build cells from surfaces (scene.hpp):
/// derived scene surfaces ("gismo" patches merged, "offset") and the constructor operations
/// (ruled, boolean_sum (six faces, or the solid of a tube), half_boolean_sum, extrude, sweep).
/// scene_read.cpp and scene_build.cpp call these; the messages follow their form,
/// "<file>: <JSON pointer>: <found>; expected <what>".
#pragma once
#include <map>
#include <string>
#include <vector>

#include "../io/json_io.hpp"
#include "trivox/scene/scene.hpp"

namespace trivox::scene::detail {

/// Reads the property field at `ptr` (scene_read.cpp reads primitives' fields with it).
construct::Field read_field(const io::json_io::Source& src, const io::json_io::json& j, const std::string& ptr,
                            std::size_t properties);

/// True for an object of "surfaces" that is a recipe ("gismo" or "offset") rather than a spline.
bool is_derived_surface(const io::json_io::json& item);

/// Reads a recipe surface at `ptr` named `name`; a "gismo" one loads and merges its patches now
/// (the file relative to the scene's folder, src.name's parent).
SceneSurfaceRecipe read_derived_surface(const io::json_io::Source& src, const io::json_io::json& item, const std::string& ptr,
                                        std::string name);

/// The constructor operations build_scene builds.
bool is_constructor(const std::string& op);

/// Reads a constructor operation's fields into o.constructor (and its name into o.name).
void read_constructor(const io::json_io::Source& src, const io::json_io::json& item, const std::string& ptr,
                      SceneOperation& o, std::size_t properties);

/// Every scene surface by name: the splines of /surfaces and the recipes, offsets computed in file
/// order; their reports appended to out.surfaces.
std::map<std::string, spline::Surface> resolve_surfaces(const Scene& scene, const io::json_io::Source& src, SceneBuild& out);

/// The cells of one constructor operation, its report appended to out.constructs.
std::vector<vmodel::VCell> apply_constructor(const Scene& scene, const io::json_io::Source& src, const SceneOperation& op,
                                             const std::map<std::string, spline::Surface>& surfaces, SceneBuild& out);

}  // namespace trivox::scene::detail
