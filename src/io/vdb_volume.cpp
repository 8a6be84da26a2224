#include "trivox/io/vdb_volume.hpp"

#include <openvdb/io/Archive.h>
#include <openvdb/openvdb.h>

#include <algorithm>
#include <ostream>
#include <type_traits>

#include "trivox/error.hpp"
#include "vdb_file.hpp"

namespace trivox::io {

namespace {

using FloatLeaf = openvdb::FloatTree::LeafNodeType;
using Vec3Leaf = openvdb::Vec3STree::LeafNodeType;
using LeafMask = FloatLeaf::NodeMaskType;

static_assert(FloatLeaf::DIM == vdb_leaf_dim && FloatLeaf::SIZE == vdb_leaf_voxels && Vec3Leaf::SIZE == vdb_leaf_voxels);
static_assert(sizeof(openvdb::Vec3s) == 3 * sizeof(float));
static_assert(LeafMask::WORD_COUNT == 8 && sizeof(LeafMask::Word) == sizeof(std::uint64_t));

/// Archive::write into any seekable stream: what File::write does into its own ofstream.
class StreamArchive : public openvdb::io::Archive {
public:
  void write_to(std::ostream& os, const openvdb::GridCPtrVec& grids, const openvdb::MetaMap& meta) const {
    Archive::write(os, grids, /*seekable=*/true, meta);
  }
};

void insert(openvdb::MetaMap& into, const VdbMetaEntry& e) {
  std::visit(
      [&](const auto& v) {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, std::string>)
          into.insertMeta(e.name, openvdb::StringMetadata(v));
        else if constexpr (std::is_same_v<T, double>)
          into.insertMeta(e.name, openvdb::DoubleMetadata(v));
        else
          into.insertMeta(e.name, openvdb::Int32Metadata(v));
      },
      e.value);
}

}  // namespace

void VdbLeafValues::clear(const std::array<int, 3>& leaf_origin, int float_grids) {
  origin = leaf_origin;
  active.fill(0);
  density.assign(static_cast<std::size_t>(vdb_leaf_voxels), 0.0f);
  color.assign(static_cast<std::size_t>(3 * vdb_leaf_voxels), 0.0f);
  floats.assign(static_cast<std::size_t>(float_grids) * vdb_leaf_voxels, 0.0f);
}

struct VdbLeaves::Impl {
  int float_grids = 0;
  std::vector<std::unique_ptr<FloatLeaf>> density;
  std::vector<std::unique_ptr<Vec3Leaf>> color;
  std::vector<std::vector<std::unique_ptr<FloatLeaf>>> floats;  // per float grid
};

VdbLeaves::VdbLeaves(int float_grids) : impl_(std::make_unique<Impl>()) {
  impl_->float_grids = float_grids;
  impl_->floats.resize(static_cast<std::size_t>(float_grids));
}
VdbLeaves::VdbLeaves(VdbLeaves&&) noexcept = default;
VdbLeaves& VdbLeaves::operator=(VdbLeaves&&) noexcept = default;
VdbLeaves::~VdbLeaves() = default;

std::size_t VdbLeaves::size() const { return impl_ ? impl_->density.size() : 0; }

void VdbLeaves::add(const VdbLeafValues& values) {
  const std::size_t n = vdb_leaf_voxels, grids = impl_ ? impl_->floats.size() : 0;
  if (!impl_ || values.density.size() != n || values.color.size() != 3 * n || values.floats.size() != grids * n)
    throw Error("VDB leaf at (" + std::to_string(values.origin[0]) + ", " + std::to_string(values.origin[1]) + ", " +
                    std::to_string(values.origin[2]) + "): " + std::to_string(values.density.size()) + " density, " +
                    std::to_string(values.color.size()) + " colour and " + std::to_string(values.floats.size()) +
                    " float values; expected 512, 1536 and 512 x " + std::to_string(grids),
                ErrorKind::failed);
  const openvdb::Coord origin(values.origin[0], values.origin[1], values.origin[2]);
  LeafMask mask;
  for (openvdb::Index w = 0; w < LeafMask::WORD_COUNT; ++w) mask.getWord<LeafMask::Word>(w) = values.active[w];
  // A new leaf holds the background (0) everywhere; the values overwrite it and the mask makes
  // the same voxels active in every grid.
  auto float_leaf = [&](const float* v) {
    auto leaf = std::make_unique<FloatLeaf>(origin, 0.0f, false);
    std::copy_n(v, n, leaf->buffer().data());
    leaf->setValueMask(mask);
    return leaf;
  };
  impl_->density.push_back(float_leaf(values.density.data()));
  auto cl = std::make_unique<Vec3Leaf>(origin, openvdb::Vec3s(0.0f), false);
  openvdb::Vec3s* c = cl->buffer().data();
  for (std::size_t i = 0; i < n; ++i) c[i] = openvdb::Vec3s(values.color[3 * i], values.color[3 * i + 1], values.color[3 * i + 2]);
  cl->setValueMask(mask);
  impl_->color.push_back(std::move(cl));
  for (std::size_t g = 0; g < grids; ++g) impl_->floats[g].push_back(float_leaf(values.floats.data() + g * n));
}

