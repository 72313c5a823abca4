// A scene: everything that defines a run. Plain data with defaults that are the default pull
// (a notched copy sheet of 120 × 80 × 3 thin cells, fibres along x, gripped left and right
// and pulled apart; tools/scenes/paper.toml).
// Units: the material in published units (MPa, kg/m³), everything else in the lattice's
// (length 1 mm, time 1 µs, mass 1 mg: core/elasticity.hpp). tools/ reads a scene from TOML;
// embedders fill it in code.
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
  std::array<int, 3> cells{120, 80, 3};            // sheet.cells: nx, ny, layers
  std::array<double, 3> cell_size{1.0, 1.0, 0.3};  // sheet.cell_size: hx, hy, hz, mm
};

// Material: elasticity (MODEL.md §4), fibre blocks (§3) and strength (§5). A preset fills
// every value; the scene may then override any of them.
struct MaterialParams {
  std::string preset = "copy";   // copy | coated | washi | kraft
  char grain = 'x';              // machine direction: 'x' or 'y'
  // Elasticity: paper's orthotropic constants, MPa (MD: along the grain, CD: across it, ZD:
  // through the thickness); the springs follow from them and the cell's shape
  // (core/elasticity.hpp). Sources: docs/calibration.md.
  double E_md = 5500.0;
  double E_cd = 2500.0;
  double E_zd = 35.0;
  double G_md_cd = 1500.0;       // in-plane shear
  double G_md_zd = 100.0;        // transverse shears
  double G_cd_zd = 80.0;
  double density = 800.0;        // kg/m³: grammage / thickness (80 g/m² at 0.1 mm)
  double damping = 0.2;          // c = damping * k (a relative rate, in 1/µs): damps the
                                 // stress waves each split sends out, so cracks stay sharp
  // Fibre blocks: staggered bricks of cells.
  double fiber_length = 4.0;        // mean block length along the grain, in cells
  double fiber_length_sigma = 0.4;  // sigma of the log-normal length distribution
  int block_width = 2;              // blocks are 1..block_width cells across the grain
  int block_depth = 2;              // and 1..block_depth layers deep
  double block_stiffness = 0.2;     // share of the edge stiffness the block lattice carries
  // Strength: the edge strain (|d| - L0) / L0 at which a bond opens.
  double strain_intra = 0.12;    // inside a block
  double strain_inter = 0.10;    // between blocks (fibre-to-fibre bonding)
  double strain_layer = 0.40;    // between layers (different blocks)
  double strain_surface = 0.40;  // between the top layer and the one below (coated: weak)
  double grain_strength = 1.3;   // strength of faces normal to the grain / of the others
  double cross_stretch = 1.3;    // strain at which tension across the grain opens a bond / along
                                 // it (paper's CD stretch at break exceeds its MD stretch)
  double strength_jitter = 0.05; // relative spread of the per-block strength factor
  double tip_strength = 0.3;     // a bond's strength at a crack tip, relative (fracture_pass.hpp)
  double bridge_time = 20.0;     // how long fibres bridge a fresh crack, in bond failure times
                                 // (fracture_pass.hpp; 0: no bridging)
};

struct LoadParams {
  std::string kind = "pull";  // pull: grips at both ends of `axis` move apart; none: free;
                              // pierce: a rigid indenter pushed through a clamped sheet;
                              // tear: two grips by a notch move apart out of plane (mode III)
  char axis = 'x';            // the pulling direction (tear: the axis the two grips sit on)
  int grip_cells = 2;         // each grip holds this many cell columns at its end
  double speed = 0.05;        // each grip's speed, mm/µs
  double ramp_time = 20.0;    // grips accelerate linearly to `speed` over this time, µs
  int grip_margin = 4;        // bonds this many cells beyond each grip never break: the
                              // specimen's tabs, so it fails in its body and not at the clamp
  int notch = 4;              // a cut this many cells deep at the middle of one side edge,
                              // across the pull (every real sheet has such a flaw; 0: none)
  // Pierce (core/contact.hpp): a rigid round-nosed indenter moving along -z at `speed`.
  std::string indenter = "sphere";      // sphere: a ball on a rod; cone: a cone, rounded tip
  double indenter_radius = 3.0;         // the ball's (the cone tip's) radius, in cells
  double indenter_angle = 30.0;         // cone: half-angle in degrees (0 < angle < 90)
  std::array<double, 2> indenter_at{0.5, 0.5};  // axis position, fractions of the sheet's x, y
  double contact_stiffness = 10.0;      // penalty stiffness, relative to the stiffest edge spring
};

struct WorldParams {
  std::array<double, 3> gravity{0.0, 0.0, 0.0};  // mm/µs² (Earth's: 9.81e-9)
  double drag = 0.0;  // global velocity drag, 1/µs (it resists the pull itself: a stress
                      // gradient that makes sheets fail at the grips; keep it small)
};

struct RunParams {
  int steps = 1200;             // run.steps
  double dt = 0.0;              // run.dt: 0 means "auto" (stable limit × dt_safety)
  double dt_safety = 0.5;       // run.dt_safety
  int frames = 30;              // run.frames: how many frames the CLI writes (at most one per step)
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

// Upper bounds on every count and size a scene may ask for. validate() checks them before
// anything is allocated or looped over, so a runaway value (a typo, a fuzzer, a generated
// file) costs an error line, not a hang or the machine's memory. They are far above any
// real use: the largest sheet the bench runs is 1000 x 1000 x 5 cells.
struct SceneLimit {
  const char* key;
  double bound;
  const char* what;
};
namespace limits {
inline constexpr int kMaxCellsAlong = 100'000;           // sheet.cells[0], sheet.cells[1]
inline constexpr int kMaxLayers = 64;                    // sheet.cells[2]
inline constexpr std::int64_t kMaxCells = 50'000'000;    // nx * ny * layers
inline constexpr int kMaxSteps = 100'000'000;            // run.steps
inline constexpr int kMaxFrames = 100'000;               // run.frames (a run writes at most one per step)
inline constexpr std::size_t kMaxLines = 1'000;          // [[line]] tables
inline constexpr std::size_t kMaxLinePoints = 10'000;    // points of one line
inline constexpr double kMinPitch = 0.01;                // line.pitch, in cells
inline constexpr double kMaxFibreLength = 100'000.0;     // material.fiber_length, in cells
inline constexpr int kMaxBlockSize = 1'000;              // material.block_width, block_depth
inline constexpr int kMaxThreads = 4'096;                // --threads, Simulation options
}  // namespace limits
// The bounds above with their keys, for `papertear info` and the README.
const std::vector<SceneLimit>& scene_limits();

// Throws SceneError ("<key>: <what is wrong>") for the first impossible value: sizes that
// are zero or negative, non-finite numbers, unknown grain or load kind, a sheet too large
// for memory... The time step is checked against the stable limit by the Simulation.
void validate(const Scene& scene);

}  // namespace papertear
