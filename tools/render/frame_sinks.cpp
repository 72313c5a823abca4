#include "tools/render/frame_sinks.hpp"

#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <optional>

#include "core/scene.hpp"
#include "tools/render/animation.hpp"
#include "tools/render/indenter_mesh.hpp"
#include "tools/render/mesh_export.hpp"
#include "tools/render/raytracer.hpp"
#include "tools/render/surface.hpp"
#include "tools/render/video.hpp"
#include "tools/run_frames.hpp"
#include "tools/toml_keys.hpp"

namespace papertear::render {

namespace {

const std::vector<std::string>& output_keys() {
  static const std::vector<std::string> keys = {"output.png", "output.prefix", "output.mesh", "output.mesh_frames",
                                                "output.video", "output.video_fps", "output.animation"};
  return keys;
}

// Frame and mesh files are named <prefix>_NNNN.<ext> inside DIR/frames and DIR/mesh, so a
// prefix cannot lead out of the output directory; it is still held to portable file-name
// characters, so that every file system, shell and ffmpeg's pattern take it as it is.
std::string prefix_problem(const std::string& prefix) {
  if (prefix.empty()) return "must not be empty";
  if (prefix.size() > std::size_t(kMaxPrefixLength))
    return "may be at most " + std::to_string(kMaxPrefixLength) + " characters (got " + std::to_string(prefix.size()) + ")";
  for (unsigned char c : prefix)
    if (!(std::isalnum(c) || c == '_' || c == '-' || c == '.'))
      return "may hold only letters, digits, '_', '-' and '.' (it names files in DIR/frames and DIR/mesh)";
  if (prefix.front() == '.' || prefix.front() == '-') return "must not begin with '.' or '-'";
  return "";
}

std::string numbered(const std::string& prefix, int frame, const char* extension) {
  char digits[16];
  std::snprintf(digits, sizeof digits, "_%04d", frame);
  return prefix + digits + extension;
}

class RenderSink final : public io::FrameSink {
 public:
  RenderSink(const RenderSettings& render, const OutputSettings& output, std::filesystem::path out_dir)
      : renderer_(render), output_(output), out_dir_(std::move(out_dir)) {}

  // The camera is fitted to the sheet at rest: a camera.up along the view fails here.
  void check(const Simulation& sim) const override {
    try {
      (void)renderer_.camera_for(sim.world());
    } catch (const RenderError& e) {
      throw SceneError(e.what());
    }
  }

  // Frames go to DIR/frames/, meshes (and the print texture they reference) to DIR/mesh/.
  void on_start(const Simulation& sim) override {
    camera_ = renderer_.camera_for(sim.world());
    if (output_.png) std::filesystem::create_directories(frames_dir());
    if (output_.glb || output_.obj) std::filesystem::create_directories(mesh_dir());
    if (output_.obj && renderer_.settings().print.enabled)
      write_png(mesh_dir() / (output_.prefix + "_print.png"), renderer_.print());
  }

  void on_frame(const Simulation& sim, int frame, int frames, const Metrics&) override {
    const bool last = frame + 1 == frames;
    const bool mesh_due = (output_.glb || output_.obj) && (output_.mesh_every_frame || last);
    const FrameInfo info{frame, sim.world().step, sim.time(), output_.video_fps, sim.digest()};
    if (output_.animation) recording_.add_frame(sim.world(), info);
    if (!output_.png && !mesh_due) return;
    build_surface_mesh(sim.world(), renderer_.mesh_options(), mesh_);
    if (mesh_due) {
      ExportOptions options = export_options();
      options.frame = info;
      if (output_.glb) export_glb(mesh_, mesh_dir() / numbered(output_.prefix, frame, ".glb"), options);
      if (output_.obj) export_obj(mesh_, mesh_dir() / numbered(output_.prefix, frame, ".obj"), options);
    }
    // The frame shows the pierce scene's indenter too; the meshes hold the sheet only.
    if (!output_.png) return;
    append_indenter(sim.world(), mesh_);
    write_png(frames_dir() / numbered(output_.prefix, frame, ".png"), renderer_.draw(mesh_, *camera_));
  }

