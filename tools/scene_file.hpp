// Scene files: a TOML file whose keys are papertear::Scene's fields by dotted name
// (tools/scene_fields.hpp), plus sections for the renderer, plus --set overrides.
//
//   [sheet]     cells = [90, 90, 5]
//   [material]  preset = "washi"      # applied first; the other material keys override it
//   [run]       dt = "auto"
//   [render] [camera] [light] [print] [output]   # not read here: handed to the renderer
//
// Resolution order: parse the file; put every --set value into the document (so a value
// given on the command line is checked exactly like one in the file); reject unknown keys;
// apply material.preset; read every other key; papertear::validate(). Any failure throws
// papertear::SceneError with one line naming the place and the key.
#pragma once
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <toml++/toml.h>

#include "core/scene.hpp"

namespace papertear::io {

// Every Scene key by dotted name, in file order ("sheet.cells", ..., "run.max_splits_per_step").
const std::vector<std::string>& scene_keys();
// Top-level sections that belong to the renderer and are passed through untouched.
const std::vector<std::string>& renderer_sections();

// One --set argument, split at its first '='.
struct SetOverride {
  std::string key;     // dotted, e.g. "sheet.cells"
  std::string value;   // as typed, e.g. "[30,30,5]"
  std::string origin;  // how errors name it; empty: "--set key=value" (e.g. "--steps 20")
  std::string argument() const { return key + "=" + value; }
  std::string source() const { return origin.empty() ? "--set " + argument() : origin; }
};

// Splits "key=value". Throws SceneError for a missing '=', an empty value, or a key that is
// not dot-separated bare words.
SetOverride parse_set_argument(std::string_view argument);

// Puts an override's value into a TOML document at its dotted key, creating tables on the
// way. The value is read as a TOML value (42, 1.5, [30, 30, 5], "text", true, nan); a bare
// word that is not TOML is taken as a string (y, washi, auto, frames/out.png). Values keep
// override_.source() as their source, so later errors name the argument. Throws SceneError.
void apply_override(toml::table& document, const SetOverride& override_);

struct SceneFile {
  Scene scene;                // resolved and validated
  toml::table render_config;  // the renderer's sections as written (with --set applied);
                              // nodes keep their source, so io::where() locates them
  std::string path;           // the scene file; empty for the built-in default
  toml::table document;       // the scene's own sections as read, for locating errors that
                              // only later checks find (rethrow_located)
};

// Re-throws a SceneError whose message starts with a key ("run.dt: ...") with the place
// that key was written in the file or on the command line, when it was written at all.
[[noreturn]] void rethrow_located(const SceneError& e, const SceneFile& file);

// Reads a scene file. Throws SceneError (missing file, syntax error with line and column,
// unknown key, wrong type, impossible value).
SceneFile load_scene_file(const std::string& path, std::span<const SetOverride> overrides = {});
// The same from text; `source_name` names it in errors (may be empty).
SceneFile parse_scene(std::string_view text, std::string_view source_name,
                      std::span<const SetOverride> overrides = {});
// The built-in default scene (the paper's experiment) with overrides applied.
SceneFile default_scene_file(std::span<const SetOverride> overrides = {});

// Every key of a scene as a TOML document that parse_scene reads back to the same scene.
toml::table scene_to_toml(const Scene& scene);

}  // namespace papertear::io
