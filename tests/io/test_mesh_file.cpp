// Mesh files (io/mesh_file.hpp) read back by readers written here from the formats' definitions:
// binary STL's 84-byte head and 50-byte facets, PLY's header and little-endian body, OBJ's
// `v` and `f` lines. The mesh is a box coloured by its corners, so every value is known.
#include <catch2/catch.hpp>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <string>

#include "trivox/error.hpp"
#include "trivox/io/mesh_file.hpp"
#include "trivox/io/model_file.hpp"
#include "trivox/vmodel/boundary_mesh.hpp"

using namespace trivox;
namespace fs = std::filesystem;

namespace {

/// The box [0,2] x [0,3] x [0,4], r = x / 2, g = y / 3, b = 1 (exact at the corners); the
/// property "t" = z, not a colour.
vmodel::BoundaryMesh box_mesh() {
  std::vector<double> pts;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) pts.insert(pts.end(), {2.0 * i, 3.0 * j, 4.0 * k, double(i), double(j), 1.0, 4.0 * k});
  const spline::KnotVector kv(2, {0, 0, 1, 1});
  vmodel::VModel m;
  m.properties = {"r", "g", "b", "t"};
  m.cells.push_back({"box", spline::Trivariate({kv, kv, kv}, 7, pts)});
  return vmodel::mesh_boundary(m);
}

template <class T>
T get(const std::string& s, std::size_t at) {
  REQUIRE(at + sizeof(T) <= s.size());
  T v;
  std::memcpy(&v, s.data() + at, sizeof(T));
  return v;
}

std::array<std::uint8_t, 3> expected_colour(const std::array<double, 3>& p) {
  return {static_cast<std::uint8_t>(std::lround(p[0] / 2 * 255)), static_cast<std::uint8_t>(std::lround(p[1] / 3 * 255)),
          255};
}

}  // namespace

TEST_CASE("binary STL: 84-byte head, 50 bytes per facet, outward unit normals", "[mesh_file]") {
  const auto mesh = box_mesh();
  const std::string s = io::encode_mesh(mesh, io::MeshFormat::stl);
  REQUIRE(s.substr(0, 5) != "solid");
  const auto n = get<std::uint32_t>(s, 80);
  REQUIRE(n == mesh.triangles.size());
  REQUIRE(s.size() == 84 + 50 * std::size_t{n});
  double volume = 0;
  for (std::uint32_t t = 0; t < n; ++t) {
    const std::size_t at = 84 + 50 * std::size_t{t};
    float f[12];
    for (int k = 0; k < 12; ++k) f[k] = get<float>(s, at + 4 * k);
    REQUIRE(get<std::uint16_t>(s, at + 48) == 0);
    for (int k = 0; k < 3; ++k)
      for (int d = 0; d < 3; ++d) REQUIRE(f[3 + 3 * k + d] == static_cast<float>(mesh.vertices[mesh.triangles[t][k]][d]));
    REQUIRE(std::hypot(f[0], f[1], f[2]) == Approx(1.0));
    // Outward: the normal points away from the box's centre (1, 1.5, 2).
    const double cx = (f[3] + f[6] + f[9]) / 3 - 1, cy = (f[4] + f[7] + f[10]) / 3 - 1.5, cz = (f[5] + f[8] + f[11]) / 3 - 2;
    REQUIRE(f[0] * cx + f[1] * cy + f[2] * cz > 0);
    // Divergence theorem on the facets as read.
    volume += (f[3] * (f[7] * f[11] - f[8] * f[10]) - f[4] * (f[6] * f[11] - f[8] * f[9]) + f[5] * (f[6] * f[10] - f[7] * f[9])) / 6;
  }
  REQUIRE(volume == Approx(24.0));
}

