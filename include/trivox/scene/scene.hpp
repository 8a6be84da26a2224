/// @file trivox/scene/scene.hpp
/// @brief Scenes: model files whose cells may be primitives with property fields, and which may
/// list operations; `trivox build` turns one into a model (docs/model-format.md, "Scenes", is the
/// user's reference).
///
/// A scene has the model file's header (`trivox`, `units`, `properties`) and `cells`, each
/// either `{"name", "trivariate": SPLINE}` as in a model or `{"name", "primitive": {...},
/// "field": {...}}` (construct/primitives.hpp: Massarwi & Elber 2016, Sec. 3.2.3), optional free
/// `surfaces`, and `operations`, a list of `{"op": NAME, ...}`. Reading checks every value before
/// use and reports the first problem as trivox::Error (bad_input) "<file>: <JSON pointer>: <found>;
/// expected <what>", reusing the model reader's checked access (src/io/json_io.hpp).
///
/// Operations: the names of docs/model-format.md (`union`, `intersection`, `subtraction`, `fillet` and the
/// constructors `ruled`, `extrude`, `revolve`, `boolean_sum`, `half_boolean_sum`, `sweep`) are
/// recognised. The Booleans are built (vmodel/boolean.hpp: Massarwi & Elber 2016, Alg. 1-3): {"op":
/// "union", "a": NAME, "b": NAME, "name": RESULT (default: a), "blend": "sum_clip" | "mean" |
/// "first" | "distance", "power": k}, where a and b name scene cells (a primitive's cells all
/// together) or earlier results; the operation consumes a and b and puts its result, untrimmed
/// (slice::untrim), where a was. Fillets (fillet/fillet.hpp: Masalha et al. 2021, Alg. 2 with Sec.
/// 7.1): {"op": "fillet", "between": [A, B], "distance": d | [d1, d2], "tau", "section": "hermite"
/// | "flend", "dip", "method": "auto" | "compose" | "fit", "blend": "parametric" | "shepard",
/// "power": q (Shepard only, 1..16, default 2; fillet/shepard.hpp, Masalha et al. 2021, Sec. 7.2),
/// "flip": bool | [bool, bool], "construction": "ruled" | "vbs" | "vrep", "name"}, A and B cell
/// names or {"cell": NAME, "face": "u0".."w1"}; without faces, the one pair of faces that
/// intersects is used. With "bridge": true (and both faces named) the fillet is a flend between
/// disjoint faces instead (fillet/bridge.hpp, Eager & Dannenhoffer 2019, Sec. III): one cell
/// `<name>.1` from face to face, with "dip". With a list [{"cell", "face"}, ...] on either side of
/// "between", the fillet runs over several faces (fillet/corners.hpp, Masalha et al. 2021, Sec. 6):
/// one fillet per pair of listed faces that crosses along a curve, chained along C, cells
/// `<name>.<k>a`, `<name>.<k>b` in chain order; with "corners": "bridge" (the default; "open"
/// leaves the gaps, Fig. 12 (c)) each convex C1 corner gets the singular bridging fillet of Sec.
/// 6.1, cells `<name>.c<j>a`, `<name>.c<j>b`. Ruled construction, Hermite section and the
/// parametric blend only. The fillet's cells, two per intersection component (`<name>.<k>a`,
/// `<name>.<k>b`; with "construction": "vbs", Masalha et al. 2021, Sec. 3.2 / Alg. 3, three:
/// `<name>.<k>.1` at C, `.2` at rail 1, `.3` at rail 2; with "vrep", Sec. 5 / Alg. 6, one trimmed
/// cell `<name>.<k>`, the half volumetric Boolean sum without the solid beyond S_b
/// (fillet/vrep_fillet.hpp); vbs and vrep are refused with the Shepard blend), are appended to the
/// model; the filleted cells stay as they are. Constructors (Massarwi & Elber 2016, Sec. 3.2.2,
/// construct/constructors.hpp) build cells from scene surfaces: {"op": "ruled" | "boolean_sum" |
/// "half_boolean_sum" | "extrude" | "revolve" | "sweep", "surfaces": [NAME, ...], "name", "field",
/// ...} (revolve: "axis", "origin", "angle" in degrees, "tolerance" as `trivox construct`), or
/// {"op": "boolean_sum", "tube": NAME, "core"} for the five cells inside a tube
/// (construct/tube_solid.hpp); scene surfaces may be G+Smo patches merged ({"name", "gismo": FILE,
/// "patches", "scale", "u", "v"}) or offsets ({"name", "offset": {"surface", "distance",
/// "tolerance"}}). An unknown name is refused by the reader, which lists the known ones.
///
/// Cost: linear in the file size to read; building is the primitives' cost (milliseconds each)
/// plus any field refinement.
#pragma once
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "trivox/construct/patches.hpp"
#include "trivox/construct/constructors.hpp"
#include "trivox/construct/primitives.hpp"
#include "trivox/fillet/bridge.hpp"
#include "trivox/fillet/corners.hpp"
#include "trivox/fillet/fillet.hpp"
#include "trivox/vmodel/vmodel.hpp"

