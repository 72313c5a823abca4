// A Simulation as an embedding host drives it: built from a scene (or a checkpoint) the way
// `papertear run` builds it, stepped in calls of any length, with a run record so that the
// summary has the same layout as summary.json. No Python here: module.cpp binds it.
#pragma once
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/simulation.hpp"
#include "tools/run_frames.hpp"
#include "tools/scene_file.hpp"

namespace papertear::embed {

class EmbeddedRun {
 public:
  // A scene file (empty path: the built-in default) with --set style overrides.
  // Throws SceneError with the CLI's message.
  EmbeddedRun(const std::string& scene_path, const std::vector<io::SetOverride>& overrides, int threads);
  // Continues a checkpoint (core/checkpoint.hpp) written by save() or by `papertear run`.
  // Throws CheckpointError.
  static std::unique_ptr<EmbeddedRun> from_checkpoint(const std::string& path, int threads);

  // Steps n times and measures the world afterwards: each call is one frame of the summary.
  // Calls from several threads are serialised. Throws BlowUpError (also kept in the record).
  void step(int n);
  // summary.json's layout: the metrics of every step() call as frames, the last as "final".
  nlohmann::json summary() const;
  // Writes the world as a checkpoint that `papertear resume` and from_checkpoint() read.
  void save_checkpoint(const std::string& path) const;

  const Simulation& simulation() const { return sim_; }
  const std::string& scene_path() const { return scene_path_; }
  int threads() const { return threads_; }

 private:
  EmbeddedRun(Simulation sim, std::string scene_path, int threads);
  EmbeddedRun(const EmbeddedRun&) = delete;
  EmbeddedRun& operator=(const EmbeddedRun&) = delete;

  std::string scene_path_;
  int threads_;
  Simulation sim_;
  io::RunRecord record_;
  std::int64_t first_step_;  // the step the simulation was built or loaded at
  mutable std::mutex mutex_;  // one step() at a time; summary and save wait for it
};

}  // namespace papertear::embed
