// What the subcommands share: resolving the scene, the thread count, error lines.
#include <iostream>

#include "tools/commands.hpp"
#include "tools/scene_setup.hpp"

namespace papertear::cli {

void print_error(const std::string& message) {
  std::cerr << "papertear: error: " << message << std::endl;
}

io::SceneFile resolve_scene(const SceneOptions& options, const std::vector<io::SetOverride>& extra) {
  std::vector<io::SetOverride> overrides;
  for (const std::string& arg : options.sets) overrides.push_back(io::parse_set_argument(arg));
  overrides.insert(overrides.end(), extra.begin(), extra.end());
  return io::resolve_scene(options.scene_path, overrides);
}

Simulation make_simulation(const io::SceneFile& file, int threads) {
  return io::make_simulation(file, threads);
}

int resolved_threads(int requested) { return io::resolved_threads(requested); }

}  // namespace papertear::cli
