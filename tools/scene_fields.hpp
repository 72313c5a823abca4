// The one list of every papertear::Scene field and its dotted key in a scene file. Reading
// TOML, writing TOML and writing JSON all walk this list, so a field added to core/scene.hpp
// needs one line here and nothing else in tools/.
#pragma once
#include <string>
#include <type_traits>

#include "core/scene.hpp"

namespace papertear::io {

// run.dt is a number or "auto" (stored as 0): readers and writers treat it apart.
template <class D>
struct AutoOrNumber {
  D& value;
};
template <class D>
AutoOrNumber<D> auto_or_number(D& value) { return {value}; }

// Calls visit(key, field) for every field, in file order. SceneT is Scene or const Scene.
template <class SceneT, class Visitor>
  requires std::is_same_v<std::remove_const_t<SceneT>, Scene>
void visit_scene_fields(SceneT& s, Visitor&& visit) {
  visit("sheet.cells", s.sheet.cells);
  visit("sheet.cell_size", s.sheet.cell_size);

  visit("material.preset", s.material.preset);
  visit("material.grain", s.material.grain);
  visit("material.E_md", s.material.E_md);
  visit("material.E_cd", s.material.E_cd);
  visit("material.E_zd", s.material.E_zd);
  visit("material.G_md_cd", s.material.G_md_cd);
  visit("material.G_md_zd", s.material.G_md_zd);
  visit("material.G_cd_zd", s.material.G_cd_zd);
  visit("material.density", s.material.density);
  visit("material.damping", s.material.damping);
  visit("material.fiber_length", s.material.fiber_length);
  visit("material.fiber_length_sigma", s.material.fiber_length_sigma);
  visit("material.block_width", s.material.block_width);
  visit("material.block_depth", s.material.block_depth);
  visit("material.block_stiffness", s.material.block_stiffness);
  visit("material.strain_intra", s.material.strain_intra);
  visit("material.strain_inter", s.material.strain_inter);
  visit("material.strain_layer", s.material.strain_layer);
  visit("material.strain_surface", s.material.strain_surface);
  visit("material.grain_strength", s.material.grain_strength);
  visit("material.cross_stretch", s.material.cross_stretch);
  visit("material.strength_jitter", s.material.strength_jitter);
  visit("material.tip_strength", s.material.tip_strength);
  visit("material.bridge_time", s.material.bridge_time);

  visit("load.kind", s.load.kind);
  visit("load.axis", s.load.axis);
  visit("load.grip_cells", s.load.grip_cells);
  visit("load.speed", s.load.speed);
  visit("load.ramp_time", s.load.ramp_time);
  visit("load.grip_margin", s.load.grip_margin);
  visit("load.notch", s.load.notch);
  visit("load.indenter", s.load.indenter);
  visit("load.indenter_radius", s.load.indenter_radius);
  visit("load.indenter_angle", s.load.indenter_angle);
  visit("load.indenter_at", s.load.indenter_at);
  visit("load.contact_stiffness", s.load.contact_stiffness);

  visit("world.gravity", s.world.gravity);
  visit("world.drag", s.world.drag);

  visit("run.steps", s.run.steps);
  visit("run.dt", auto_or_number(s.run.dt));
  visit("run.dt_safety", s.run.dt_safety);
  visit("run.frames", s.run.frames);
  visit("run.seed", s.run.seed);
  visit("run.max_splits_per_step", s.run.max_splits_per_step);

  // A top-level array of tables ([[line]]): each element's fields by visit_line_fields.
  visit("line", s.lines);
}

// Calls visit(name, field) for every field of one [[line]] table, in file order. LineT is
// LineParams or const LineParams.
template <class LineT, class Visitor>
  requires std::is_same_v<std::remove_const_t<LineT>, LineParams>
void visit_line_fields(LineT& l, Visitor&& visit) {
  visit("kind", l.kind);
  visit("points", l.points);
  visit("strength", l.strength);
  visit("depth", l.depth);
  visit("pitch", l.pitch);
  visit("duty", l.duty);
}

// "line[2]": how errors and dotted paths name the element at `index`.
inline std::string line_name(std::size_t index) { return "line[" + std::to_string(index) + "]"; }

}  // namespace papertear::io
