#include "trivox/io/vdb_inspect.hpp"

#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <system_error>

#include "trivox/error.hpp"
#include "trivox/io/model_file.hpp"
#include "trivox/io/png_image.hpp"

namespace trivox::io {

namespace fs = std::filesystem;

namespace {

constexpr const char* expected_vdb = "expected an OpenVDB file (.vdb)";

/// The file's bytes, with messages for a missing, folder or unreadable path.
std::string read_vdb_bytes(const fs::path& path) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (!fs::exists(st)) throw Error(path.string() + ": no such file; " + expected_vdb);
  if (fs::is_directory(st)) throw Error(path.string() + ": is a folder; " + expected_vdb);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string() + ": cannot open (" + std::strerror(errno) + "); " + expected_vdb);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  if (in.bad()) throw Error(path.string() + ": read error; " + expected_vdb);
  return std::move(bytes).str();
}

bool has_magic(std::string_view bytes) {
  if (bytes.size() < 8) return false;
  std::int64_t magic = 0;
  std::memcpy(&magic, bytes.data(), 8);
  return magic == static_cast<std::int64_t>(openvdb::OPENVDB_MAGIC);
}

/// Every grid and the file metadata, read from memory with stream exceptions on, so a truncated
/// or corrupt file ends in an exception, never in a read past the end.
struct Loaded {
  openvdb::GridPtrVec grids;
  openvdb::MetaMap::Ptr meta;
  std::string format;
  std::int64_t bytes = 0;
};

Loaded load(const fs::path& path) {
  std::string bytes = read_vdb_bytes(path);
  if (!has_magic(bytes))
    throw Error(path.string() + ": " + (bytes.empty() ? std::string("empty file") : "no OpenVDB magic number at the start") +
                "; " + expected_vdb);
  openvdb::initialize();
  Loaded l;
  l.bytes = static_cast<std::int64_t>(bytes.size());
  try {
    std::istringstream is(std::move(bytes), std::ios::binary);
    is.exceptions(std::ios::failbit | std::ios::badbit);
    openvdb::io::Stream stream(is, /*delayLoad=*/false);
    auto grids = stream.getGrids();
    if (!grids) throw std::runtime_error("no grids could be read");
    l.grids = *grids;
    l.meta = stream.getMetadata();
    for (const auto& g : l.grids)
      if (!g) throw std::runtime_error("a grid could not be read");
    l.format = std::to_string(stream.libraryVersion().first) + "." + std::to_string(stream.libraryVersion().second) + "/" +
               std::to_string(stream.fileVersion());
  } catch (const std::ios_base::failure&) {
    throw Error(path.string() + ": truncated or corrupt: the data ends early; " + expected_vdb);
  } catch (const std::bad_alloc&) {
    throw Error(path.string() + ": corrupt: sizes in the file are impossible; " + expected_vdb);
  } catch (const std::exception& e) {
    throw Error(path.string() + ": corrupt: " + e.what() + "; " + expected_vdb);
  }
  return l;
}

std::vector<VdbMeta> metadata_of(const openvdb::MetaMap& m, bool skip_standard) {
  std::vector<VdbMeta> out;
  for (auto it = m.beginMeta(); it != m.endMeta(); ++it) {
    const std::string& name = it->first;
    if (skip_standard && (name.rfind("file_", 0) == 0 || name == openvdb::GridBase::META_GRID_NAME ||
                          name == openvdb::GridBase::META_GRID_CLASS))
      continue;
    VdbMeta v;
    v.name = name;
    v.type = it->second->typeName();
    v.value = it->second->str();
    v.numeric = v.type == "bool" || v.type == "int32" || v.type == "int64" || v.type == "float" || v.type == "double";
    out.push_back(std::move(v));
  }
  return out;
}

/// Range and mean of the active values (tiles weighted by their voxel counts).
struct Stats {
  VdbGridInfo* info;
  template <class GridT>
  void operator()(const GridT& grid) const {
    using V = typename GridT::ValueType;
    constexpr int n = openvdb::VecTraits<V>::Size;
    info->components = n;
    info->min.assign(n, std::numeric_limits<double>::infinity());
    info->max.assign(n, -std::numeric_limits<double>::infinity());
    std::vector<double> sum(n, 0.0);
    double count = 0;
    for (auto it = grid.cbeginValueOn(); it; ++it) {
      const double c = static_cast<double>(it.getVoxelCount());
      const V v = *it;
      for (int q = 0; q < n; ++q) {
        double x;
        if constexpr (openvdb::VecTraits<V>::IsVec) x = static_cast<double>(v[q]);
        else x = static_cast<double>(v);
        info->min[static_cast<std::size_t>(q)] = std::min(info->min[static_cast<std::size_t>(q)], x);
        info->max[static_cast<std::size_t>(q)] = std::max(info->max[static_cast<std::size_t>(q)], x);
        sum[static_cast<std::size_t>(q)] += x * c;
      }
      count += c;
    }
    info->mean.resize(n);
    for (int q = 0; q < n; ++q) info->mean[static_cast<std::size_t>(q)] = count > 0 ? sum[static_cast<std::size_t>(q)] / count : 0.0;
    if (count == 0) info->min.clear(), info->max.clear(), info->mean.clear();
  }
};

