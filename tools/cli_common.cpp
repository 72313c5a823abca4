// What the subcommands share: resolving the scene, the thread count, error lines.
#include <iostream>

#include <oneapi/tbb/info.h>

#include "tools/commands.hpp"

namespace papertear::cli {

void print_error(const std::string& message) {
  std::cerr << "papertear: error: " << message << std::endl;
}

io::SceneFile resolve_scene(const SceneOptions& options, const std::vector<io::SetOverride>& extra) {
  std::vector<io::SetOverride> overrides;
  for (const std::string& arg : options.sets) overrides.push_back(io::parse_set_argument(arg));
  overrides.insert(overrides.end(), extra.begin(), extra.end());
  if (options.scene_path.empty()) return io::default_scene_file(overrides);
  return io::load_scene_file(options.scene_path, overrides);
}

Simulation make_simulation(const io::SceneFile& file, int threads) {
  try {
    return Simulation(file.scene, {.threads = threads});
  } catch (const SceneError& e) {
    io::rethrow_located(e, file);
  }
}

int resolved_threads(int requested) {
  return requested > 0 ? requested : tbb::info::default_concurrency();
}

}  // namespace papertear::cli
