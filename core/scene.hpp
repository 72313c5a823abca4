// A scene: everything that defines a run. Plain data with defaults that are the paper's
// experiment (90 × 90 × 5 cells, fibres along x, gripped left and right and pulled apart).
// Units are the lattice's own: lengths in cell sizes, mass in cell masses, so the defaults
// do not depend on a physical scale. tools/ reads it from TOML; embedders fill it in code.
#pragma once
#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace papertear {

// A scene that cannot be run. The message starts with the dotted key at fault.
struct SceneError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct SheetParams {
  std::array<int, 3> cells{90, 90, 5};             // sheet.cells: nx, ny, layers
  std::array<double, 3> cell_size{1.0, 1.0, 1.0};  // sheet.cell_size: hx, hy, hz
  double density = 1.0;                            // sheet.density: mass per unit volume
};

// Material: elasticity (MODEL.md §4), fibre blocks (§3) and strength (§5). A preset fills
// every value; the scene may then override any of them.
struct MaterialParams {
  std::string preset = "copy";   // copy | coated | washi | kraft
  char grain = 'x';              // machine direction: 'x' or 'y'
  // Elasticity: stiffness of one cell's spring of each family, and damping along springs.
  double k_edge = 1.0;
  double k_face = 0.5;
  double k_body = 0.5;
  double damping = 0.2;          // c = damping * k (a relative rate, in 1/time): damps the
                                 // stress waves each split sends out, so cracks stay sharp
  double grain_stiffness = 1.5;  // edge stiffness along the grain / across it
  // Fibre blocks: staggered bricks of cells.
  double fiber_length = 4.0;        // mean block length along the grain, in cells
  double fiber_length_sigma = 0.4;  // sigma of the log-normal length distribution
  int block_width = 2;              // blocks are 1..block_width cells across the grain
  int block_depth = 2;              // and 1..block_depth layers deep
  double block_stiffness = 0.3;     // coarse block-lattice spring stiffness, relative
  // Strength: the edge strain (|d| - L0) / L0 at which a bond opens.
  double strain_intra = 0.12;    // inside a block
  double strain_inter = 0.10;    // between blocks (fibre-to-fibre bonding)
  double strain_layer = 0.20;    // between layers (different blocks)
  double strain_surface = 0.20;  // between the top layer and the one below (coated: weak)
  double grain_strength = 1.3;   // strength of faces normal to the grain / of the others
  double strength_jitter = 0.05; // relative spread of the per-block strength factor
};

struct LoadParams {
  std::string kind = "pull";  // pull: grips at both ends of `axis` move apart; none: free;
                              // pierce: a rigid indenter pushed through a clamped sheet;
                              // tear: two grips by a notch move apart out of plane (mode III)
  char axis = 'x';            // the pulling direction (tear: the axis the two grips sit on)
  int grip_cells = 2;         // each grip holds this many cell columns at its end
  double speed = 0.05;        // each grip's speed, in cell sizes per unit time
  double ramp_time = 20.0;    // grips accelerate linearly to `speed` over this time
  int grip_margin = 4;        // bonds this many cells beyond each grip never break: the
                              // specimen's tabs, so it fails in its body and not at the clamp
  int notch = 4;              // a cut this many cells deep at the middle of one side edge,
                              // across the pull (every real sheet has such a flaw; 0: none)
  // Pierce (core/contact.hpp): a rigid round-nosed indenter moving along -z at `speed`.
  std::string indenter = "sphere";      // sphere: a ball on a rod; cone: a cone, rounded tip
  double indenter_radius = 3.0;         // the ball's (the cone tip's) radius, in cells
  double indenter_angle = 30.0;         // cone: half-angle in degrees (0 < angle < 90)
  std::array<double, 2> indenter_at{0.5, 0.5};  // axis position, fractions of the sheet's x, y
  double contact_stiffness = 10.0;      // penalty stiffness, relative to material.k_edge
};

struct WorldParams {
  std::array<double, 3> gravity{0.0, 0.0, 0.0};
  double drag = 0.0;  // global velocity drag, 1/time (it resists the pull itself: a stress
                      // gradient that makes sheets fail at the grips; keep it small)
};

struct RunParams {
  int steps = 1200;             // run.steps
  double dt = 0.0;              // run.dt: 0 means "auto" (stable limit × dt_safety)
  double dt_safety = 0.5;       // run.dt_safety
  int frames = 30;              // run.frames: how many frames the CLI writes
  std::uint64_t seed = 1;       // run.seed: block layout and strength jitter
  int max_splits_per_step = 0;  // run.max_splits_per_step: 0 = no cap
};

// A line drawn on the sheet to steer a tear: a `[[line]]` table in a scene file. A polyline
// in cell units measured from the sheet's corner (x along sheet.cells[0], y along
// sheet.cells[1]); it acts on every in-plane bond whose segment between the two cell centres
// it crosses (fracture/lines.hpp), in the top `depth` layers.
struct LineParams {
  std::string kind = "score";                 // cut: opened before the first step;
                                              // score: weakened; perforation: cut holes, lands
  std::vector<std::array<double, 2>> points;  // >= 2 points within [0, nx] x [0, ny]
  double strength = 0.5;  // factor on the opening strain of every crossed bond left uncut
  int depth = 0;          // layers from the top surface the line acts on; 0: all layers
  double pitch = 4.0;     // perforation: cells along the line per hole and land
  double duty = 0.5;      // perforation: fraction of each pitch cut through

  bool operator==(const LineParams&) const = default;
};

struct Scene {
  SheetParams sheet;
  MaterialParams material;
  LoadParams load;
  WorldParams world;
  RunParams run;
  std::vector<LineParams> lines;  // applied in this order after the notch (empty: none)
};

// Fills every material value from a named preset (copy, coated, washi, kraft). Throws
// SceneError naming material.preset for an unknown name.
void apply_material_preset(MaterialParams& material, const std::string& name);
// The names apply_material_preset accepts, in a fixed order.
const std::array<const char*, 4>& material_preset_names();

// The kinds a LineParams may have, in a fixed order.
const std::array<const char*, 3>& line_kind_names();

// Throws SceneError ("<key>: <what is wrong>") for the first impossible value: sizes that
// are zero or negative, non-finite numbers, unknown grain or load kind, a sheet too large
// for memory... The time step is checked against the stable limit by the Simulation.
void validate(const Scene& scene);

}  // namespace papertear
