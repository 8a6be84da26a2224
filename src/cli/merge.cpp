// `trivox merge DIR`: joins the shards of a print job (io/merge.hpp).
#include <tbb/global_control.h>

#include <cstdio>
#include <memory>

#include "common.hpp"
#include "trivox/error.hpp"
#include "trivox/job/merge.hpp"

namespace trivox::cli {

namespace {

struct Options {
  std::string dir;
  int threads = 0;
};

}  // namespace

void add_merge(CLI::App& app, Common& common) {
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "merge", "Join the shards of a job (trivox slice --shard K/N) into one stack, VDB and manifest, after checking them");
  sub->add_option("DIR", opt->dir, "The job's output folder, shared by its shards")->required();
  sub->add_option("--threads", opt->threads, "Worker threads for checksums and the VDB merge (default: all cores)");
  sub->add_flag("--json", common.json, "Print the summary as one JSON object");
  sub->callback([opt, &common] {
    if (opt->threads < 0 || opt->threads > 1024)
      throw Error("--threads " + std::to_string(opt->threads) + ": out of range; expected 1 to 1024 (0: all cores)");
    std::unique_ptr<tbb::global_control> limit;
    if (opt->threads > 0)
      limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                    static_cast<std::size_t>(opt->threads));
    const job::MergeSummary s = job::merge_job(opt->dir);
    // A warning, not a failure: the archive is complete without the mesh.
    if (!s.mesh_warning.empty()) std::fprintf(stderr, "trivox: warning: %s\n", s.mesh_warning.c_str());
    if (common.json) {
      nlohmann::ordered_json mats = nlohmann::ordered_json::object();
      for (std::size_t m = 0; m < s.materials.size(); ++m) mats[s.materials[m]] = s.material_voxels[m];
      nlohmann::ordered_json files = nlohmann::ordered_json::array();
      for (const auto& f : s.files) files.push_back({{"role", f.role}, {"file", f.file}, {"sha256", f.sha256}});
      print_json({{"folder", opt->dir},
                  {"shards", s.shards},
                  {"layers", s.layers},
                  {"material_voxels", mats},
                  {"inversion_failures", s.inversion_failures},
                  {"files", files},
                  {"mesh_warning", s.mesh_warning.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(s.mesh_warning)}});
      return;
    }
    std::printf("%s: merged %d shards, %d layers; every layer and part verified (SHA-256)\n", opt->dir.c_str(), s.shards,
                s.layers);
    for (std::size_t m = 0; m < s.materials.size(); ++m)
      if (s.material_voxels[m] > 0)
        std::printf("  %-16s %14lld voxels\n", s.materials[m].c_str(), static_cast<long long>(s.material_voxels[m]));
    std::printf("inversion failures: %lld\n", static_cast<long long>(s.inversion_failures));
    for (const auto& f : s.files) std::printf("wrote %s (%s)\n", f.file.c_str(), f.role.c_str());
    std::printf("wrote manifest.json\n");
  });
}

}  // namespace trivox::cli
