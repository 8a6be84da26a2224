#!/usr/bin/env bash
# The installed trivox (docs/install.md): `cmake --install BUILD --prefix P` into a temporary
# prefix, then
#   (a) a consumer project written here, built with find_package(trivox) and trivox::core alone,
#       loads models/graded_block.json and evaluates two of its cells; the points must equal
#       values computed here from the model file's control points (the block is trilinear, so
#       its point is the trilinear blend of its 8 corners; the arch's knots are clamped, so its
#       corner is a control point);
#   (b) every #include "..." of an installed header resolves to an installed header, and each
#       installed header compiles alone (g++ -fsyntax-only -I P/include);
#   (c) the installed P/bin/trivox prints its version and slices to PNGs with the module from
#       P/lib/trivox/ (TRIVOX_PLUGIN_DIR unset; the dynamic loader's log, LD_DEBUG=files, names
#       the one it initialised: the build folder's module, tried last, must not be the one).
# Usage: tests/house/install.sh BUILD_DIR   (run from the repository's top folder)
set -euo pipefail
build=$(cd "${1:?usage: install.sh BUILD_DIR}" && pwd)
src=$(pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
tmp=$(cd "$tmp" && pwd -P)   # as the loader names it (/proc/self/exe has no symbolic links)
cache() { sed -n "s/^$1:[A-Z]*=//p" "$build/CMakeCache.txt"; }
cmake=$(cache CMAKE_COMMAND)
cxx=$(cache CMAKE_CXX_COMPILER)
generator=$(cache CMAKE_GENERATOR)
make_program=$(cache CMAKE_MAKE_PROGRAM)
version=$(sed -n 's/^CMAKE_PROJECT_VERSION:STATIC=//p' "$build/CMakeCache.txt")
prefix=$tmp/prefix

"$cmake" --install "$build" --prefix "$prefix" > "$tmp/install.log"
for f in bin/trivox lib/trivox/libtrivox_png.so lib/libtrivox_core.a include/trivox/version.hpp \
         include/trivox/io/model_file.hpp lib/cmake/trivox/trivoxConfig.cmake \
         lib/cmake/trivox/trivoxConfigVersion.cmake lib/cmake/trivox/trivoxTargets.cmake; do
  [ -f "$prefix/$f" ] || { echo "not installed: $f"; cat "$tmp/install.log"; exit 1; }
done
if find "$prefix" -name '*bench*' -o -name 'test_*' | grep .; then echo "benches or tests installed"; exit 1; fi
grep -q "\"$version\"" "$prefix/include/trivox/version.hpp"

# (a) A consumer of the package.
mkdir "$tmp/consumer"
cat > "$tmp/consumer/CMakeLists.txt" <<'EOF'
cmake_minimum_required(VERSION 3.25)
project(consumer LANGUAGES CXX)
find_package(trivox REQUIRED)
add_executable(consumer main.cpp)
target_compile_features(consumer PRIVATE cxx_std_20)
target_link_libraries(consumer PRIVATE trivox::core)
get_target_property(png_module trivox::png LOCATION)
message(STATUS "trivox ${trivox_VERSION}, PNG module ${png_module}")
EOF
cat > "$tmp/consumer/main.cpp" <<'EOF'
// Prints the point of a cell of a model at parameters given as fractions of its domain.
#include <array>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "trivox/error.hpp"
#include "trivox/io/model_file.hpp"
#include "trivox/version.hpp"

int main(int argc, char** argv) {
  if (argc != 6) return 2;
  try {
    const trivox::vmodel::VModel model = trivox::io::load_model(argv[1]);
    const trivox::vmodel::VCell* cell = model.find_cell(argv[2]);
    if (!cell) return 3;
    std::array<double, 3> t{};
    for (int d = 0; d < 3; ++d) {
      const auto [a, b] = cell->volume.domain(d);
      t[static_cast<std::size_t>(d)] = a + std::atof(argv[3 + d]) * (b - a);
    }
    const std::vector<double> p = cell->volume.eval(t);
    std::printf("trivox %s:", trivox::version);
    for (double x : p) std::printf(" %.17g", x);
    std::printf("\n");
  } catch (const trivox::Error& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
}
EOF
"$cmake" -S "$tmp/consumer" -B "$tmp/consumer/build" -G "$generator" -DCMAKE_MAKE_PROGRAM="$make_program" \
  -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$prefix" > "$tmp/configure.log" 2>&1 ||
  { cat "$tmp/configure.log"; exit 1; }
grep -q -- "-- trivox $version, PNG module $prefix/lib/trivox/libtrivox_png.so\$" "$tmp/configure.log" ||
  { echo "find_package(trivox) gave another version or module:"; cat "$tmp/configure.log"; exit 1; }
"$cmake" --build "$tmp/consumer/build" > "$tmp/build.log" 2>&1 || { cat "$tmp/build.log"; exit 1; }
# The imported target's include folder is the prefix's, never the source tree's.
grep -q -- "-I$src/include\|-isystem $src/include" "$tmp/consumer/build/build.ninja" 2> /dev/null &&
  { echo "the consumer compiles with the source tree's headers"; exit 1; }

model=$src/models/graded_block.json
check() {  # cell u v w: the consumer's point against the one computed from the file
  local got want
  got=$("$tmp/consumer/build/consumer" "$model" "$@")
  want=$(python3 - "$model" "$@" <<'EOF'
import json, sys
model, name = json.load(open(sys.argv[1])), sys.argv[2]
t = [float(x) for x in sys.argv[3:6]]
cell = next(c for c in model["cells"] if c["name"] == name)["trivariate"]
counts = [len(k) - o for k, o in zip(cell["knots"], cell["orders"])]
pts = cell["points"]
row = lambda i, j, k: i + counts[0] * (j + counts[1] * k)   # u fastest (docs/model-format.md)
if cell["orders"] == [2, 2, 2] and counts == [2, 2, 2]:
    # trilinear: the blend of the eight corners
    p = [0.0] * len(pts[0])
    for i in (0, 1):
        for j in (0, 1):
            for k in (0, 1):
                w = (t[0] if i else 1 - t[0]) * (t[1] if j else 1 - t[1]) * (t[2] if k else 1 - t[2])
                p = [a + w * b for a, b in zip(p, pts[row(i, j, k)])]
else:
    # clamped knots: at a corner of the domain the cell is its corner control point
    assert all(x in (0.0, 1.0) for x in t) and "weights" not in cell
    p = pts[row(*[int(x) * (n - 1) for x, n in zip(t, counts)])]
print(" ".join(repr(float(x)) for x in p))
EOF
)
  python3 - "$got" "$want" "$version" <<'EOF' || { echo "cell $1 at $2,$3,$4: consumer printed '$got', expected '$want'"; exit 1; }
import sys
got, want, version = sys.argv[1].split(), [float(x) for x in sys.argv[2].split()], sys.argv[3]
assert got[:2] == ["trivox", version + ":"], got
got = [float(x) for x in got[2:]]
assert len(got) == len(want) and all(abs(a - b) <= 1e-12 * (1 + abs(b)) for a, b in zip(got, want))
EOF
}
check block 0.25 0.5 0.75
check arch 1 0 1
check arch 0 1 0

# (b) The installed headers: includes resolved inside the prefix, each one self-contained.
headers=$(cd "$prefix/include" && find trivox -name '*.hpp' | sort)
diff <(echo "$headers") <( (cd "$src/include" && find trivox -name '*.hpp'; echo trivox/version.hpp) | sort) ||
  { echo "installed headers (<) differ from include/trivox/ and version.hpp (>)"; exit 1; }
for h in $headers; do
  sed -n 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*"\([^"]*\)".*/\1/p' "$prefix/include/$h" |
    while read -r inc; do
      [ -f "$prefix/include/$inc" ] || { echo "$h includes \"$inc\", which is not installed"; exit 1; }
    done
