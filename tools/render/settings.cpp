#include "tools/render/settings.hpp"

#include <cmath>
#include <string>

#include "core/scene.hpp"
#include "tools/toml_keys.hpp"

namespace papertear::render {

namespace {

const toml::node* member(const toml::table* table, std::string_view key) {
  return table ? table->get(key) : nullptr;
}

// "#rrggbb" or [r, g, b] with each component in [0, 1].
Vec3d read_colour(const toml::node& node, const std::string& key) {
  if (node.is_string()) {
    const std::string text = io::read_string(node, key);
    Vec3d rgb{};
    const bool hex = text.size() == 7 && text[0] == '#' &&
                     text.find_first_not_of("0123456789abcdefABCDEF", 1) == std::string::npos;
    if (!hex) io::fail_at(node, key, "expected a colour \"#rrggbb\" or [r, g, b], got \"" + text + "\"");
    for (std::size_t c = 0; c < 3; ++c)
      rgb[c] = double(std::stoi(text.substr(1 + 2 * c, 2), nullptr, 16)) / 255.0;
    return rgb;
  }
  const Vec3d rgb = io::read_number3(node, key);
  for (double v : rgb)
    if (v < 0.0 || v > 1.0) io::fail_at(node, key, "colour components must be in [0, 1]");
  return rgb;
}

double read_range(const toml::node& node, const std::string& key, double lo, double hi) {
  const double v = io::read_number(node, key);
  if (v < lo || v > hi)
    io::fail_at(node, key, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return v;
}

int read_int_range(const toml::node& node, const std::string& key, int lo, int hi) {
  const int v = io::read_int(node, key);
  if (v < lo || v > hi)
    io::fail_at(node, key, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return v;
}

// Applies `read` to a key when it is present.
template <class Read>
void with(const toml::table* table, const char* section, const char* key, Read&& read) {
  if (const toml::node* n = member(table, key)) read(*n, std::string(section) + "." + key);
}

void read_render(const toml::table* t, RenderSettings& s) {
  with(t, "render", "width", [&](auto& n, auto k) { s.width = read_int_range(n, k, 1, kMaxImageSide); });
  with(t, "render", "height", [&](auto& n, auto k) { s.height = read_int_range(n, k, 1, kMaxImageSide); });
  with(t, "render", "samples", [&](auto& n, auto k) { s.samples = read_int_range(n, k, 1, kMaxSamples); });
  with(t, "render", "background", [&](auto& n, auto k) { s.background = read_colour(n, k); });
  with(t, "render", "paper_color", [&](auto& n, auto k) { s.paper_color = read_colour(n, k); });
  with(t, "render", "exposure", [&](auto& n, auto k) { s.exposure = read_range(n, k, 0.0, 100.0); });
  with(t, "render", "fray", [&](auto& n, auto k) { s.fray = io::read_bool(n, k); });
  with(t, "render", "fray_length", [&](auto& n, auto k) { s.fray_length = read_range(n, k, 0.0, kMaxFrayLength); });
  with(t, "render", "layer_opacity", [&](auto& n, auto k) { s.layer_opacity = read_range(n, k, 0.0, 1.0); });
}

void read_camera(const toml::table* t, CameraSettings& c) {
  with(t, "camera", "position", [&](auto& n, auto k) { c.position = io::read_number3(n, k); });
  with(t, "camera", "target", [&](auto& n, auto k) { c.target = io::read_number3(n, k); });
  with(t, "camera", "up", [&](auto& n, auto k) { c.up = io::read_number3(n, k); });
  with(t, "camera", "fov", [&](auto& n, auto k) { c.fov = read_range(n, k, 1.0, 170.0); });
}

void read_light(const toml::table* t, LightSettings& l) {
  with(t, "light", "direction", [&](auto& n, auto k) { l.direction = io::read_number3(n, k); });
  with(t, "light", "intensity", [&](auto& n, auto k) { l.intensity = read_range(n, k, 0.0, 100.0); });
  with(t, "light", "ambient", [&](auto& n, auto k) { l.ambient = read_range(n, k, 0.0, 100.0); });
  with(t, "light", "softness", [&](auto& n, auto k) { l.softness = read_range(n, k, 0.0, 0.5); });
}

void read_print(const toml::table* t, PrintSettings& p, const std::filesystem::path& base_dir) {
  with(t, "print", "enabled", [&](auto& n, auto k) { p.enabled = io::read_bool(n, k); });
  with(t, "print", "image", [&](auto& n, auto k) {
    const std::string file = io::read_string(n, k);
    if (file.empty()) io::fail_at(n, k, "must name a PNG file (leave the key out for the built-in print)");
    const std::filesystem::path path(file);
    p.image = path.is_absolute() || base_dir.empty() ? path : base_dir / path;
  });
}

double length(const Vec3d& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

[[noreturn]] void fail(const std::string& key, const std::string& problem) {
  throw SceneError(key + ": " + problem);
}

}  // namespace

const std::vector<std::string>& render_setting_keys() {
  static const std::vector<std::string> keys = {
      "render.width", "render.height", "render.samples", "render.background",
      "render.paper_color", "render.exposure", "render.fray", "render.fray_length",
      "render.layer_opacity",
      "camera.position", "camera.target", "camera.up", "camera.fov",
      "light.direction", "light.intensity", "light.ambient", "light.softness",
      "print.image", "print.enabled"};
  return keys;
}

RenderSettings parse_render_settings(const toml::table& root, const std::filesystem::path& base_dir) {
  RenderSettings s;
  const std::vector<std::string>& known = render_setting_keys();
  const toml::table* tables[4] = {
      io::find_table(root, "render", "render"), io::find_table(root, "camera", "camera"),
      io::find_table(root, "light", "light"), io::find_table(root, "print", "print")};
  const char* names[4] = {"render", "camera", "light", "print"};
  for (int i = 0; i < 4; ++i)
    if (tables[i]) io::check_known_keys(*tables[i], names[i], known);
  read_render(tables[0], s);
  read_camera(tables[1], s.camera);
  read_light(tables[2], s.light);
  read_print(tables[3], s.print, base_dir);
  validate(s);
  return s;
}

void validate(const RenderSettings& s) {
  if (s.width < 1 || s.height < 1) fail("render.width", "the image must be at least 1 x 1 pixels");
  if (s.samples < 1) fail("render.samples", "must be at least 1");
  if (!(s.fray_length >= 0.0)) fail("render.fray_length", "must be >= 0");
  if (!(s.layer_opacity >= 0.0 && s.layer_opacity <= 1.0)) fail("render.layer_opacity", "must be in [0, 1]");
  if (!(s.camera.fov > 0.0 && s.camera.fov < 180.0)) fail("camera.fov", "must be in (0, 180) degrees");
  if (!(length(s.camera.up) > 0.0)) fail("camera.up", "must not be the zero vector");
  if (!(length(s.light.direction) > 0.0)) fail("light.direction", "must not be the zero vector");
  if (s.camera.position && s.camera.target && length({(*s.camera.position)[0] - (*s.camera.target)[0],
                                                      (*s.camera.position)[1] - (*s.camera.target)[1],
                                                      (*s.camera.position)[2] - (*s.camera.target)[2]}) == 0.0)
    fail("camera.target", "must differ from camera.position");
}

}  // namespace papertear::render
