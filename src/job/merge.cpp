#include "trivox/job/merge.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <map>
#include <optional>

#include "trivox/error.hpp"
#include "trivox/io/gcvf.hpp"
#include "trivox/job/archive_mesh.hpp"
#include "trivox/io/model_file.hpp"
#include "trivox/io/safe_path.hpp"
#include "trivox/io/sha256.hpp"
#include "trivox/io/slice_stack.hpp"
#include "trivox/io/vdb_merge.hpp"

namespace trivox::job {

namespace fs = std::filesystem;

namespace {

/// "manifest.shard-K-of-N.json" -> {K, N}.
std::optional<Shard> shard_of_name(const std::string& name) {
  const std::string head = "manifest.shard-", tail = ".json";
  if (!name.starts_with(head) || !name.ends_with(tail)) return std::nullopt;
  const std::string mid = name.substr(head.size(), name.size() - head.size() - tail.size());
  const auto of = mid.find("-of-");
  if (of == std::string::npos) return std::nullopt;
  try {
    const Shard s = parse_shard(mid.substr(0, of) + "/" + mid.substr(of + 4));
    return s.manifest_name() == name ? std::optional<Shard>(s) : std::nullopt;
  } catch (const Error&) {
    return std::nullopt;
  }
}

/// A regular file (not a link: links out of the folder are never followed) with digest `sha`.
bool file_matches(const fs::path& path, const std::string& sha) { return io::sha256_regular_file(path) == sha; }

/// Where a part's `files` entry lives, derived from the job and the folder, never from the
/// entry's string (which must equal what the shard writes); empty with the reason in `why`.
fs::path part_file(const fs::path& dir, const Manifest& job, const Shard& shard, const ManifestFile& f, std::string& why) {
  std::string expected;
  fs::path path;
  if (f.role == "vdb") {
    expected = shard.part_name(vdb_file_name(job));
    path = dir / expected;
  } else if (f.role == "zip") {
    expected = zip_entry_name(dir);
    path = io::gcvf_path(dir);
  } else if (f.role == "mesh") {
    expected = archive_mesh_name;
    path = dir / expected;
  } else {
    expected = "ConfigFile.xml";
    path = dir / expected;
  }
  if (f.file != expected) {
    why = "lists its " + f.role + " file as \"" + f.file + "\"; expected \"" + expected + "\"";
    return {};
  }
  return path;
}

}  // namespace

MergeSummary merge_job(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw Error(dir.string() + ": not a folder; expected the output folder of a sharded trivox slice job");

  // The parts, by shard index; all of one job and one shard count.
  std::map<int, Manifest> parts;
  std::optional<Manifest> first;
  std::string first_name;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    const auto shard = shard_of_name(name);
    if (!shard) continue;
    Manifest m = *read_manifest(dir, name);
    if (m.shard != *shard)
      throw Error((dir / name).string() + ": /shard: says shard " + std::to_string(m.shard.index) + "/" +
                  std::to_string(m.shard.count) + "; expected " + std::to_string(shard->index) + "/" +
                  std::to_string(shard->count) + " as its name says");
    if (!first) {
      first = m;
      first_name = name;
    } else if (m.shard.count != first->shard.count) {
      throw Error(dir.string() + ": holds parts of " + std::to_string(first->shard.count) + " shards (" + first_name +
                  ") and of " + std::to_string(m.shard.count) + " (" + name +
                  "); expected the parts of one job (remove the stale ones, or rerun every shard)");
    } else if (const std::string why = first->difference(m); !why.empty()) {
      throw Error(dir.string() + ": " + name + " and " + first_name + " are parts of different jobs (" + why +
                  "); expected the parts of one job");
    }
    parts.emplace(shard->index, std::move(m));
  }
  if (!first)
    throw Error(dir.string() + ": no shard manifests (manifest.shard-K-of-N.json); expected the folder of a job "
                "sliced with --shard K/N or a scheduler's array index");
  const Manifest& job = *first;
  const int n = job.shard.count, nz = job.grid[2];
  const auto png_option = job.options.find("png");
  const bool png = png_option == job.options.end() || png_option->second != "no";  // a PNG stack