  // The animation of the recorded frames, on the topology the run ended with. Not after a
  // blow-up: the final state may hold non-finite values.
  void on_finish(const Simulation& sim, const io::RunRecord& record) override {
    if (!output_.animation || record.failure || recording_.frame_count() == 0) return;
    recording_.write_glb(sim.world(), export_options(), out_dir_ / "animation.glb");
  }

 private:
  ExportOptions export_options() const {
    ExportOptions options;
    const bool printed = renderer_.settings().print.enabled;
    options.print = printed ? &renderer_.print() : nullptr;
    options.print_file = printed ? output_.prefix + "_print.png" : "";
    options.paper_color = renderer_.settings().paper_color;
    return options;
  }

  std::filesystem::path frames_dir() const { return out_dir_ / "frames"; }
  std::filesystem::path mesh_dir() const { return out_dir_ / "mesh"; }

  Renderer renderer_;
  SurfaceMesh mesh_;  // rebuilt in place each frame: its memory stays mapped
  OutputSettings output_;
  std::filesystem::path out_dir_;
  std::optional<Camera> camera_;
  TearRecording recording_;  // every frame's node positions, for animation.glb
};

}  // namespace

OutputSettings parse_output_settings(const toml::table& root) {
  OutputSettings o;
  const toml::table* t = io::find_table(root, "output", "output");
  if (!t) return o;
  io::check_known_keys(*t, "output", output_keys());
  if (const toml::node* n = t->get("png")) o.png = io::read_bool(*n, "output.png");
  if (const toml::node* n = t->get("prefix")) {
    o.prefix = io::read_string(*n, "output.prefix");
    if (const std::string problem = prefix_problem(o.prefix); !problem.empty())
      io::fail_at(*n, "output.prefix", problem);
  }
  if (const toml::node* n = t->get("mesh")) {
    const std::string mesh = io::read_string(*n, "output.mesh");
    if (mesh != "none" && mesh != "glb" && mesh != "obj" && mesh != "both")
      io::fail_at(*n, "output.mesh", "expected \"none\", \"glb\", \"obj\" or \"both\", got \"" + mesh + "\"");
    o.glb = mesh == "glb" || mesh == "both";
    o.obj = mesh == "obj" || mesh == "both";
  }
  if (const toml::node* n = t->get("mesh_frames")) {
    const std::string which = io::read_string(*n, "output.mesh_frames");
    if (which != "last" && which != "all")
      io::fail_at(*n, "output.mesh_frames", "expected \"last\" or \"all\", got \"" + which + "\"");
    o.mesh_every_frame = which == "all";
  }
  if (const toml::node* n = t->get("animation")) o.animation = io::read_bool(*n, "output.animation");
  if (const toml::node* n = t->get("video")) o.video = io::read_bool(*n, "output.video");
  if (const toml::node* n = t->get("video_fps")) {
    o.video_fps = io::read_int(*n, "output.video_fps");
    if (o.video_fps < 1 || o.video_fps > 240) io::fail_at(*n, "output.video_fps", "must be between 1 and 240");
  }
  return o;
}

std::vector<std::unique_ptr<io::FrameSink>> make_render_sinks(const toml::table& render_config,
                                                              const std::filesystem::path& scene_dir,
                                                              const std::filesystem::path& out_dir) {
  const RenderSettings render = parse_render_settings(render_config, scene_dir);
  const OutputSettings output = parse_output_settings(render_config);
  std::vector<std::unique_ptr<io::FrameSink>> sinks;
  if (!output.png && !output.glb && !output.obj && !output.animation) return sinks;
  try {
    sinks.push_back(std::make_unique<RenderSink>(render, output, out_dir));
    if (output.png && output.video) {
      const char* path = std::getenv("PATH");
      sinks.push_back(std::make_unique<VideoSink>(out_dir / "frames", output.prefix, out_dir, output.video_fps,
                                                  path ? path : "", std::cerr));
    }
  } catch (const RenderError& e) {  // the print image: bad input, reported like the scene's
    throw SceneError(e.what());
  }
  return sinks;
}

}  // namespace papertear::render
