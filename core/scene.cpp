#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <unistd.h>

#include "core/memory_estimate.hpp"
#include "core/scene.hpp"

namespace papertear {

const std::array<const char*, 4>& material_preset_names() {
  static constexpr std::array<const char*, 4> names = {"copy", "coated", "washi", "kraft"};
  return names;
}

// Presets (MODEL.md §1, §3). Strengths are edge strains at which a bond opens; the ratios
// between them are what shapes a tear: weak block boundaries make cracks follow blocks,
// long blocks (washi, kraft) make them wander further along the fibres before crossing.
void apply_material_preset(MaterialParams& m, const std::string& name) {
  MaterialParams base;  // the defaults are the `copy` preset
  base.grain = m.grain;
  if (name == "copy") {
    // short wood-pulp fibres, firm layers
  } else if (name == "coated") {
    // copy paper with a coating: denser and stiffer, and the bond under the top layer is
    // weak, so it peels
    base.E_md = 6500.0;
    base.E_cd = 3000.0;
    base.G_md_cd = 1700.0;
    base.density = 1100.0;
    base.strain_surface = 0.05;
  } else if (name == "washi") {
    // long kozo fibres: a light, open sheet (soft), long blocks with large spread, strong
    // inside, loose between
    base.E_md = 3000.0;
    base.E_cd = 1500.0;
    base.E_zd = 15.0;
    base.G_md_cd = 850.0;
    base.G_md_zd = 50.0;
    base.G_cd_zd = 40.0;
    base.density = 450.0;
    base.fiber_length = 16.0;
    base.fiber_length_sigma = 0.6;
    base.block_width = 2;
    base.strain_intra = 0.20;
    base.strain_inter = 0.08;
    base.strength_jitter = 0.2;
    base.grain_strength = 1.5;
  } else if (name == "kraft") {
    // long, strong softwood fibres; a tear across them has to break them (docs/calibration.md:
    // with the default grain strength the tear across the grain cost no more than along it)
    base.fiber_length = 10.0;
    base.grain_strength = 1.6;
    base.cross_stretch = 1.15;  // 1.3 let the tear along its long blocks cost more than
                                // across them (CD/MD tear 0.63, docs/calibration.md)
    base.strain_intra = 0.18;
    base.strain_inter = 0.14;
    base.strain_layer = 0.25;
    base.strain_surface = 0.25;
    base.E_md = 7500.0;
    base.E_cd = 3300.0;
    base.E_zd = 40.0;
    base.G_md_cd = 1800.0;
    base.G_md_zd = 120.0;
    base.G_cd_zd = 90.0;
    base.density = 700.0;
  } else {
    std::string list;
    for (const char* n : material_preset_names()) list += std::string(list.empty() ? "" : ", ") + n;
    throw SceneError("material.preset: unknown preset '" + name + "' (known: " + list + ")");
  }
  base.preset = name;
  m = base;
}

namespace {

void require(bool ok, const char* key, const std::string& what) {
  if (!ok) throw SceneError(std::string(key) + ": " + what);
}
void positive(double v, const char* key) {
  require(std::isfinite(v), key, "must be a finite number");
  require(v > 0.0, key, "must be greater than 0 (got " + std::to_string(v) + ")");
}
void non_negative(double v, const char* key) {
  require(std::isfinite(v), key, "must be a finite number");
  require(v >= 0.0, key, "must not be negative (got " + std::to_string(v) + ")");
}

// A number for a message: whole numbers without a fraction, others as %g.
std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

// "<key>: <what> <bound> (got <value>)" when the value is above its bound.
template <class T, class B>
void at_most(T value, B bound, const char* key, const char* what = "must be at most") {
  require(value <= bound, key, std::string(what) + " " + number_text(double(bound)) + " (got " + number_text(double(value)) + ")");
}

void validate_sheet(const SheetParams& s) {
  const char* keys[3] = {"sheet.cells[0] (nx)", "sheet.cells[1] (ny)", "sheet.cells[2] (layers)"};
  for (int a = 0; a < 3; ++a)
    require(s.cells[std::size_t(a)] >= 1, keys[a],
            "must be at least 1 (got " + std::to_string(s.cells[std::size_t(a)]) + ")");
  at_most(s.cells[0], limits::kMaxCellsAlong, keys[0]);
  at_most(s.cells[1], limits::kMaxCellsAlong, keys[1]);
  at_most(s.cells[2], limits::kMaxLayers, keys[2]);
  at_most(std::int64_t(s.cells[0]) * s.cells[1] * s.cells[2], limits::kMaxCells, "sheet.cells",
          "nx * ny * layers must be at most");
  for (int a = 0; a < 3; ++a) positive(s.cell_size[std::size_t(a)], "sheet.cell_size");
  const std::uint64_t bytes = estimate_memory_bytes(s);
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  if (pages > 0 && page > 0) {
    const std::uint64_t phys = std::uint64_t(pages) * std::uint64_t(page);
    require(bytes < phys, "sheet.cells",
            "the sheet needs about " + std::to_string(bytes >> 20) + " MiB, more than this machine's " +
                std::to_string(phys >> 20) + " MiB");
  }
  // Node ids are 32-bit and splits add nodes: keep room for every cell to come apart.
  require(std::uint64_t(s.cells[0]) * std::uint64_t(s.cells[1]) * std::uint64_t(s.cells[2]) * 8u <
              std::uint64_t(UINT32_MAX),
          "sheet.cells", "too many cells for 32-bit node ids");
}

void validate_material(const MaterialParams& m) {
  require(m.grain == 'x' || m.grain == 'y', "material.grain", "must be \"x\" or \"y\"");
  positive(m.E_md, "material.E_md");
  positive(m.E_cd, "material.E_cd");
  positive(m.E_zd, "material.E_zd");
  positive(m.G_md_cd, "material.G_md_cd");
  positive(m.G_md_zd, "material.G_md_zd");
  positive(m.G_cd_zd, "material.G_cd_zd");
  positive(m.density, "material.density");
  non_negative(m.damping, "material.damping");
  require(std::isfinite(m.fiber_length) && m.fiber_length >= 1.0, "material.fiber_length",
          "must be at least 1 cell");
  at_most(m.fiber_length, limits::kMaxFibreLength, "material.fiber_length");
  at_most(m.block_width, limits::kMaxBlockSize, "material.block_width");
  at_most(m.block_depth, limits::kMaxBlockSize, "material.block_depth");
  non_negative(m.fiber_length_sigma, "material.fiber_length_sigma");
  require(m.block_width >= 1, "material.block_width", "must be at least 1");
  require(m.block_depth >= 1, "material.block_depth", "must be at least 1");
  non_negative(m.block_stiffness, "material.block_stiffness");
  require(m.block_stiffness < 1.0, "material.block_stiffness",
          "is the share of the edge stiffness the block lattice carries: must be below 1");
  positive(m.strain_intra, "material.strain_intra");
  positive(m.strain_inter, "material.strain_inter");
  positive(m.strain_layer, "material.strain_layer");
  positive(m.strain_surface, "material.strain_surface");
  positive(m.grain_strength, "material.grain_strength");
  positive(m.cross_stretch, "material.cross_stretch");
  non_negative(m.strength_jitter, "material.strength_jitter");
  require(m.strength_jitter < 1.0, "material.strength_jitter", "must be below 1");
  positive(m.tip_strength, "material.tip_strength");
  require(m.tip_strength <= 1.0, "material.tip_strength", "must not be above 1");
  require(m.bridge_time >= 0.0 && m.bridge_time <= 1000.0, "material.bridge_time", "must be in [0, 1000]");
}

// The indenter keys are checked whatever the load, so a typo never waits for a pierce run.
void validate_indenter(const LoadParams& l) {
  require(l.indenter == "sphere" || l.indenter == "cone", "load.indenter",
          "must be \"sphere\" or \"cone\" (got \"" + l.indenter + "\")");
  positive(l.indenter_radius, "load.indenter_radius");
  require(std::isfinite(l.indenter_angle) && l.indenter_angle > 0.0 && l.indenter_angle < 90.0,
          "load.indenter_angle", "must be between 0 and 90 degrees (got " + std::to_string(l.indenter_angle) + ")");
  for (double f : l.indenter_at)
    require(std::isfinite(f) && f >= 0.0 && f <= 1.0, "load.indenter_at",
            "must be fractions of the sheet between 0 and 1 (got " + std::to_string(f) + ")");
  positive(l.contact_stiffness, "load.contact_stiffness");
}

void validate_pull(const LoadParams& l, const SheetParams& s) {
  const int n = s.cells[l.axis == 'y' ? 1 : 0];
  require(l.grip_cells >= 1, "load.grip_cells", "must be at least 1");
  require(2 * l.grip_cells < n, "load.grip_cells",
          "the two grips (" + std::to_string(l.grip_cells) + " cells each) must leave free cells between them on a sheet " +
              std::to_string(n) + " cells long");
  const int across = s.cells[l.axis == 'y' ? 0 : 1];
  require(l.notch < across, "load.notch",
          "a notch of " + std::to_string(l.notch) + " cells would cut the sheet (" + std::to_string(across) + " cells across)");
}

void validate_pierce(const LoadParams& l, const SheetParams& s) {
  const int n = std::min(s.cells[0], s.cells[1]);
  require(l.grip_cells >= 1, "load.grip_cells", "must be at least 1");
  require(2 * l.grip_cells < n, "load.grip_cells",
          "the clamp (" + std::to_string(l.grip_cells) + " cells wide) must leave free cells inside it on a sheet " +
              std::to_string(n) + " cells across");
}

// The two fingers (core/lattice_builder.hpp, tear_grips) must fit on the sheet.
void validate_tear(const LoadParams& l, const SheetParams& s) {
  const int n = s.cells[l.axis == 'y' ? 1 : 0], across = s.cells[l.axis == 'y' ? 0 : 1];
  require(l.grip_cells >= 1, "load.grip_cells", "must be at least 1");
  require(l.grip_cells < across, "load.grip_cells",
          "the grips (" + std::to_string(l.grip_cells) + " cells deep) must leave free cells on a sheet " +
              std::to_string(across) + " cells across");
  require(n / 2 - l.grip_margin - l.grip_cells >= 0, "load.grip_margin",
          "two grips of " + std::to_string(l.grip_cells) + " cells, " + std::to_string(l.grip_margin) +
              " cells each side of the middle, do not fit on a sheet " + std::to_string(n) + " cells long");
  require(l.notch < across, "load.notch",
          "a notch of " + std::to_string(l.notch) + " cells would cut the sheet (" + std::to_string(across) + " cells across)");
}

void validate_load(const LoadParams& l, const SheetParams& s) {
  require(l.kind == "pull" || l.kind == "none" || l.kind == "pierce" || l.kind == "tear", "load.kind",
          "must be \"pull\", \"pierce\", \"tear\" or \"none\"");
  require(l.axis == 'x' || l.axis == 'y', "load.axis", "must be \"x\" or \"y\"");
  require(std::isfinite(l.speed), "load.speed", "must be a finite number");
  non_negative(l.ramp_time, "load.ramp_time");
  require(l.notch >= 0, "load.notch", "must not be negative");
  require(l.grip_margin >= 0, "load.grip_margin", "must not be negative");
  validate_indenter(l);
  if (l.kind == "pull") validate_pull(l, s);
  if (l.kind == "pierce") validate_pierce(l, s);
  if (l.kind == "tear") validate_tear(l, s);
}

// Lines are named by their index in the scene: "line[2].points".
void validate_line(const LineParams& line, std::size_t index, const SheetParams& s) {
  const std::string prefix = "line[" + std::to_string(index) + "].";
  auto key = [&](const char* field) { return prefix + field; };
  bool known = false;
  for (const char* k : line_kind_names()) known = known || line.kind == k;
  require(known, key("kind").c_str(), "must be \"cut\", \"score\" or \"perforation\" (got \"" + line.kind + "\")");
  require(line.points.size() >= 2, key("points").c_str(),
          "needs at least 2 points (got " + std::to_string(line.points.size()) + ")");
  at_most(line.points.size(), limits::kMaxLinePoints, key("points").c_str(), "may have at most");
  const double nx = s.cells[0], ny = s.cells[1];
  for (std::size_t i = 0; i < line.points.size(); ++i) {
    const auto& p = line.points[i];
    require(std::isfinite(p[0]) && std::isfinite(p[1]) && p[0] >= 0.0 && p[0] <= nx && p[1] >= 0.0 && p[1] <= ny,
            key("points").c_str(),
            "point " + std::to_string(i) + " (" + std::to_string(p[0]) + ", " + std::to_string(p[1]) +
                ") lies outside the sheet [0, " + std::to_string(s.cells[0]) + "] x [0, " + std::to_string(s.cells[1]) + "]");
  }
  require(std::isfinite(line.strength) && line.strength > 0.0 && line.strength <= 1.0, key("strength").c_str(),
          "must be in (0, 1] (got " + std::to_string(line.strength) + ")");
  require(line.depth >= 0 && line.depth <= s.cells[2], key("depth").c_str(),
          "must be 0 (all layers) to " + std::to_string(s.cells[2]) + " (got " + std::to_string(line.depth) + ")");
  positive(line.pitch, key("pitch").c_str());
  require(line.pitch >= limits::kMinPitch, key("pitch").c_str(),
          "must be at least " + number_text(limits::kMinPitch) + " cells (got " + number_text(line.pitch) + ")");
  require(std::isfinite(line.duty) && line.duty >= 0.0 && line.duty <= 1.0, key("duty").c_str(),
          "must be in [0, 1] (got " + std::to_string(line.duty) + ")");
}

}  // namespace

const std::vector<SceneLimit>& scene_limits() {
  using namespace limits;
  static const std::vector<SceneLimit> table = {
      {"sheet.cells[0], sheet.cells[1]", kMaxCellsAlong, "cells along x and along y"},
      {"sheet.cells[2]", kMaxLayers, "layers"},
      {"sheet.cells", double(kMaxCells), "cells in all (and the machine's memory)"},
      {"run.steps", kMaxSteps, "steps"},
      {"run.frames", kMaxFrames, "frames (a run writes at most one per step)"},
      {"line", double(kMaxLines), "[[line]] tables"},
      {"line.points", double(kMaxLinePoints), "points per line"},
      {"line.pitch", kMinPitch, "cells per perforation hole and land, at least"},
      {"material.fiber_length", kMaxFibreLength, "cells, mean block length"},
      {"material.block_width, block_depth", kMaxBlockSize, "cells"},
      {"--threads", kMaxThreads, "worker threads"},
  };
  return table;
}

const std::array<const char*, 3>& line_kind_names() {
  static constexpr std::array<const char*, 3> names = {"cut", "score", "perforation"};
  return names;
}

void validate(const Scene& scene) {
  validate_sheet(scene.sheet);
  validate_material(scene.material);
  validate_load(scene.load, scene.sheet);
  for (double g : scene.world.gravity) require(std::isfinite(g), "world.gravity", "must be finite");
  non_negative(scene.world.drag, "world.drag");
  require(scene.run.steps >= 0, "run.steps", "must not be negative");
  at_most(scene.run.steps, limits::kMaxSteps, "run.steps");
  non_negative(scene.run.dt, "run.dt");
  positive(scene.run.dt_safety, "run.dt_safety");
  require(scene.run.dt_safety <= 1.0, "run.dt_safety", "must be at most 1");
  require(scene.run.frames >= 1, "run.frames", "must be at least 1");
  at_most(scene.run.frames, limits::kMaxFrames, "run.frames");
  require(scene.run.max_splits_per_step >= 0, "run.max_splits_per_step", "must not be negative");
  at_most(scene.lines.size(), limits::kMaxLines, "line", "a scene may have at most");
  for (std::size_t i = 0; i < scene.lines.size(); ++i) validate_line(scene.lines[i], i, scene.sheet);
}

}  // namespace papertear