struct VdbVolume::Impl {
  openvdb::FloatGrid::Ptr density;
  openvdb::Vec3SGrid::Ptr color;
  std::vector<openvdb::FloatGrid::Ptr> floats;
  openvdb::GridCPtrVec grids;  // in file order
  std::vector<std::string> names;
  openvdb::MetaMap meta;       // the file's
};

VdbVolume::VdbVolume(const VdbVolumeSpec& spec) : impl_(std::make_unique<Impl>()) {
  openvdb::initialize();
  Impl& m = *impl_;
  m.density = openvdb::FloatGrid::create(0.0f);
  m.color = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  for (std::size_t g = 0; g < spec.float_grids.size(); ++g) m.floats.push_back(openvdb::FloatGrid::create(0.0f));

  // Transform: index (i, j, k) at world first_centre + (i, j, k) voxel_size.
  const double vx = spec.voxel_size;
  auto xform = openvdb::math::Transform::createLinearTransform(vx);
  xform->postTranslate(openvdb::Vec3d(spec.first_centre[0], spec.first_centre[1], spec.first_centre[2]));
  for (const auto& e : spec.metadata) insert(m.meta, e);

  auto finish = [&](openvdb::GridBase::Ptr g, const std::string& name) {
    g->setName(name);
    g->setTransform(xform->copy());
    for (auto it = m.meta.beginMeta(); it != m.meta.endMeta(); ++it) g->insertMeta(it->first, *it->second);
    m.grids.push_back(g);
    m.names.push_back(name);
  };
  m.density->setGridClass(openvdb::GRID_FOG_VOLUME);
  finish(m.density, "density");
  m.color->setVectorType(openvdb::VEC_INVARIANT);
  // Cd shares color's tree: OpenVDB writes it once and the second grid as an instance of it
  // (the reader links them back), so neither the memory nor the file holds the colours twice.
  auto cd = m.color->copy();
  finish(m.color, "color");
  finish(cd, "Cd");
  for (std::size_t g = 0; g < spec.float_grids.size(); ++g) {
    for (const auto& e : spec.float_grids[g].metadata) insert(*m.floats[g], e);
    finish(m.floats[g], spec.float_grids[g].name);
  }
}

VdbVolume::~VdbVolume() = default;

void VdbVolume::adopt(VdbLeaves& leaves) {
  Impl& m = *impl_;
  if (!leaves.impl_ || leaves.impl_->floats.size() != m.floats.size())
    throw Error("VDB leaves for " + std::to_string(leaves.impl_ ? leaves.impl_->floats.size() : 0) +
                    " float grids; expected " + std::to_string(m.floats.size()) + " (the volume's)",
                ErrorKind::failed);
  // Each leaf is a new position (the pieces of work are disjoint): the trees take it over.
  auto take = [](auto& tree, auto& list) {
    for (auto& l : list) tree.addLeaf(l.release());
    list.clear();
  };
  take(m.density->tree(), leaves.impl_->density);
  take(m.color->tree(), leaves.impl_->color);
  for (std::size_t g = 0; g < m.floats.size(); ++g) take(m.floats[g]->tree(), leaves.impl_->floats[g]);
}

std::vector<std::string> VdbVolume::grid_names() const { return impl_->names; }

VdbFileWritten VdbVolume::write(const std::filesystem::path& path) const {
  return detail::write_vdb_file(path, [&](std::ostream& os) {
    try {
      StreamArchive().write_to(os, impl_->grids, impl_->meta);
    } catch (const openvdb::Exception& e) {
      throw Error(path.string() + ": OpenVDB could not write the grids: " + e.what(), ErrorKind::failed);
    }
  });
}

}  // namespace trivox::io
