// Where the renderer plugs into `papertear run`: its sinks read the scene's [render],
// [camera], [light], [print] and [output] sections (--set values included) and write PNG
// frames and meshes under the output directory. See tools/frame_sink.hpp for what a sink
// may do when; add any other per-frame writer here.
#include "tools/commands.hpp"
#include "tools/render/frame_sinks.hpp"
#include "tools/render/settings.hpp"

namespace papertear::cli {

std::vector<std::unique_ptr<io::FrameSink>> make_frame_sinks(const io::SceneFile& scene, const Simulation& sim,
                                                             const std::filesystem::path* out_dir) {
  // A relative print image is found from the scene file's folder (the working directory
  // for the built-in scene).
  const std::filesystem::path scene_dir = std::filesystem::path(scene.path).parent_path();
  if (!out_dir) {
    // Nowhere to write frames, but a mistyped render key is still an error, with or
    // without --out.
    render::parse_render_settings(scene.render_config, scene_dir);
    render::parse_output_settings(scene.render_config);
    return {};
  }
  auto sinks = render::make_render_sinks(scene.render_config, scene_dir, *out_dir);
  for (const auto& sink : sinks) sink->check(sim);
  return sinks;
}

}  // namespace papertear::cli
