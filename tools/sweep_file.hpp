// Sweep files: a parameter study as a list of points, each a scene with overrides and a seed.
//
//   scene = "base.toml"          # optional, relative to this file; default: the built-in scene
//   seeds = [1, 2, 3]            # optional; default: the scene's run.seed (one run per point)
//   [set]                        # overrides for every point (dotted keys, as with --set)
//   run.steps = 600
//   [grid]                       # dotted key -> list of values: the cartesian product
//   material.fiber_length = [4, 8, 16]
//   material.block_width = [1, 2, 4]
//   # or instead of [grid], a list of override sets:
//   [[point]]
//   material.preset = "washi"
//
// The points are numbered in a stable order: grid keys in the order they are written (the
// first key varies slowest), or the [[point]] tables in file order; seeds innermost. A point
// is resolved exactly like `papertear run BASE --set <[set]>... --set <point>... --set
// run.seed=<seed>`, so its digest is the one that run prints.
#pragma once
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "tools/scene_file.hpp"

namespace papertear::io {

// More points than this is a mistake in the file (a grid with a runaway key), not a study.
inline constexpr std::size_t kMaxSweepPoints = 100'000;

// One overridden key of a point: the value as --set text and as JSON (for the result rows).
struct SweepValue {
  std::string key;     // dotted scene key
  std::string toml;    // TOML text, e.g. 8, 0.25, "washi", [12, 12, 2]
  nlohmann::json json;
  std::string where;   // "study.toml:7:24", for errors
};

struct SweepPoint {
  int index = 0;
  std::vector<SweepValue> values;  // the point's own overrides (grid values or [[point]] keys)
  std::optional<std::uint64_t> seed;  // from `seeds`; empty: the scene's run.seed
};

struct SweepDefinition {
  std::filesystem::path path;        // the sweep file
  std::string scene_path;            // resolved base scene file; empty: the built-in default
  std::vector<SweepValue> common;    // [set]
  std::vector<std::string> keys;     // the swept keys, in column order
  bool seeded = false;               // `seeds` was given
  std::vector<SweepPoint> points;
};

// Reads and checks a sweep file: syntax, known top-level keys, known scene keys, non-empty
// lists. Throws SceneError naming the file, place and problem. Does not resolve the scenes.
SweepDefinition load_sweep(const std::filesystem::path& path);
// The same from text already read; `path` names the file in messages and anchors a relative
// base scene.
SweepDefinition parse_sweep(std::string_view text, const std::filesystem::path& path);

// The --set overrides that make point `p`'s scene from the base scene.
std::vector<SetOverride> point_overrides(const SweepDefinition& sweep, const SweepPoint& p);

// The point's resolved scene. Throws SceneError prefixed with the point and where its value
// was written.
SceneFile resolve_point(const SweepDefinition& sweep, const SweepPoint& p);

// A hash of what the sweep computes: every point's index, overrides and resolved scene
// (`scenes[i]` is resolve_point of point i). Point files carry it, so that --collect refuses
// files of another sweep (or of an edited base scene).
std::uint64_t sweep_hash(const SweepDefinition& sweep, std::span<const SceneFile> scenes);

}  // namespace papertear::io
