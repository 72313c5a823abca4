// Whole-step benchmarks: one RK4 step plus the fracture pass of papertear::Simulation, and
// one step of the plain double-precision ReferenceModel (kernels/reference.hpp) on the same
// world, so the two can be compared case by case.
//
// Each papertear case first runs a fixed number of untimed steps from the scene and puts the
// digest after them in the label: the same label on 1 and 2 threads shows the run is
// deterministic as well as fast.
#include <cstdio>
#include <string>

#include "bench_cases.hpp"
#include "core/simulation.hpp"
#include "kernels/reference.hpp"

namespace papertear::bench {
namespace {

constexpr int kWarmupSteps = 10;

double springs_per_step(const Size& size) {
  return double(kSpringsPerCell) * double(size.cells()) * kForceEvaluationsPerStep;
}

std::string digest_label(std::uint64_t digest) {
  char text[48];
  std::snprintf(text, sizeof text, "digest@%d=%016llx", kWarmupSteps,
                static_cast<unsigned long long>(digest));
  return text;
}

void step_papertear(benchmark::State& state, Case c) {
  Simulation sim(quiet_pull_scene(c.size), {.threads = c.threads});
  sim.step(kWarmupSteps);
  state.SetLabel(digest_label(sim.digest()));
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

}  // namespace

void register_step_benchmarks() {
  for (const Case& c : papertear_cases()) {
    register_timed(case_name("step", "papertear", c), benchmark::kMillisecond, step_papertear, c);
  }
  // The reference is serial: one case per size.
  for (const Case& c : papertear_cases()) {
    if (c.threads != 1) continue;
    register_timed(case_name("step", "reference", c), benchmark::kMillisecond, step_reference, c);
  }
}

}  // namespace papertear::bench
