#include "tools/calibration/standard_tests.hpp"

#include <algorithm>
#include <numeric>

#include "core/lattice_builder.hpp"
#include "core/simulation.hpp"
#include "fracture/metrics.hpp"

namespace papertear::calibration {
namespace {

Scene preset_scene(const std::string& preset, std::uint64_t seed) {
  Scene s;
  apply_material_preset(s.material, preset);
  s.run.seed = seed;
  s.run.frames = 1;
  return s;
}

// The kinetic energy of the nodes the grips do not hold. The grips move their nodes
// kinematically: that motion's energy is put in by the driver, not by the work the grips do
// on the sheet through its springs, so it is no part of what the specimen stores.
double free_kinetic_energy(const World& w) {
  const NodeStore& n = w.nodes;
  double e = 0.0;
  for (std::uint32_t i = 0; i < n.count; ++i)
    if (n.grip[i] == 0)
      e += 0.5 * double(n.mass[i]) * (double(n.vx[i]) * n.vx[i] + double(n.vy[i]) * n.vy[i] + double(n.vz[i]) * n.vz[i]);
  return e;
}

}  // namespace

const char* name(Direction d) { return d == Direction::MD ? "MD" : "CD"; }

double mean(const std::vector<double>& v) {
  return v.empty() ? 0.0 : std::accumulate(v.begin(), v.end(), 0.0) / double(v.size());
}

// A strip 4x longer than wide (ISO 1924-2 uses 15 mm x 180 mm; shorter keeps it cheap),
// pulled along x slowly enough that the stress is nearly uniform along it. MD: the grain
// runs along the pull.
Scene tensile_scene(const std::string& preset, Direction direction, Size size, std::uint64_t seed) {
  Scene s = preset_scene(preset, seed);
  s.material.grain = direction == Direction::MD ? 'x' : 'y';
  s.sheet.cells = size == Size::quick ? std::array<int, 3>{32, 8, 3} : std::array<int, 3>{64, 16, 3};
  s.load.kind = "pull";
  s.load.axis = 'x';
  s.load.grip_cells = 2;
  s.load.grip_margin = 2;
  s.load.notch = 0;  // a tensile strip has no cut
  s.load.speed = 0.02;
  s.load.ramp_time = 10.0;
  s.run.steps = size == Size::quick ? 3000 : 6000;  // an upper bound: run_tensile stops at the break
  return s;
}

// The Elmendorf specimen (63 mm x 76 mm with a 20 mm cut, torn 43 mm) at lattice scale: a
// notch at the middle of the top edge, torn out of plane by the "tear" load. MD: the tear
// runs along the grain, i.e. down the sheet (y).
Scene tear_scene(const std::string& preset, Direction direction, Size size, std::uint64_t seed) {
  Scene s = preset_scene(preset, seed);
  s.material.grain = direction == Direction::MD ? 'y' : 'x';
  const bool quick = size == Size::quick;
  s.sheet.cells = quick ? std::array<int, 3>{24, 28, 3} : std::array<int, 3>{40, 48, 3};
  s.load.kind = "tear";
  s.load.axis = 'x';         // the grips sit left and right of the tear line, which runs along y
  s.load.grip_cells = quick ? 5 : 8;
  s.load.grip_margin = 2;    // the grips' inner edges are 2 cells from the tear line
  s.load.speed = 0.1;
  s.load.ramp_time = 5.0;
  s.load.notch = quick ? 7 : 12;
  s.run.steps = quick ? 2400 : 4800;  // an upper bound: run_tear stops when torn through
  return s;
}

TensileResult run_tensile(const Scene& scene, int threads) {
  Simulation sim(scene, {.threads = threads});
  const LatticeDims& d = sim.world().topo.dims;
  const double width = d.ny * d.hy * d.nl * d.hz;
  const double free_length = (d.nx - 2 * scene.load.grip_cells) * d.hx;
  constexpr int kEvery = 4;  // steps between force samples
  TensileResult r;
  double separation_at_peak = 0.0;
  while (sim.steps_done() < scene.run.steps) {
    sim.step(kEvery);
    const double f = grip_force(sim.world());
    if (f > r.peak_force) {
      r.peak_force = f;
      // Both grips move apart at the same speed: separation = 2 × each grip's travel.
      separation_at_peak = 2.0 * ramped_travel(scene.load.speed, scene.load.ramp_time, sim.time());
    }
    if (r.peak_force > 0.0 && f < 0.25 * r.peak_force) break;  // broken through
  }
  r.steps = sim.steps_done();
  r.strength = r.peak_force / width;
  r.strain_at_peak = separation_at_peak / free_length;
  return r;
}

// Elmendorf reports the work to tear a fixed distance through the specimen, not per unit of
// fracture surface: a tear that wanders or frays costs more, and that is part of the
// resistance. So the run stops once the specimen is in two pieces and the energy is divided
// by the distance torn, from the notch tip to the far edge. The energy is the grips' work
// less what the pieces still hold (the bent flaps' elastic energy, their motion): what the
// tear consumed. The stored part is large here (a third to a half of the work: the lattice's
// flaps are thick and the grips fast) and about the same along and across the grain, so
// leaving it in would wash the anisotropy out.
TearResult run_tear(const Scene& scene, int threads) {
  Simulation sim(scene, {.threads = threads});
  const LatticeDims& d = sim.world().topo.dims;
  constexpr int kCheckEvery = 20;  // steps between checks for the separation
  TearResult r;
  double power_before = grip_power(sim.world());
  while (sim.steps_done() < scene.run.steps) {
    sim.step(1);
    const double power = grip_power(sim.world());
    r.work += 0.5 * (power_before + power) * sim.dt();  // trapezoid rule over the step
    power_before = power;
    if (sim.steps_done() % kCheckEvery == 0 && measure(sim.world()).pieces >= 2) {
      r.torn_through = true;
      break;
    }
  }
  r.steps = sim.steps_done();
  const Metrics end = measure(sim.world());
  r.stored = end.elastic_energy + free_kinetic_energy(sim.world());
  r.torn_length = end.torn_edge_length;
  r.tear_distance = (d.ny - scene.load.notch) * d.hy;
  r.resistance = r.torn_through ? (r.work - r.stored) / r.tear_distance : 0.0;
  return r;
}

double PresetCalibration::tensile_ratio() const { return mean(tensile_md) / mean(tensile_cd); }
double PresetCalibration::tear_ratio() const { return mean(tear_cd) / mean(tear_md); }

PresetCalibration calibrate_preset(const std::string& preset, Size size, const std::vector<std::uint64_t>& seeds,
                                   int threads) {
  PresetCalibration c;
  c.preset = preset;
  for (std::uint64_t seed : seeds) {
    c.tensile_md.push_back(run_tensile(tensile_scene(preset, Direction::MD, size, seed), threads).strength);
    c.tensile_cd.push_back(run_tensile(tensile_scene(preset, Direction::CD, size, seed), threads).strength);
    c.tear_md.push_back(run_tear(tear_scene(preset, Direction::MD, size, seed), threads).resistance);
    c.tear_cd.push_back(run_tear(tear_scene(preset, Direction::CD, size, seed), threads).resistance);
  }
  return c;
}

}  // namespace papertear::calibration
