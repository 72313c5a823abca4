// The renderer's part of `papertear run`: frame sinks (tools/frame_sink.hpp) that write a
// PNG per frame and, if asked, the display mesh, as the scene's [output] table says:
//
//   [output]
//   png = true              # frames/<prefix>_0000.png, one per frame
//   prefix = "frame"        # file name prefix
//   mesh = "none"           # "none", "glb", "obj" or "both"
//   mesh_frames = "last"    # "last" (the final frame only) or "all"
//   animation = true        # animation.glb: the whole run as one animated mesh (animation.hpp)
//   video = true            # video.mp4 from the PNG frames (video.hpp)
//   video_fps = 15          # the video's frame rate, also the animation's and the meshes' "fps"
//
// The camera is fixed at the start of the run (the scene's [camera], or fitted to the
// intact sheet), so the frames of a run line up. With OBJ output the print image is written
// once as <prefix>_print.png for the .mtl to refer to; a .glb embeds it.
#pragma once
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "tools/frame_sink.hpp"

namespace papertear::render {

struct OutputSettings {
  bool png = true;
  std::string prefix = "frame";
  bool glb = true;                // a .glb per frame by default: meshes other tools open
  bool obj = false;
  bool mesh_every_frame = false;  // true: every frame (torn frames are tens of MB each)
  bool video = true;              // frames into video.mp4 when ffmpeg is on the PATH
  int video_fps = 15;
  bool animation = true;          // DIR/animation.glb, next to summary.json
};

// Reads [output] from a scene's renderer sections. Throws SceneError naming the key.
OutputSettings parse_output_settings(const toml::table& root);

// Sinks for a run writing into `out_dir` (which exists when on_start runs). `render_config`
// holds the scene's [render], [camera], [light], [print] and [output] tables; a relative
// print image is found from `scene_dir`. Throws SceneError for bad settings (also for a
// print image that cannot be read); writes nothing.
std::vector<std::unique_ptr<io::FrameSink>> make_render_sinks(const toml::table& render_config,
                                                              const std::filesystem::path& scene_dir,
                                                              const std::filesystem::path& out_dir);

}  // namespace papertear::render