done
for h in $headers; do echo "#include \"$h\"" > "$tmp/${h//\//_}.cpp"; done
ls "$tmp"/trivox_*.cpp | xargs -P 2 -n 1 "$cxx" -std=c++20 -fsyntax-only -I "$prefix/include"

# (c) The installed command line and its PNG module.
unset TRIVOX_PLUGIN_DIR
[ "$("$prefix/bin/trivox" --version)" = "trivox $version" ] || { "$prefix/bin/trivox" --version; exit 1; }
LD_DEBUG=files LD_DEBUG_OUTPUT=$tmp/ld "$prefix/bin/trivox" slice "$model" -o "$tmp/stack" --png \
  --dpi 100,100 --layer 0.254 --progress never > /dev/null
ls "$tmp/stack"/*.png > /dev/null
[ -f "$tmp/stack/ConfigFile.xml" ]
# The loader logs every file it tries; "calling init" only for the one it loaded.
loaded=$(sed -n 's/.*calling init: \(.*libtrivox_png\.so\)$/\1/p' "$tmp"/ld.*)
[ "$loaded" = "$prefix/lib/trivox/libtrivox_png.so" ] ||
  { echo "the installed trivox loaded '$loaded', not $prefix/lib/trivox/libtrivox_png.so"; exit 1; }
echo "house install: ok"
