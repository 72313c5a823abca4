// Render settings: the [render], [camera], [light] and [print] tables of a scene file.
// Colours are written as sRGB, either "#rrggbb" or an array of three numbers in [0, 1];
// lengths are in the lattice's units (cell sizes).
//
//   [render]  width, height, samples, background, paper_color, exposure,
//             fray, fray_length, layer_opacity
//   [camera]  position, target, up, fov          (position/target default: framed on the sheet)
//   [light]   direction, intensity, ambient, softness
//   [print]   image                               (a PNG; default: the built-in poster), enabled
//
// Every table and key is optional; a missing one takes the default below.
#pragma once
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <toml++/toml.h>

namespace papertear::render {

using Vec3d = std::array<double, 3>;

struct CameraSettings {
  std::optional<Vec3d> position;  // none: above the sheet at an angle, fitted to its bounds
  std::optional<Vec3d> target;    // none: the centre of the sheet's bounding box
  Vec3d up{0.0, 0.0, 1.0};
  double fov = 35.0;              // vertical field of view, degrees
};

struct LightSettings {
  Vec3d direction{0.45, 0.6, -1.0};  // the way the light travels (towards the sheet)
  double intensity = 0.85;           // key light
  double ambient = 0.32;             // sky light, unshadowed
  double softness = 0.03;            // angular radius of the light, radians (soft shadows)
};

struct PrintSettings {
  bool enabled = true;                // false: the top face is plain paper
  std::filesystem::path image;        // empty: the built-in procedural print
};

// Upper bounds on the image: a 16k frame is 800 MB of samples before it is encoded.
inline constexpr int kMaxImageSide = 16384;    // render.width, render.height, in pixels
inline constexpr int kMaxSamples = 256;        // render.samples
inline constexpr double kMaxFrayLength = 2.0;  // render.fray_length, in cells
inline constexpr int kMaxPrefixLength = 64;    // output.prefix, in characters

struct RenderSettings {
  int width = 1280;
  int height = 720;
  int samples = 4;                               // rays per pixel (anti-aliasing, soft shadows)
  Vec3d background{0.17, 0.19, 0.22};            // sRGB
  Vec3d paper_color{0.93, 0.91, 0.86};           // sRGB, the unprinted fibre colour
  double exposure = 1.0;
  bool fray = true;                              // torn faces drawn as frayed fibres
  double fray_length = 0.45;                     // how far fibres stick out, in cell sizes
  double layer_opacity = 0.7;                    // opacity of a peeled skin one layer thick
  CameraSettings camera;
  LightSettings light;
  PrintSettings print;
};

// Reads the render tables of a scene (`root` is the whole scene file; other tables are left
// to their own readers). A relative print image is taken relative to `base_dir` (the scene
// file's folder). Throws papertear::SceneError naming the key for an unknown key (with the
// nearest known one suggested), a wrong type, or an impossible value.
RenderSettings parse_render_settings(const toml::table& root,
                                     const std::filesystem::path& base_dir = {});

// Checks the values of settings built in code; throws SceneError like the parser.
void validate(const RenderSettings& settings);

// The keys parse_render_settings reads, dotted ("render.width", ...): for a scene reader
// that checks the whole file's keys at once.
const std::vector<std::string>& render_setting_keys();

}  // namespace papertear::render
