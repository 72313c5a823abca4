// From a scene (a file or the built-in default) and --set style overrides to a Simulation
// ready to step: the steps `papertear run` takes before its first step. The CLI and other
// embedders (the Python module) share them, so a scene means the same everywhere and its
// errors read the same.
#pragma once
#include <span>
#include <string>
#include <vector>

#include "core/simulation.hpp"
#include "tools/scene_file.hpp"

namespace papertear::io {

// Loads the scene file at `path` (empty: the built-in default scene) with the overrides
// applied in order. Throws papertear::SceneError.
SceneFile resolve_scene(const std::string& path, std::span<const SetOverride> overrides = {});

// The file's Simulation; a scene the constructor refuses (run.dt above the stable limit)
// gets its error located in the file like any other bad value. Throws SceneError.
Simulation make_simulation(const SceneFile& file, int threads);

// The worker count a Simulation given `requested` threads uses (0: all hardware threads).
int resolved_threads(int requested);

}  // namespace papertear::io