namespace trivox::scene {

/// The operation names a scene may use (docs/model-format.md), in the order messages list them.
inline constexpr const char* scene_operations[] = {"union",   "intersection", "subtraction", "fillet",
                                                   "ruled",   "extrude",      "revolve",     "boolean_sum",
                                                   "half_boolean_sum", "sweep"};

/// A primitive cell's recipe.
struct ScenePrimitive {
  construct::Primitive primitive;
  construct::PrimitiveOptions options;     ///< the optional "tolerance" of the primitive object
  std::optional<construct::Field> field;   ///< absent only when the scene has no properties
};

struct SceneCell {
  std::string name;
  std::string pointer;  ///< "/cells/<i>", for messages
  std::variant<spline::Trivariate, ScenePrimitive> content;
};

/// A scene surface made from other surfaces instead of given as a spline (see
/// docs/model-format.md, "Scene surfaces"): G+Smo patches merged into one surface
/// (construct/patches.hpp; loaded with the scene), or the offset of an earlier scene surface
/// (computed by build_scene). These feed the constructors; they are not written to the model.
struct SceneSurfaceRecipe {
  std::string name;
  std::string pointer;                    ///< "/surfaces/<i>", for messages
  std::optional<spline::Surface> merged;  ///< "gismo": the merged, scaled (and restricted) patches
  std::string file;                       ///< "gismo": the G+Smo file as the scene names it
  std::vector<int> patches;               ///< "gismo": the patch indices, row after row
  std::array<int, 2> grid{0, 0};          ///< "gismo": columns (along u), rows (along v)
  double max_gap = 0.0;                   ///< "gismo": the largest gap between shared edges
  std::string of;                         ///< "offset": the surface offset
  double distance = 0.0;                  ///< "offset": along S_u x S_v (model units)
  construct::OffsetOptions offset;        ///< "offset": tolerance
};

/// The fields of a constructor operation (ruled, boolean_sum, half_boolean_sum,
/// extrude, revolve, sweep).
struct SceneConstructor {
  std::vector<std::string> surfaces;      ///< the input surfaces' names, in the op's order
  std::string tube;                       ///< boolean_sum: the tube whose solid is built (5 cells)
  double core = 0.5;                      ///< boolean_sum of a tube: the core's relative size
  std::optional<construct::Field> field;  ///< the cells' properties (absent: the surfaces' own)
  int ruling_order = 2;                   ///< ruled
  std::vector<double> vector;             ///< extrude
  construct::Revolution revolution;       ///< revolve: axis, origin, angle, relative tolerance
  std::vector<double> params;             ///< sweep (empty: chord length)
  int order = 4;                          ///< sweep
  double tolerance = 1e-9;                ///< how far boundaries that must meet may be apart
};

struct SceneOperation {
  std::string op;
  std::string pointer;  ///< "/operations/<i>"
  // Booleans:
  std::string a, b;     ///< the operands: scene cell names or earlier results
  std::string name;     ///< the result's name (a when not given)
  vmodel::BlendRule blend = vmodel::BlendRule::sum_clip;
  double power = 1.0;
  // Fillets: the two cells (model cell names, or a scene cell of one cell) and, when chosen,
  // their faces; the fillet's parameters. The result is `name` (default "fillet").
  std::array<std::string, 2> between;
  std::array<std::optional<spline::Face>, 2> faces;
  fillet::FilletOptions fillet;
  bool bridge = false;      ///< "bridge": true: a flend between disjoint faces (fillet/bridge.hpp)
  /// "between" with a list of {"cell", "face"} on a side: the fillet over several faces of seed
  /// 000 Sec. 6 (fillet/corners.hpp); sides[i] are side i's (cell, face, pointer) and between[i]
  /// its first cell. "corners": "bridge" (Sec. 6.1, the default) or "open".
  struct SideFace {
    std::string cell;
    spline::Face face = spline::Face::u0;
    std::string pointer;
  };
  bool across = false;
  std::array<std::vector<SideFace>, 2> sides;
  fillet::CornerOptions corners;
  bool shepard = false;     ///< "blend": "shepard" (Masalha et al. 2021, Sec. 7.2), else parametric (Sec. 7.1)
  int shepard_power = 2;    ///< "power": Shepard's q, 1..16
  SceneConstructor constructor;  ///< constructors: their inputs (the result is `name`)
};

struct Scene {
  std::string source;  ///< the file name messages start with
  std::string units = "mm";
  std::vector<std::string> properties;
  std::vector<SceneCell> cells;
  std::vector<vmodel::NamedSurface> surfaces;
  std::vector<SceneSurfaceRecipe> derived_surfaces;  ///< "gismo" and "offset" surfaces, in file order
  std::vector<SceneOperation> operations;
};

/// Parses a scene (a model file is a scene too: one without primitives or operations).
/// @throws trivox::Error (bad_input) naming `source`, the JSON pointer and what was expected
Scene read_scene_json(std::string_view text, const std::string& source);

/// Reads and parses the scene file at `path` (messages name it as `path.string()`).
Scene load_scene(const std::filesystem::path& path);

/// What building one primitive cell gave, for the quality report.
struct PrimitiveBuild {
  std::string name;     ///< the scene cell's name
  std::string type;     ///< construct::primitive_type
  int first_cell = 0;   ///< index of its first cell in the model
  int cell_count = 0;
  double exact_volume = 0.0;
  bool has_field = false;
  construct::FieldReport field;
  /// The cells' xyz before the field was applied: the same solids, often in coarser spaces (a
  /// non-affine field refines them), so validity and volume are cheaper to check on these.
  std::vector<spline::Trivariate> geometry;
};

/// What one fillet operation gave: per intersection component, a fillet of two cells.
struct FilletBuild {
  std::string name;      ///< the operation's result name
  std::string pointer;   ///< "/operations/<i>"
  std::array<std::string, 2> cells;  ///< the filleted cells
  std::array<spline::Face, 2> faces{};
  /// per component: its cells in the model (ruled: a, b; vbs: T_1, T_2, T_3; vrep: the trimmed T_hbs)
  std::vector<std::vector<std::string>> cell_names;
  std::vector<fillet::FilletQuality> quality;          ///< per component
  /// "blend": "shepard": the encoding's fit of f per cell (two per component, a then b).
  struct ShepardFit {
    double max_error = 0.0, rms_error = 0.0, check_error = 0.0;
    std::int64_t samples = 0;
    double seconds = 0.0;
  };
  std::vector<ShepardFit> shepard;
};

/// What one bridge (a fillet operation with "bridge": true) gave: one cell.
struct BridgeBuild {
  std::string name;       ///< the operation's result name
  std::string pointer;    ///< "/operations/<i>"
  std::array<std::string, 2> cells;  ///< the bridged cells
  std::array<spline::Face, 2> faces{};
  std::string cell_name;  ///< the bridge's cell in the model, <name>.1
  fillet::BridgeQuality quality;
  double seconds = 0.0;
};

/// What one bridging fillet of a fillet over several faces gave (Masalha et al.
/// 2021, Sec. 6.1): two cells.
struct CornerBuild {
  std::string name;                       ///< the operation's result name
  std::string pointer;                    ///< "/operations/<i>"
  std::array<std::string, 2> cell_names;  ///< <name>.c<j>a, <name>.c<j>b
  std::array<std::string, 2> pieces;      ///< the neighbouring pieces, "cell/face x cell/face"
  std::array<std::string, 2> faces;       ///< the face with the gap (smooth at o), the one with the edge
  /// -1: the whole bridge; 0, 1: its part on the arriving or the leaving piece's face (the gap
  /// spans a seam, fillet::CornerFillet::part)
  int part = -1;
  fillet::Junction junction;
  fillet::CornerQuality quality;
};

/// A concave corner of a fillet over several faces (Masalha et al. 2021, Sec. 6): the two pieces
/// clipped at the rails' crossing and stitched.
struct StitchBuild {
  std::string name;                   ///< the operation's result name
  std::string pointer;                ///< "/operations/<i>"
  std::array<std::string, 2> pieces;  ///< the two pieces, "cell/face x cell/face"
  std::array<std::string, 2> faces;   ///< the face whose rails cross, the one with the edge
  fillet::Junction junction;          ///< o, x (the crossing), r, glue
};

/// What one derived surface gave ("gismo" or "offset").
struct SurfaceBuild {
  std::string name, kind;
  std::array<int, 2> orders{}, counts{};
  double max_gap = 0.0;        ///< gismo: largest gap between shared patch edges
  double distance = 0.0;       ///< offset
  construct::OffsetReport offset;
  double seconds = 0.0;
};

/// What one constructor operation gave: its cells.
struct ConstructBuild {
  std::string name, op, pointer;
  std::vector<std::string> cells;  ///< the cells in the model: `name`, or `name.core`, `name.s0`..
  bool has_field = false;
  construct::FieldReport field;
  double seconds = 0.0;
};

struct SceneBuild {
  vmodel::VModel model;
  std::vector<SurfaceBuild> surfaces;
  std::vector<ConstructBuild> constructs;
  std::vector<PrimitiveBuild> primitives;
  std::vector<FilletBuild> fillets;
  std::vector<BridgeBuild> bridges;
  std::vector<CornerBuild> corners;  ///< fillets over several faces: the bridging fillets
  std::vector<StitchBuild> stitches;  ///< fillets over several faces: the stitched concave corners
};

/// Expands the primitives (named `<name>.<part>`, construct/primitives.hpp) and applies their
/// fields; trivariate cells are kept as they are, in scene order.
/// @throws trivox::Error (bad_input) for an operation ("<file>: /operations/<i>/op: \"union\"
///         is not supported yet ..."), for expanded names that collide with other cells, and
///         for primitive or field parameters construct refuses (with the cell's pointer)
SceneBuild build_scene(const Scene& scene);

}  // namespace trivox::scene
