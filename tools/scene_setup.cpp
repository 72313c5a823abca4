// From a scene and its overrides to a Simulation (tools/scene_setup.hpp).
#include "tools/scene_setup.hpp"

#include <oneapi/tbb/info.h>

namespace papertear::io {

SceneFile resolve_scene(const std::string& path, std::span<const SetOverride> overrides) {
  if (path.empty()) return default_scene_file(overrides);
  return load_scene_file(path, overrides);
}

Simulation make_simulation(const SceneFile& file, int threads) {
  try {
    return Simulation(file.scene, {.threads = threads});
  } catch (const SceneError& e) {
    rethrow_located(e, file);
  }
}

int resolved_threads(int requested) {
  return requested > 0 ? requested : tbb::info::default_concurrency();
}

}  // namespace papertear::io