  // Every problem, per shard.
  std::vector<std::string> problems;
  std::vector<int> rerun;
  for (int k = 0; k < n; ++k) {
    const Shard s{k, n};
    const auto it = parts.find(k);
    std::string problem;
    if (it == parts.end()) {
      problem = "no " + s.manifest_name() + " (the shard never ran, or failed before its first layer)";
    } else {
      const Manifest& m = it->second;
      const auto range = s.range(nz);
      if (m.layer_range != range) {
        problem = s.manifest_name() + " covers layers [" + std::to_string(m.layer_range[0]) + ", " +
                  std::to_string(m.layer_range[1]) + "); expected [" + std::to_string(range[0]) + ", " +
                  std::to_string(range[1]) + ")";
      } else if (!m.complete) {
        problem = "unfinished: " + std::to_string(m.layers.size()) + " of " + std::to_string(range[1] - range[0]) +
                  " layers";
      } else if (static_cast<int>(m.layers.size()) != (png ? range[1] - range[0] : 0)) {
        problem = "lists " + std::to_string(m.layers.size()) + " layers; expected " +
                  std::to_string(png ? range[1] - range[0] : 0);
      } else {
        std::vector<char> ok(m.layers.size(), 0);
        tbb::parallel_for(std::size_t{0}, m.layers.size(),
                          [&](std::size_t i) { ok[i] = file_matches(dir / m.layers[i].file, m.layers[i].sha256); });
        std::vector<std::string> bad;
        for (std::size_t i = 0; i < ok.size(); ++i)
          if (!ok[i]) bad.push_back(m.layers[i].file);
        for (const auto& f : m.files) {
          std::string why;
          const fs::path path = part_file(dir, job, s, f, why);
          if (path.empty()) {
            problem = why;
            break;
          }
          if (!file_matches(path, f.sha256)) bad.push_back(f.file);
        }
        if (problem.empty() && !bad.empty())
          problem = std::to_string(bad.size()) + " file(s) missing or changed since the shard wrote them (" + bad.front() +
                    (bad.size() > 1 ? ", ..." : "") + ")";
      }
    }
    if (!problem.empty()) {
      problems.push_back("shard " + std::to_string(k) + "/" + std::to_string(n) + ": " + problem);
      rerun.push_back(k);
    }
  }
  if (!problems.empty()) {
    std::string msg = dir.string() + ": cannot merge; expected every shard complete and intact:";
    for (const auto& p : problems) msg += "\n  " + p;
    msg += "\nrerun only ";
    for (std::size_t i = 0; i < rerun.size(); ++i)
      msg += (i ? ", " : "") + std::string("--shard ") + std::to_string(rerun[i]) + "/" + std::to_string(n);
    msg += " (same model and options, same folder), then merge again";
    throw Error(msg);
  }

  // The merged manifest and stack.
  Manifest merged = job;
  merged.shard = {0, 1};
  merged.layer_range = {0, nz};  // for a volume-only job: the VDB's layers
  merged.layers.clear();
  merged.files.clear();
  MergeSummary sum;
  sum.shards = n;
  sum.layers = nz;
  sum.materials = job.materials;
  sum.material_voxels.assign(job.materials.size(), 0);
  // The merged VDB's name and its parts' come from the job (the model's name), not from the
  // strings of the parts, which were checked above to be those names.
  std::vector<fs::path> vdb_parts;
  std::optional<ManifestFile> mesh;  // the archive's boundary mesh (archive_mesh.hpp)
  const std::string vdb_name = vdb_file_name(job);
  for (const auto& [k, m] : parts) {
    for (const auto& l : m.layers) {
      merged.layers.push_back(l);
      for (std::size_t i = 0; i < l.voxels.size() && i < sum.material_voxels.size(); ++i) sum.material_voxels[i] += l.voxels[i];
      sum.inversion_failures += l.failures;
    }
    for (const auto& f : m.files) {
      if (f.role == "vdb") vdb_parts.push_back(dir / Shard{k, n}.part_name(vdb_name));
      if (f.role == "mesh") mesh = f;  // shard 0's, verified above
    }
  }
  if (!vdb_parts.empty() && static_cast<int>(vdb_parts.size()) != n)
    throw Error(dir.string() + ": only " + std::to_string(vdb_parts.size()) + " of " + std::to_string(n) +
                " shards list a VDB part; expected all or none");

  if (png) {
    const io::StackConfig cfg = stack_config_of(job, sum.material_voxels);
    const std::string config = io::config_xml(cfg);
    io::write_file_atomically(dir / "ConfigFile.xml", config);
    merged.files.push_back({"config", "ConfigFile.xml", io::sha256_hex(config)});
    const auto zip_opt = job.options.find("png.zip");
    if (zip_opt != job.options.end() && zip_opt->second == "yes") {
      std::vector<std::string> extra;
      if (mesh) {
        merged.files.push_back(*mesh);
        extra.push_back(mesh->file);
      } else {
        sum.mesh_warning = dir.string() + ": no " + std::string(archive_mesh_name) + " in the archive: shard 0 did not "
                           "write one (the model could not be meshed; its output said why)";
      }
      const fs::path zip = io::gcvf_path(dir);
      io::zip_stack(dir, zip, extra);
      merged.files.push_back({"zip", "../" + zip.filename().string(), io::sha256_file(zip)});
    }
  }
  if (!vdb_parts.empty()) {
    io::merge_vdb_parts(vdb_parts, dir / vdb_name);
    merged.files.push_back({"vdb", vdb_name, io::sha256_file(dir / vdb_name)});
  }
  merged.complete = true;
  io::write_file_atomically(dir / merged.shard.manifest_name(), manifest_json(merged));
  sum.files = merged.files;
  return sum;
}

}  // namespace trivox::job
