// EmbeddedRun (tools/python/embedded_run.hpp).
#include "tools/python/embedded_run.hpp"

#include <chrono>

#include "core/checkpoint.hpp"
#include "fracture/metrics.hpp"
#include "tools/scene_setup.hpp"
#include "tools/summary.hpp"

namespace papertear::embed {

EmbeddedRun::EmbeddedRun(Simulation sim, std::string scene_path, int threads)
    : scene_path_(std::move(scene_path)),
      threads_(io::resolved_threads(threads)),
      sim_(std::move(sim)),
      first_step_(sim_.steps_done()) {
  record_.digest = sim_.digest();
  record_.dt = sim_.dt();
  record_.time = sim_.time();
}

namespace {
Simulation build(const io::SceneFile& file, int threads) { return io::make_simulation(file, threads); }
}  // namespace

EmbeddedRun::EmbeddedRun(const std::string& scene_path, const std::vector<io::SetOverride>& overrides,
                         int threads)
    : EmbeddedRun(build(io::resolve_scene(scene_path, overrides), threads), scene_path, threads) {}

std::unique_ptr<EmbeddedRun> EmbeddedRun::from_checkpoint(const std::string& path, int threads) {
  World world = load_checkpoint(path);
  return std::unique_ptr<EmbeddedRun>(
      new EmbeddedRun(Simulation(std::move(world), {.threads = threads}), "", threads));
}

void EmbeddedRun::step(int n) {
  std::lock_guard lock(mutex_);
  const auto start = std::chrono::steady_clock::now();
  record_.steps_planned = record_.steps_done + n;
  try {
    sim_.step(n);
  } catch (const BlowUpError& e) {
    record_.failure = io::RunFailure{e.what(), e.step, e.node};
    record_.steps_done = sim_.steps_done() - first_step_;
    throw;
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  record_.step_seconds += seconds;
  record_.steps_done = sim_.steps_done() - first_step_;
  record_.frames.push_back(measure(sim_.world()));
  record_.wall_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  record_.digest = sim_.digest();
  record_.time = sim_.time();
}

nlohmann::json EmbeddedRun::summary() const {
  std::lock_guard lock(mutex_);
  const Scene& scene = sim_.scene();
  const io::RunSettings settings{scene_path_, threads_, Simulation::stable_dt_limit(scene)};
  return io::summary_json(scene, settings, record_);
}

void EmbeddedRun::save_checkpoint(const std::string& path) const {
  std::lock_guard lock(mutex_);
  papertear::save_checkpoint(sim_.world(), path);
}

}  // namespace papertear::embed