using SummarisedGrids = openvdb::TypeList<openvdb::FloatGrid, openvdb::DoubleGrid, openvdb::Int32Grid,
                                          openvdb::Int64Grid, openvdb::Vec3SGrid, openvdb::Vec3DGrid, openvdb::Vec3IGrid>;

VdbGridInfo grid_info(const openvdb::GridBase& g) {
  VdbGridInfo info;
  info.name = g.getName();
  info.type = g.valueType();
  info.grid_class = openvdb::GridBase::gridClassToString(g.getGridClass());
  const auto vs = g.transform().voxelSize();
  info.voxel_size = {vs[0], vs[1], vs[2]};
  info.active_voxels = static_cast<std::int64_t>(g.activeVoxelCount());
  const openvdb::CoordBBox box = g.evalActiveVoxelBoundingBox();
  info.empty = info.active_voxels == 0 || box.empty();
  if (!info.empty) {
    const auto wb = g.transform().indexToWorld(
        openvdb::BBoxd(box.min().asVec3d() - openvdb::Vec3d(0.5), box.max().asVec3d() + openvdb::Vec3d(0.5)));
    for (int d = 0; d < 3; ++d) {
      info.index_bounds[0][static_cast<std::size_t>(d)] = box.min()[d];
      info.index_bounds[1][static_cast<std::size_t>(d)] = box.max()[d];
      info.world_bounds[0][static_cast<std::size_t>(d)] = wb.min()[d];
      info.world_bounds[1][static_cast<std::size_t>(d)] = wb.max()[d];
    }
    g.apply<SummarisedGrids>(Stats{&info});
  }
  info.metadata = metadata_of(g, true);
  return info;
}

/// sum(fraction x density) over the fraction grid's active values, density looked up at the
/// same index (both grids share the transform).
double weighted_sum(const openvdb::FloatGrid& fraction, const openvdb::FloatGrid& density) {
  auto acc = density.getConstAccessor();
  double s = 0.0;
  for (auto it = fraction.cbeginValueOn(); it; ++it) {
    if (it.isVoxelValue()) {
      s += static_cast<double>(*it) * static_cast<double>(acc.getValue(it.getCoord()));
      continue;
    }
    // An active tile: exact when density is constant over it (a tile at least as coarse), else
    // voxel by voxel.
    openvdb::CoordBBox b;
    it.getBoundingBox(b);
    const int depth = acc.getValueDepth(b.min());
    const int tile_depth = static_cast<int>(openvdb::FloatTree::DEPTH) - 1 - static_cast<int>(it.getLevel());
    if (depth >= 0 && depth <= tile_depth) {
      s += static_cast<double>(*it) * static_cast<double>(acc.getValue(b.min())) * static_cast<double>(b.volume());
    } else {
      for (auto c = b.begin(); c; ++c) s += static_cast<double>(*it) * static_cast<double>(acc.getValue(*c));
    }
  }
  return s;
}

openvdb::FloatGrid::ConstPtr find_float(const openvdb::GridPtrVec& grids, const std::string& name) {
  for (const auto& g : grids)
    if (g->getName() == name)
      if (auto f = openvdb::GridBase::constGrid<openvdb::FloatGrid>(g)) return f;
  return nullptr;
}

}  // namespace

bool looks_like_vdb(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  char head[8];
  if (!in.read(head, 8)) return false;
  return has_magic(std::string_view(head, 8));
}

