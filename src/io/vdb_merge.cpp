#include "trivox/io/vdb_merge.hpp"

#include <openvdb/io/Archive.h>
#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <string>
#include <utility>

#include "trivox/error.hpp"
#include "trivox/io/model_file.hpp"
#include "vdb_file.hpp"

namespace trivox::io {

namespace fs = std::filesystem;

namespace {

/// Archive::write into any seekable stream: what File::write does into its own ofstream.
class StreamArchive : public openvdb::io::Archive {
public:
  void write_to(std::ostream& os, const openvdb::GridCPtrVec& grids, const openvdb::MetaMap& meta) const {
    Archive::write(os, grids, /*seekable=*/true, meta);
  }
};

}  // namespace

void merge_vdb_parts(const std::vector<fs::path>& parts, const fs::path& out) {
  if (parts.empty()) throw Error(out.string() + ": no VDB parts to merge; expected at least one");
  openvdb::initialize();
  openvdb::GridPtrVec merged;
  openvdb::MetaMap meta;
  for (std::size_t p = 0; p < parts.size(); ++p) {
    openvdb::GridPtrVecPtr grids;
    openvdb::MetaMap::Ptr file_meta;
    try {
      std::ifstream in(parts[p], std::ios::binary);
      if (!in) throw Error(parts[p].string() + ": cannot open: " + std::strerror(errno) + "; expected a shard's VDB part");
      // Read whole (no delayed loading), so nothing is copied to a temporary folder ($TMPDIR).
      openvdb::io::Stream stream(in, /*delayLoad=*/false);
      grids = stream.getGrids();
      file_meta = stream.getMetadata();
    } catch (const openvdb::Exception& e) {
      throw Error(parts[p].string() + ": cannot read it as a VDB file (" + e.what() + "); expected a shard's VDB part");
    }
    if (p == 0) {
      // OpenVDB hands the grids back sorted by name; the file order (density first) is that of
      // their descriptors, each starting with the name and the type, length-prefixed.
      const std::string bytes = read_file(parts[p]);
      auto position = [&](const openvdb::GridBase::Ptr& g) {
        auto field = [](const std::string& t) {
          const auto n = static_cast<std::uint32_t>(t.size());
          std::string f(4, '\0');
          for (int b = 0; b < 4; ++b) f[static_cast<std::size_t>(b)] = static_cast<char>((n >> (8 * b)) & 0xff);
          return f + t;
        };
        const auto at = bytes.find(field(g->getName()) + field(g->type()));
        if (at == std::string::npos)
          throw Error(parts[p].string() + ": grid " + g->getName() + " not found in the file; expected an OpenVDB 10 file");
        return at;
      };
      merged = *grids;
      std::vector<std::pair<std::size_t, openvdb::GridBase::Ptr>> order;
      for (auto& g : merged) order.emplace_back(position(g), g);
      std::sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
      for (std::size_t g = 0; g < order.size(); ++g) merged[g] = order[g].second;
      meta = *file_meta;
      continue;
    }
    // The other parts' grids, matched to the first's by name.
    std::map<std::string, openvdb::GridBase::Ptr> by_name;
    for (auto& g : *grids) by_name[g->getName()] = g;
    openvdb::GridPtrVec ordered;
    for (auto& g : merged) {
      const auto it = by_name.find(g->getName());
      if (it == by_name.end())
        throw Error(parts[p].string() + ": no grid " + g->getName() + "; expected the grids of " + parts[0].string());
      ordered.push_back(it->second);
    }
    *grids = ordered;
    if (grids->size() != merged.size())
      throw Error(parts[p].string() + ": " + std::to_string(grids->size()) + " grids; expected " +
                  std::to_string(merged.size()) + " like " + parts[0].string());
    std::vector<const void*> trees;  // the trees merged so far (Cd shares color's: merge it once)
    for (std::size_t g = 0; g < grids->size(); ++g) {
      auto& into = merged[g];
      auto& from = (*grids)[g];
      const void* tree = into->baseTreePtr().get();
      const bool instance = std::find(trees.begin(), trees.end(), tree) != trees.end();
      trees.push_back(tree);
      if (from->getName() != into->getName() || from->type() != into->type() ||
          from->transform() != into->transform())
        throw Error(parts[p].string() + ": grid " + std::to_string(g) + " (" + from->getName() + ", " + from->type() +
                    ") differs from " + parts[0].string() + " (" + into->getName() + ", " + into->type() +
                    "); expected parts of one job");
      // The parts hold disjoint whole leaves (shards are whole 8-layer blocks): merging moves
      // them into the first part's trees.
      if (instance) continue;
      if (auto f = openvdb::gridPtrCast<openvdb::FloatGrid>(into)) {
        f->tree().merge(openvdb::gridPtrCast<openvdb::FloatGrid>(from)->tree());
      } else if (auto v = openvdb::gridPtrCast<openvdb::Vec3SGrid>(into)) {
        v->tree().merge(openvdb::gridPtrCast<openvdb::Vec3SGrid>(from)->tree());
      } else {
        throw Error(parts[p].string() + ": grid " + from->getName() + " of type " + from->type() +
                    "; expected the float and vec3s grids trivox writes");
      }
    }
  }
  // OpenVDB adds statistics (file_bbox_*, file_voxel_count, ...) to grids it writes and reads
  // them back as metadata: drop them so they are computed afresh for the merged grids.
  openvdb::GridCPtrVec out_grids;
  for (auto& g : merged) {
    for (const char* stat : {"file_bbox_min", "file_bbox_max", "file_mem_bytes", "file_voxel_count", "file_compression",
                             "file_delayed_load"})
      g->removeMeta(stat);
    out_grids.push_back(g);
  }
  detail::write_vdb_file(out, [&](std::ostream& os) {
    try {
      StreamArchive().write_to(os, out_grids, meta);
    } catch (const openvdb::Exception& e) {
      throw Error(out.string() + ": OpenVDB could not write the grids: " + e.what(), ErrorKind::failed);
    }
  });
}

}  // namespace trivox::io
