// summary.json: what a run measured, in a form scripts can read (parameter studies compare
// many of them). Every key is documented in docs/summary-schema.md; a change to the layout
// bumps kSummarySchemaVersion.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "core/scene.hpp"
#include "fracture/metrics.hpp"
#include "tools/run_frames.hpp"

namespace papertear::io {

inline constexpr int kSummarySchemaVersion = 2;

// What the run record does not know: how it was set up.
struct RunSettings {
  std::string scene_path;  // empty for the built-in default scene
  int threads = 0;         // worker threads actually used
  double stable_dt = 0.0;  // Simulation::stable_dt_limit(scene)
};

// 16 lowercase hex digits, zero-padded: the form printed as "digest: ..." and stored in JSON.
std::string digest_hex(std::uint64_t digest);

nlohmann::json metrics_to_json(const Metrics& metrics);
// Every Scene key, grouped by section as in a scene file; run.dt is "auto" or a number.
nlohmann::json scene_to_json(const Scene& scene);
nlohmann::json summary_json(const Scene& scene, const RunSettings& settings,
                            const RunRecord& record);

// Writes summary_json(...) to dir/summary.json atomically. Throws OutputError.
void write_summary(const std::filesystem::path& dir, const Scene& scene,
                   const RunSettings& settings, const RunRecord& record);

}  // namespace papertear::io