VdbReport inspect_vdb(const fs::path& path) {
  const Loaded l = load(path);
  VdbReport r;
  r.path = path.string();
  r.bytes = l.bytes;
  r.format = l.format;
  if (l.meta) {
    r.metadata = metadata_of(*l.meta, false);
    if (auto u = l.meta->getMetadata<openvdb::StringMetadata>("units")) r.units = u->value();
    if (r.units == "mm") r.mm_per_unit = 1.0;
    if (r.units == "m") r.mm_per_unit = 1000.0;
  }
  for (const auto& g : l.grids) r.grids.push_back(grid_info(*g));
  if (auto density = find_float(l.grids, "density")) {
    const double voxel_volume = density->transform().voxelVolume();
    double s = 0.0;
    for (auto it = density->cbeginValueOn(); it; ++it)
      s += static_cast<double>(*it) * static_cast<double>(it.getVoxelCount());
    r.volume = s * voxel_volume;
    for (const auto& g : l.grids) {
      const std::string& name = g->getName();
      if (name.rfind("material.", 0) != 0) continue;
      auto f = openvdb::GridBase::constGrid<openvdb::FloatGrid>(g);
      if (!f || !(f->transform() == density->transform())) continue;
      r.materials.push_back({name.substr(9), weighted_sum(*f, *density) * voxel_volume});
    }
  }
  return r;
}

// ---- render ----

namespace {

using Vec3 = openvdb::Vec3d;

struct View {
  Vec3 right, up, dir;  // dir: the direction the rays travel (from the viewer into the scene)
};

View parse_view(const std::string& v) {
  const Vec3 x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
  if (v == "+z") return {x, y, -z};
  if (v == "-z") return {x, -y, z};
  if (v == "+x") return {y, z, -x};
  if (v == "-x") return {-y, z, x};
  if (v == "+y") return {-x, z, -y};
  if (v == "-y") return {x, z, y};
  if (v == "iso") {
    const Vec3 from = Vec3(1, -1, 1).unit();
    Vec3 up = z - from * z.dot(from);
    up.normalize();
    const Vec3 right = up.cross(from);
    return {right, up, -from};
  }
  throw Error("--view " + v + ": unknown view; expected +z, -z, +x, -x, +y, -y or iso");
}

/// Trilinear interpolation at index point p of the active values only: returns false when no
/// corner is active; `out` is the weighted mean of the active corners.
template <class Acc, class V>
bool active_trilinear(const Acc& acc, const Vec3& p, V& out) {
  const openvdb::Coord c0(static_cast<int>(std::floor(p[0])), static_cast<int>(std::floor(p[1])),
                          static_cast<int>(std::floor(p[2])));
  const Vec3 f = p - c0.asVec3d();
  double wsum = 0.0;
  V acc_v = openvdb::zeroVal<V>();
  for (int corner = 0; corner < 8; ++corner) {
    const int dx = corner & 1, dy = (corner >> 1) & 1, dz = corner >> 2;
    const double w = (dx ? f[0] : 1 - f[0]) * (dy ? f[1] : 1 - f[1]) * (dz ? f[2] : 1 - f[2]);
    if (w <= 0.0) continue;
    V v;
    if (!acc.probeValue(c0.offsetBy(dx, dy, dz), v)) continue;
    acc_v = acc_v + v * static_cast<typename openvdb::VecTraits<V>::ElementType>(w);
    wsum += w;
  }
  if (wsum <= 0.0) return false;
  out = acc_v * static_cast<typename openvdb::VecTraits<V>::ElementType>(1.0 / wsum);
  return true;
}

/// Plain trilinear density (inactive voxels hold the background, 0 for fog volumes).
template <class Acc>
double trilinear(const Acc& acc, const Vec3& p) {
  const openvdb::Coord c0(static_cast<int>(std::floor(p[0])), static_cast<int>(std::floor(p[1])),
                          static_cast<int>(std::floor(p[2])));
  // Empty space: no leaf and an inactive zero at the base corner, and all corners in that node.
  const bool inside_leaf = (c0[0] & 7) != 7 && (c0[1] & 7) != 7 && (c0[2] & 7) != 7;
  if (inside_leaf && !acc.probeConstLeaf(c0) && acc.getValue(c0) == 0.0f) return 0.0;
  const Vec3 f = p - c0.asVec3d();
  double s = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const int dx = corner & 1, dy = (corner >> 1) & 1, dz = corner >> 2;
    const double w = (dx ? f[0] : 1 - f[0]) * (dy ? f[1] : 1 - f[1]) * (dz ? f[2] : 1 - f[2]);
    if (w > 0.0) s += w * static_cast<double>(acc.getValue(c0.offsetBy(dx, dy, dz)));
  }
  return s;
}

