// Short standard scenes shared by the golden-digest test and the cross-instruction-set check
// (tests/simd/): an intact sheet (pure elasticity, with gravity), a tearing one and a peeling
// one, a wider tearing one (20 cells of a colour per row: with 16-lane vectors its rows hold
// whole vector groups, which the 24-cell rows of the others do not) and a narrower one (7
// cells of a colour per row: shorter than a vector of 8 or 16). Small enough to run in a
// second each.
#pragma once
#include <array>

#include "core/scene.hpp"

namespace papertear::standard {

inline Scene small(const char* preset) {
  Scene s;
  apply_material_preset(s.material, preset);
  s.sheet.cells = {24, 16, 3};
  s.load.grip_cells = 2;
  s.load.grip_margin = 2;
  s.load.notch = 3;
  s.load.speed = 0.15;
  s.load.ramp_time = 5.0;
  return s;
}

struct StandardScene {
  const char* name;
  Scene scene;
  int steps;
};

inline std::array<StandardScene, 5> scenes() {
  Scene intact = small("copy");
  intact.load.speed = 0.002;  // stays intact: a fifth of the strain rate that tears the others
  intact.world.gravity = {0.0, 0.0, -0.0001};  // mm/µs²: a load to sag under, not to break
  Scene wide = small("washi"), narrow = small("washi");
  wide.sheet.cells = {40, 12, 3};
  narrow.sheet.cells = {14, 16, 3};
  return {{{"intact", intact, 300},
           {"tearing", small("washi"), 400},
           {"peeling", small("coated"), 400},
           {"wide", wide, 200},
           {"narrow", narrow, 300}}};
}

}  // namespace papertear::standard
