// Whole-step benchmarks: one RK4 step plus the fracture pass of papertear::Simulation, and
// one step of the plain double-precision ReferenceModel (kernels/reference.hpp) on the same
// world, so the two can be compared case by case.
//
// step/torn/<size>/threads:<t> is the same papertear step on the default scene after it
// has torn in two (from step kTornAt on): the state a run spends its second half in, with a
// damage zone of split nodes that the quiet sheet of the other cases does not have.
//
// stable_step/<cells> reports the stable RK4 step (core/timestep.hpp) of a 90 x 90 x 5 sheet
// of cube cells and of cells 3x and 10x flatter than wide, with the material fitted to each
// shape: paper is soft through its thickness, so flat cells should need no smaller step.
//
// Each papertear case first runs a fixed number of untimed steps from the scene and puts the
// digest after them in the label: the same label on 1 and 2 threads shows the run is
// deterministic as well as fast.
#include <cstdio>
#include <string>
#include <utility>

#include "bench_cases.hpp"
#include "core/simulation.hpp"
#include "kernels/reference.hpp"

namespace papertear::bench {
namespace {

constexpr int kWarmupSteps = 10;

double springs_per_step(const Size& size) {
  return double(kSpringsPerCell) * double(size.cells()) * kForceEvaluationsPerStep;
}

std::string digest_label(std::int64_t step, std::uint64_t digest) {
  char text[48];
  std::snprintf(text, sizeof text, "digest@%lld=%016llx", static_cast<long long>(step),
                static_cast<unsigned long long>(digest));
  return text;
}

void step_papertear(benchmark::State& state, Case c) {
  Simulation sim(quiet_pull_scene(c.size), {.threads = c.threads});
  sim.step(kWarmupSteps);
  state.SetLabel(digest_label(sim.steps_done(), sim.digest()));
  double seconds = 0.0;
  for (auto _ : state) {
    const double t = timed([&] { sim.step(1); });
    state.SetIterationTime(t);
    seconds += t;
  }
  set_throughput_counters(state, c.size, springs_per_step(c.size), seconds, "ns_per_cell_step");
  const SolverFootprint footprint = solver_footprint(sim.world());
  state.counters["bytes_per_cell"] = footprint.bytes_per_cell;
  state.counters["block_springs"] = double(sim.world().coarse.size());
  state.counters["evaluated_springs"] = footprint.evaluated_springs;
}

// The default scene is in two pieces by about step 450 of its 1200 (seed 1).
constexpr int kTornAt = 800;

// One untimed step first: a copied world's solver tables are built on its first step.
void step_torn(benchmark::State& state, int threads) {
  Simulation sim(default_scene_at(kTornAt), {.threads = threads});
  sim.step(1);
  state.SetLabel(digest_label(sim.steps_done(), sim.digest()));
  const LatticeDims& dims = sim.world().topo.dims;
  const Size size{dims.nx, dims.ny, dims.nl};
  double seconds = 0.0;
  for (auto _ : state) {
    const double t = timed([&] { sim.step(1); });
    state.SetIterationTime(t);
    seconds += t;
  }
  set_throughput_counters(state, size, springs_per_step(size), seconds, "ns_per_cell_step");
  state.counters["split_nodes"] = double(sim.world().nodes.count - std::size_t(sim.world().topo.dims.vertices()));
}

void step_reference(benchmark::State& state, Case c) {
  Simulation sim(quiet_pull_scene(c.size), {.threads = 1});
  sim.step(kWarmupSteps);
  ReferenceModel reference(sim.world());
  double seconds = 0.0;
  for (auto _ : state) {
    const double t = timed([&] { reference.step(1); });
    state.SetIterationTime(t);
    seconds += t;
  }
  set_throughput_counters(state, c.size, springs_per_step(c.size), seconds, "ns_per_cell_step");
}

// The stable step of cells of height `hz` (in-plane 1 x 1), timed (it is computed once per
// run); stable_dt_us is the limit in µs and over_cube its ratio to cube cells' limit.
void stable_step(benchmark::State& state, double hz) {
  const auto scene_of = [](double h) {
    Scene scene = quiet_pull_scene({90, 90, 5});
    scene.sheet.cell_size = {1.0, 1.0, h};
    return scene;
  };
  const Scene scene = scene_of(hz);
  double limit = 0.0;
  for (auto _ : state) {
    const double t = timed([&] { limit = Simulation::stable_dt_limit(scene); });
    state.SetIterationTime(t);
  }
  state.counters["stable_dt_us"] = limit;
  state.counters["over_cube"] = limit / Simulation::stable_dt_limit(scene_of(1.0));
}

}  // namespace

void register_step_benchmarks() {
  for (const auto& [name, hz] : {std::pair{"cube", 1.0}, std::pair{"flat3", 1.0 / 3.0}, std::pair{"flat10", 0.1}})
    register_timed(std::string("stable_step/") + name + "/90x90x5", benchmark::kMillisecond, stable_step, hz);
  for (const Case& c : papertear_cases()) {
    register_timed(case_name("step", "papertear", c), benchmark::kMillisecond, step_papertear, c);
  }
  for (int threads : {1, 2})
    register_timed("step/torn/" + default_scene_size() + "/threads:" + std::to_string(threads), benchmark::kMillisecond, step_torn, threads);
  // The reference is serial: one case per size.
  for (const Case& c : papertear_cases()) {
    if (c.threads != 1) continue;
    register_timed(case_name("step", "reference", c), benchmark::kMillisecond, step_reference, c);
  }
}

}  // namespace papertear::bench