/// Clips the ray o + t d (index space) to the box [lo, hi]; false when it misses.
bool clip(const Vec3& o, const Vec3& d, const Vec3& lo, const Vec3& hi, double& t0, double& t1) {
  for (int a = 0; a < 3; ++a) {
    if (std::abs(d[a]) < 1e-300) {
      if (o[a] < lo[a] || o[a] > hi[a]) return false;
      continue;
    }
    double ta = (lo[a] - o[a]) / d[a], tb = (hi[a] - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return t0 <= t1;
}

}  // namespace

RenderSummary render_vdb(const fs::path& vdb, const fs::path& png, const RenderOptions& opt) {
  const View view = parse_view(opt.view);
  if ((opt.width != 0 || opt.height != 0) &&
      (opt.width < 16 || opt.width > 16384 || opt.height < 16 || opt.height > 16384))
    throw Error("--size " + std::to_string(opt.width) + "," + std::to_string(opt.height) +
                ": out of range; expected a width and height of 16 to 16384 pixels");
  std::error_code ec;
  if (fs::is_directory(png, ec)) throw Error(png.string() + ": is a folder; expected a PNG file name to write");
  if (fs::exists(png, ec) && !opt.force)
    throw Error(png.string() + ": exists; expected a new file name (or --force to replace it)");
  if (!png.parent_path().empty() && !fs::is_directory(png.parent_path(), ec))
    throw Error(png.string() + ": the folder " + png.parent_path().string() + " does not exist; expected a writable folder");

  const Loaded l = load(vdb);
  // The grids: density (else the first fog volume, else the first float grid) and colour.
  openvdb::FloatGrid::ConstPtr density = find_float(l.grids, "density");
  for (int pass = 0; pass < 2 && !density; ++pass)
    for (const auto& g : l.grids)
      if (auto f = openvdb::GridBase::constGrid<openvdb::FloatGrid>(g))
        if (pass == 1 || f->getGridClass() == openvdb::GRID_FOG_VOLUME) {
          density = f;
          break;
        }
  if (!density)
    throw Error(vdb.string() + ": no float grid to draw; expected a float grid \"density\" (or a fog volume)");
  openvdb::Vec3SGrid::ConstPtr color;
  for (const char* name : {"color", "Cd"})
    for (const auto& g : l.grids)
      if (!color && g->getName() == name) color = openvdb::GridBase::constGrid<openvdb::Vec3SGrid>(g);
  for (const auto& g : l.grids)
    if (!color) color = openvdb::GridBase::constGrid<openvdb::Vec3SGrid>(g);
  const auto& xf = density->transform();
  if (!xf.isLinear() || (color && !color->transform().isLinear()))
    throw Error(vdb.string() + ": a grid with a non-linear (frustum) transform; expected linear transforms");

  RenderSummary sum;
  sum.view = opt.view;
  sum.density_grid = density->getName();
  sum.color_grid = color ? color->getName() : "";

  // World box of the active voxels, projected on the view's axes.
  const openvdb::CoordBBox ibox = density->evalActiveVoxelBoundingBox();
  const bool empty = density->activeVoxelCount() == 0 || ibox.empty();
  const Vec3 ilo = empty ? Vec3(0) : ibox.min().asVec3d() - Vec3(0.5), ihi = empty ? Vec3(1) : ibox.max().asVec3d() + Vec3(0.5);
  double u0 = 1e300, u1 = -1e300, v0 = 1e300, v1 = -1e300, d0 = 1e300, d1 = -1e300;
  for (int c = 0; c < 8; ++c) {
    const Vec3 ip((c & 1) ? ihi[0] : ilo[0], (c & 2) ? ihi[1] : ilo[1], (c & 4) ? ihi[2] : ilo[2]);
    const Vec3 w = xf.indexToWorld(ip);
    u0 = std::min(u0, w.dot(view.right)), u1 = std::max(u1, w.dot(view.right));
    v0 = std::min(v0, w.dot(view.up)), v1 = std::max(v1, w.dot(view.up));
    d0 = std::min(d0, w.dot(view.dir)), d1 = std::max(d1, w.dot(view.dir));
  }
  const double margin = 0.04 * std::max(u1 - u0, v1 - v0);
  u0 -= margin, u1 += margin, v0 -= margin, v1 += margin;
  int W = opt.width, H = opt.height;
  if (W == 0) {
    const double aspect = (u1 - u0) / (v1 - v0);
    if (aspect >= 1) W = 800, H = std::clamp(static_cast<int>(std::lround(800 / aspect)), 16, 800);
    else H = 800, W = std::clamp(static_cast<int>(std::lround(800 * aspect)), 16, 800);
  }
  sum.width = W, sum.height = H;
  const double pixel = std::max((u1 - u0) / W, (v1 - v0) / H);
  const double uc = 0.5 * (u0 + u1), vc = 0.5 * (v0 + v1);
  const Vec3 vs = xf.voxelSize();
  const double voxel = std::min({vs[0], vs[1], vs[2]});
  const double step = 0.5 * voxel;

  // Rays in the density grid's index space (linear transform: affine), and in the colour's.
  const Vec3 world_dir = view.dir;
  const Vec3 idir = xf.worldToIndex(world_dir) - xf.worldToIndex(Vec3(0));
  const bool same_xf = color && color->transform() == xf;
  const Vec3 cdir = color ? color->transform().worldToIndex(world_dir) - color->transform().worldToIndex(Vec3(0)) : Vec3(0);
  const Vec3 light = (-view.dir + 0.5 * view.up - 0.35 * view.right).unit();
  const double bg[3] = {opt.background[0] / 255.0, opt.background[1] / 255.0, opt.background[2] / 255.0};
  const bool transparent = opt.background[3] == 0;

  std::vector<std::uint8_t> rgba(static_cast<std::size_t>(W) * static_cast<std::size_t>(H) * 4);
  std::vector<std::int64_t> covered(static_cast<std::size_t>(H), 0);
  const openvdb::Vec3STree no_color;
  const openvdb::Vec3STree& ctree = color ? color->tree() : no_color;
  tbb::parallel_for(0, H, [&](int y) {
    auto dacc = density->getConstAccessor();
    openvdb::tree::ValueAccessor<const openvdb::Vec3STree> cacc(ctree);
    const auto& map = *xf.baseMap();
    for (int x = 0; x < W; ++x) {
      const double u = uc + (x + 0.5 - 0.5 * W) * pixel, v = vc - (y + 0.5 - 0.5 * H) * pixel;
      const Vec3 start = view.right * u + view.up * v + view.dir * (d0 - voxel);
      const Vec3 io = xf.worldToIndex(start);
      double acc_rgb[3] = {0, 0, 0};
      double T = 1.0;  // transmittance
      double t0 = 0.0, t1 = (d1 - d0) + 2 * voxel;
      if (!empty && clip(io, idir, ilo - Vec3(1.0), ihi + Vec3(1.0), t0, t1)) {
        const Vec3 co = color ? color->transform().worldToIndex(start) : Vec3(0);
        // Steps on a lattice fixed by the ray (t = n step), so clipping does not shift them.
        for (double t = std::ceil(t0 / step) * step; t <= t1 && T > 0.002; t += step) {
          const Vec3 p = io + idir * t;
          const double d = std::clamp(trilinear(dacc, p), 0.0, 1.0);
          if (d <= 0.0) continue;
          const double a = 1.0 - std::exp(-d * step / voxel);
          openvdb::Vec3s c(0.8f);
          if (color) {
            openvdb::Vec3s cv;
            if (active_trilinear(cacc, same_xf ? p : co + cdir * t, cv)) c = cv;
          }
          // Head light through the density gradient (central differences, world space).
          Vec3 g(trilinear(dacc, p + Vec3(0.5, 0, 0)) - trilinear(dacc, p - Vec3(0.5, 0, 0)),
                 trilinear(dacc, p + Vec3(0, 0.5, 0)) - trilinear(dacc, p - Vec3(0, 0.5, 0)),
                 trilinear(dacc, p + Vec3(0, 0, 0.5)) - trilinear(dacc, p - Vec3(0, 0, 0.5)));
          g = map.applyIJT(g);
          double shade = 1.0;
          const double gl = g.length();
          if (gl > 1e-9) shade = 0.3 + 0.7 * std::max(0.0, -g.dot(light) / gl);
          for (int q = 0; q < 3; ++q) acc_rgb[q] += T * a * shade * std::clamp(static_cast<double>(c[q]), 0.0, 1.0);
          T *= 1.0 - a;
        }
      }
      std::uint8_t* px = rgba.data() + (static_cast<std::size_t>(y) * static_cast<std::size_t>(W) + static_cast<std::size_t>(x)) * 4;
      const double alpha = 1.0 - T;
      if (alpha > 0.01) ++covered[static_cast<std::size_t>(y)];
      for (int q = 0; q < 3; ++q) {
        const double value = transparent ? (alpha > 0 ? acc_rgb[q] / alpha : 0.0) : acc_rgb[q] + T * bg[q];
        px[q] = static_cast<std::uint8_t>(std::lround(255.0 * std::clamp(value, 0.0, 1.0)));
      }
      px[3] = transparent ? static_cast<std::uint8_t>(std::lround(255.0 * std::clamp(alpha, 0.0, 1.0))) : 255;
    }
  });
  for (auto c : covered) sum.covered_pixels += c;
  write_file_atomically(png, encode_png_rgba(rgba.data(), W, H, 72.0, 72.0, 6));
  return sum;
}

}  // namespace trivox::io
