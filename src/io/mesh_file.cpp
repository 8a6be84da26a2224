#include "trivox/io/mesh_file.hpp"

#include <Model/COM/NMR_DLLInterfaces.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <vector>

#include "trivox/error.hpp"
#include "trivox/io/model_file.hpp"
#include "trivox/io/sha256.hpp"

namespace trivox::io {

namespace {

static_assert(std::endian::native == std::endian::little, "the binary writers assume a little-endian machine");

using vmodel::BoundaryMesh;

template <class T>
void put(std::string& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out.append(bytes, sizeof(T));
}

/// One line without control characters, for headers and comments.
std::string one_line(const std::string& s) {
  std::string out;
  for (char c : s) out.push_back(static_cast<unsigned char>(c) < 0x20 || c == 0x7f ? '_' : c);
  return out;
}

void check_counts(const BoundaryMesh& mesh) {
  constexpr auto most = static_cast<std::size_t>(std::numeric_limits<std::uint32_t>::max());
  if (mesh.vertices.size() > most || mesh.triangles.size() > most)
    throw Error("mesh: " + std::to_string(mesh.vertices.size()) + " vertices, " + std::to_string(mesh.triangles.size()) +
                " triangles; expected at most 4294967295 of each");
}

std::string encode_stl(const BoundaryMesh& mesh, const MeshWriteOptions& options) {
  std::string out;
  out.reserve(84 + mesh.triangles.size() * 50);
  std::string header = "binary STL from trivox: " + one_line(options.name);
  header.resize(80, ' ');
  out += header;
  put(out, static_cast<std::uint32_t>(mesh.triangles.size()));
  for (const auto& t : mesh.triangles) {
    std::array<std::array<float, 3>, 3> p{};
    for (std::size_t k = 0; k < 3; ++k)
      for (std::size_t d = 0; d < 3; ++d) p[k][d] = static_cast<float>(mesh.vertices[static_cast<std::size_t>(t[k])][d]);
    const auto& a = mesh.vertices[static_cast<std::size_t>(t[0])];
    const auto& b = mesh.vertices[static_cast<std::size_t>(t[1])];
    const auto& c = mesh.vertices[static_cast<std::size_t>(t[2])];
    const double ux = b[0] - a[0], uy = b[1] - a[1], uz = b[2] - a[2];
    const double vx = c[0] - a[0], vy = c[1] - a[1], vz = c[2] - a[2];
    double n[3] = {uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (double& x : n) x = len > 0.0 ? x / len : 0.0;
    for (double x : n) put(out, static_cast<float>(x));
    for (const auto& q : p)
      for (float x : q) put(out, x);
    put(out, std::uint16_t{0});
  }
  return out;
}

std::string encode_ply(const BoundaryMesh& mesh, const MeshWriteOptions& options) {
  const auto rgb = options.colour ? vmodel::colour_properties(mesh.property_names) : std::nullopt;
  std::string out = "ply\nformat binary_little_endian 1.0\ncomment trivox boundary mesh: " + one_line(options.name) +
                    "\nelement vertex " + std::to_string(mesh.vertices.size()) +
                    "\nproperty float x\nproperty float y\nproperty float z\n";
  if (rgb) out += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  out += "element face " + std::to_string(mesh.triangles.size()) + "\nproperty list uchar int vertex_indices\nend_header\n";
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    for (double x : mesh.vertices[v]) put(out, static_cast<float>(x));
    if (rgb)
      for (std::uint8_t c : vmodel::vertex_colour(mesh, v, *rgb)) put(out, c);
  }
  for (const auto& t : mesh.triangles) {
    put(out, std::uint8_t{3});
    for (int i : t) put(out, static_cast<std::int32_t>(i));
  }
  return out;
}

std::string encode_obj(const BoundaryMesh& mesh, const MeshWriteOptions& options) {
  const auto rgb = options.colour ? vmodel::colour_properties(mesh.property_names) : std::nullopt;
  std::string out = "# trivox boundary mesh: " + one_line(options.name) + "\n# " + std::to_string(mesh.vertices.size()) +
                    " vertices, " + std::to_string(mesh.triangles.size()) + " triangles" +
                    (rgb ? ", vertex colours r g b in 0..1" : "") + "\n";
  char line[160];
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    const auto& p = mesh.vertices[v];
    int n = std::snprintf(line, sizeof line, "v %.9g %.9g %.9g", p[0], p[1], p[2]);
    out.append(line, static_cast<std::size_t>(n));
    if (rgb) {
      const auto c = vmodel::vertex_colour(mesh, v, *rgb);
      n = std::snprintf(line, sizeof line, " %.6g %.6g %.6g", c[0] / 255.0, c[1] / 255.0, c[2] / 255.0);
      out.append(line, static_cast<std::size_t>(n));
    }
    out += '\n';
  }
  for (const auto& t : mesh.triangles) {
    const int n = std::snprintf(line, sizeof line, "f %d %d %d\n", t[0] + 1, t[1] + 1, t[2] + 1);
    out.append(line, static_cast<std::size_t>(n));
  }
  return out;
}

// --- 3MF through lib3mf's C interface -------------------------------------------------------

/// Releases a lib3mf handle at scope exit.
struct Handle {
  NMR::PLib3MFBase* p = nullptr;
  Handle() = default;
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle() {
    if (p) NMR::lib3mf_release(p);
  }
};

void check3mf(LIB3MFRESULT r, NMR::PLib3MFBase* instance, const char* what) {
  if (r == LIB3MF_OK) return;
  std::string message;
  if (instance) {
    DWORD code = 0;
    LPCSTR text = nullptr;
    if (NMR::lib3mf_getlasterror(instance, &code, &text) == LIB3MF_OK && text) message = text;
  }
  char hex[32];
  std::snprintf(hex, sizeof hex, "0x%08x", static_cast<unsigned>(r));
  throw Error(std::string("3MF: lib3mf ") + what + " failed (" + hex + (message.empty() ? "" : ": " + message) + ")",
              ErrorKind::failed);
}

struct Sink {
  std::string data;
  std::size_t pos = 0;
};

// lib3mf's callback stream: 0 is success.
unsigned sink_write(unsigned char* bytes, unsigned count, void* user) {
  auto* s = static_cast<Sink*>(user);
  if (s->pos + count > s->data.size()) s->data.resize(s->pos + count);
  std::memcpy(s->data.data() + s->pos, bytes, count);
  s->pos += count;
  return 0;
}

unsigned sink_seek(unsigned long long position, void* user) {
  auto* s = static_cast<Sink*>(user);
  if (position > s->data.size()) s->data.resize(static_cast<std::size_t>(position));
  s->pos = static_cast<std::size_t>(position);
  return 0;
}

DWORD unit_3mf(const std::string& units) {
  if (units == "um") return NMR::MODELUNIT_MICROMETER;
  if (units == "mm") return NMR::MODELUNIT_MILLIMETER;
  if (units == "cm") return NMR::MODELUNIT_CENTIMETER;
  if (units == "m") return NMR::MODELUNIT_METER;
  if (units == "in") return NMR::MODELUNIT_INCH;
  if (units == "ft") return NMR::MODELUNIT_FOOT;
  throw Error("3MF: units \"" + one_line(units) + "\"; expected one of um, mm, cm, m, in, ft");
}

/// A UUID (RFC 9562 version 8: custom) from the SHA-256 of the mesh and the role: lib3mf would
/// draw random ones, and the same mesh must give the same file.
std::string content_uuid(const BoundaryMesh& mesh, const MeshWriteOptions& options, char role) {
  std::string data(1, role);
  data += options.name + '\0' + options.units + '\0';
  data.append(reinterpret_cast<const char*>(mesh.vertices.data()), mesh.vertices.size() * sizeof(mesh.vertices[0]));
  data.append(reinterpret_cast<const char*>(mesh.triangles.data()), mesh.triangles.size() * sizeof(mesh.triangles[0]));
  data.append(reinterpret_cast<const char*>(mesh.properties.data()), mesh.properties.size() * sizeof(double));
  std::string h = sha256_hex(data).substr(0, 32);
  h[12] = '8';                                              // version
  h[16] = "89ab"[std::stoi(h.substr(16, 1), nullptr, 16) & 3];  // variant 10
  return h.substr(0, 8) + '-' + h.substr(8, 4) + '-' + h.substr(12, 4) + '-' + h.substr(16, 4) + '-' + h.substr(20, 12);
}

std::string encode_3mf(const BoundaryMesh& mesh, const MeshWriteOptions& options) {
  const DWORD unit = unit_3mf(options.units);
  Handle model, object, handler, item, writer;
  check3mf(NMR::lib3mf_createmodel(&model.p), nullptr, "createmodel");
  check3mf(NMR::lib3mf_model_setunit(model.p, unit), model.p, "setunit");
  check3mf(NMR::lib3mf_model_addmeshobject(model.p, &object.p), model.p, "addmeshobject");
  check3mf(NMR::lib3mf_object_setnameutf8(object.p, one_line(options.name).c_str()), object.p, "setname");
  std::vector<NMR::MODELMESHVERTEX> vertices(mesh.vertices.size());
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
    for (std::size_t d = 0; d < 3; ++d) vertices[v].m_fPosition[d] = static_cast<float>(mesh.vertices[v][d]);
  std::vector<NMR::MODELMESHTRIANGLE> triangles(mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (std::size_t k = 0; k < 3; ++k) triangles[t].m_nIndices[k] = static_cast<DWORD>(mesh.triangles[t][k]);
  check3mf(NMR::lib3mf_meshobject_setgeometry(object.p, vertices.data(), static_cast<DWORD>(vertices.size()),
                                              triangles.data(), static_cast<DWORD>(triangles.size())),
           object.p, "setgeometry");
  const auto rgb = options.colour ? vmodel::colour_properties(mesh.property_names) : std::nullopt;
  if (rgb && !mesh.vertices.empty()) {
    auto srgb = [&](std::size_t v) {
      const auto c = vmodel::vertex_colour(mesh, v, *rgb);
      return NMR::MODELMESHCOLOR_SRGB{c[0], c[1], c[2], 255};
    };
    check3mf(NMR::lib3mf_meshobject_createpropertyhandler(object.p, &handler.p), object.p, "createpropertyhandler");
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      NMR::MODELMESH_TRIANGLECOLOR_SRGB colours{};
      for (std::size_t k = 0; k < 3; ++k) colours.m_Colors[k] = srgb(static_cast<std::size_t>(mesh.triangles[t][k]));
      check3mf(NMR::lib3mf_propertyhandler_setgradientcolor(handler.p, static_cast<DWORD>(t), &colours), handler.p,
               "setgradientcolor");
    }
    // The materials extension asks for an object-level default when triangles carry properties.
    Handle fallback;
    check3mf(NMR::lib3mf_object_createdefaultpropertyhandler(object.p, &fallback.p), object.p,
             "createdefaultpropertyhandler");
    const auto c0 = srgb(0);
    check3mf(NMR::lib3mf_defaultpropertyhandler_setcolorrgb(fallback.p, c0.m_Red, c0.m_Green, c0.m_Blue), fallback.p,
             "setcolorrgb");
  }
  check3mf(NMR::lib3mf_model_addbuilditem(model.p, object.p, nullptr, &item.p), model.p, "addbuilditem");
  check3mf(NMR::lib3mf_object_setuuidutf8(object.p, content_uuid(mesh, options, 'o').c_str()), object.p, "setuuid");
  check3mf(NMR::lib3mf_builditem_setuuidutf8(item.p, content_uuid(mesh, options, 'i').c_str()), item.p, "setuuid");
  check3mf(NMR::lib3mf_model_setbuilduuidutf8(model.p, content_uuid(mesh, options, 'b').c_str()), model.p, "setuuid");
  check3mf(NMR::lib3mf_model_querywriter(model.p, "3mf", &writer.p), model.p, "querywriter");
  Sink sink;
  check3mf(NMR::lib3mf_writer_writetocallback(writer.p, reinterpret_cast<void*>(&sink_write),
                                              reinterpret_cast<void*>(&sink_seek), &sink),
           writer.p, "write");
  return std::move(sink.data);
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

const char* mesh_format_name(MeshFormat f) noexcept {
  switch (f) {
    case MeshFormat::stl: return "stl";
    case MeshFormat::ply: return "ply";
    case MeshFormat::obj: return "obj";
    case MeshFormat::threemf: return "3mf";
  }
  return "?";
}

std::optional<MeshFormat> mesh_format_from_name(std::string_view name) noexcept {
  for (MeshFormat f : {MeshFormat::stl, MeshFormat::ply, MeshFormat::obj, MeshFormat::threemf})
    if (name == mesh_format_name(f)) return f;
  return std::nullopt;
}

MeshFormat mesh_format_from_path(const std::filesystem::path& path) {
  const std::string ext = lower(path.extension().string());
  if (ext.size() > 1)
    if (auto f = mesh_format_from_name(std::string_view(ext).substr(1))) return *f;
  throw Error(path.string() + ": extension \"" + path.extension().string() +
              "\"; expected .stl, .ply, .obj or .3mf (or give the format with --format)");
}

std::string encode_mesh(const BoundaryMesh& mesh, MeshFormat format, const MeshWriteOptions& options) {
  check_counts(mesh);
  switch (format) {
    case MeshFormat::stl: return encode_stl(mesh, options);
    case MeshFormat::ply: return encode_ply(mesh, options);
    case MeshFormat::obj: return encode_obj(mesh, options);
    case MeshFormat::threemf: return encode_3mf(mesh, options);
  }
  throw Error("mesh: unknown format", ErrorKind::failed);
}

void write_mesh(const std::filesystem::path& path, const BoundaryMesh& mesh, MeshFormat format,
                const MeshWriteOptions& options) {
  std::string bytes;
  try {
    bytes = encode_mesh(mesh, format, options);
  } catch (const Error& e) {
    throw e.within(path.string());
  }
  write_file_atomically(path, bytes);
}

}  // namespace trivox::io