TEST_CASE("PLY: binary little endian with uchar vertex colours", "[mesh_file]") {
  const auto mesh = box_mesh();
  const std::string s = io::encode_mesh(mesh, io::MeshFormat::ply);
  const std::size_t end = s.find("end_header\n");
  REQUIRE(end != std::string::npos);
  std::istringstream header(s.substr(0, end));
  std::vector<std::string> lines;
  for (std::string l; std::getline(header, l);) lines.push_back(l);
  const std::vector<std::string> expected = {"ply", "format binary_little_endian 1.0", "comment trivox boundary mesh: trivox",
                                             "element vertex 8", "property float x", "property float y", "property float z",
                                             "property uchar red", "property uchar green", "property uchar blue",
                                             "element face 12", "property list uchar int vertex_indices"};
  REQUIRE(lines == expected);
  std::size_t at = end + 11;
  for (std::size_t v = 0; v < 8; ++v) {
    std::array<double, 3> p{};
    for (int d = 0; d < 3; ++d) {
      p[d] = get<float>(s, at);
      REQUIRE(p[d] == static_cast<float>(mesh.vertices[v][d]));
      at += 4;
    }
    const auto c = expected_colour(p);
    for (int k = 0; k < 3; ++k) REQUIRE(get<std::uint8_t>(s, at++) == c[k]);
  }
  for (std::size_t t = 0; t < 12; ++t) {
    REQUIRE(get<std::uint8_t>(s, at++) == 3);
    for (int k = 0; k < 3; ++k, at += 4) REQUIRE(get<std::int32_t>(s, at) == mesh.triangles[t][k]);
  }
  REQUIRE(at == s.size());
}

TEST_CASE("OBJ: v x y z r g b and 1-based faces", "[mesh_file]") {
  const auto mesh = box_mesh();
  std::istringstream in(io::encode_mesh(mesh, io::MeshFormat::obj));
  std::vector<std::array<double, 6>> v;
  std::vector<std::array<int, 3>> f;
  for (std::string line; std::getline(in, line);) {
    std::istringstream l(line);
    std::string tag;
    l >> tag;
    if (tag == "v") {
      std::array<double, 6> x{};
      for (double& c : x) REQUIRE(l >> c);
      v.push_back(x);
    } else if (tag == "f") {
      std::array<int, 3> t{};
      for (int& i : t) REQUIRE(l >> i);
      f.push_back(t);
    } else {
      REQUIRE(tag == "#");
    }
  }
  REQUIRE(v.size() == 8);
  REQUIRE(f.size() == 12);
  for (std::size_t i = 0; i < 8; ++i) {
    const auto c = expected_colour(mesh.vertices[i]);
    for (int d = 0; d < 3; ++d) REQUIRE(v[i][d] == mesh.vertices[i][d]);
    for (int k = 0; k < 3; ++k) REQUIRE(v[i][3 + k] == Approx(c[k] / 255.0).margin(1e-6));
  }
  for (std::size_t t = 0; t < 12; ++t)
    for (int k = 0; k < 3; ++k) REQUIRE(f[t][k] == mesh.triangles[t][k] + 1);
}

TEST_CASE("mesh files: formats from names, atomic writes, refusals", "[mesh_file]") {
  REQUIRE(io::mesh_format_from_path("a/b.STL") == io::MeshFormat::stl);
  REQUIRE(io::mesh_format_from_path("b.3mf") == io::MeshFormat::threemf);
  REQUIRE_THROWS_WITH(io::mesh_format_from_path("b.txt"), Catch::Contains("b.txt") && Catch::Contains("expected .stl"));
  REQUIRE_FALSE(io::mesh_format_from_name("vrml"));

  const auto mesh = box_mesh();
  const fs::path dir = fs::temp_directory_path() / ("trivox_mesh_file_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  for (auto f : {io::MeshFormat::stl, io::MeshFormat::ply, io::MeshFormat::obj, io::MeshFormat::threemf}) {
    const fs::path p = dir / (std::string("box.") + io::mesh_format_name(f));
    io::write_mesh(p, mesh, f);
    const std::string bytes = io::read_file(p);
    if (f != io::MeshFormat::threemf) REQUIRE(bytes == io::encode_mesh(mesh, f));
    else REQUIRE(bytes.substr(0, 2) == "PK");  // a zip; its content is read in tests/cli/mesh.sh
    // The same mesh gives the same bytes (3MF included: no random UUIDs).
    REQUIRE(io::encode_mesh(mesh, f) == io::encode_mesh(mesh, f));
  }
  // Only the four files: no temporary left behind.
  REQUIRE(std::distance(fs::directory_iterator(dir), fs::directory_iterator()) == 4);
  REQUIRE_THROWS_AS(io::write_mesh(dir / "missing" / "x.stl", mesh, io::MeshFormat::stl), Error);
  io::MeshWriteOptions parsec;
  parsec.units = "parsec";
  REQUIRE_THROWS_WITH(io::encode_mesh(mesh, io::MeshFormat::threemf, parsec), Catch::Contains("expected one of um, mm"));
  fs::remove_all(dir);
}
