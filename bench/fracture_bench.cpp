// The fracture pass alone (fracture/fracture_pass.hpp), in two situations:
//  * fracture/quiet/<size>: the slowly pulled sheet of the step cases, where detection finds
//    nothing: the pass's cost on most steps of a run, to compare with the step time;
//  * fracture/tearing/30x20x3: a small sheet pulled fast (the fracture tests' scene), timed
//    from its first split on, so detection finds candidates and splits happen while it runs;
//  * fracture/default/<size>: the default scene (120 x 80 x 3) while it splits fastest,
//    steps kTearFrom + 2 .. kTearFrom + kTearSteps + 1 (a few splits per step): the pass's
//    share of the step while a crack runs.
// Each iteration of the first two advances the world one RK4 step untimed, then times the
// pass.
#include <oneapi/tbb/task_arena.h>

#include "bench_cases.hpp"
#include "core/simulation.hpp"
#include "core/solver.hpp"
#include "fracture/fracture_pass.hpp"

namespace papertear::bench {
namespace {

constexpr int kWarmupSteps = 10;
constexpr int kMaxStepsToFirstSplit = 6000;
// The default scene (seed 1) cracks from step ~200, is in two by ~440, and splits fastest
// between ~640 and ~720, when a slit opens along the grain beside the tear.
constexpr int kTearFrom = 640;
constexpr int kTearSteps = 40;
constexpr int kTearIterations = 3;

Scene tearing_scene() {
  Scene s;
  apply_material_preset(s.material, "copy");
  s.sheet.cells = {30, 20, 3};
  s.load.grip_cells = 2;
  s.load.grip_margin = 2;
  s.load.notch = 3;
  s.load.speed = 0.1;
  s.load.ramp_time = 5.0;
  return s;
}

void time_fracture_passes(benchmark::State& state, World world, int threads) {
  tbb::task_arena arena(threads);
  SolverScratch solver;
  FractureScratch fracture;
  double seconds = 0.0;
  std::size_t splits = 0;
  for (auto _ : state) {
    arena.execute([&] { integrate_step(world, solver); });
    const double t = timed([&] { arena.execute([&] { splits += fracture_pass(world, fracture); }); });
    ++world.step;
    state.SetIterationTime(t);
    seconds += t;
  }
  const double cells = double(world.topo.dims.cells()), iterations = double(state.iterations());
  state.counters["ns_per_cell"] = iterations > 0 ? seconds * 1e9 / (cells * iterations) : 0.0;
  state.counters["splits_per_step"] = iterations > 0 ? double(splits) / iterations : 0.0;
}

void fracture_quiet(benchmark::State& state, Case c) {
  Simulation sim(quiet_pull_scene(c.size), {.threads = c.threads});
  sim.step(kWarmupSteps);
  time_fracture_passes(state, sim.world(), c.threads);
}

void fracture_tearing(benchmark::State& state, int threads) {
  Simulation sim(tearing_scene(), {.threads = threads});
  for (int i = 0; i < kMaxStepsToFirstSplit && sim.world().events.size() < 4; i += 10) sim.step(10);
  if (sim.world().events.empty()) {
    state.SkipWithError("the tearing scene did not start tearing");
    return;
  }
  time_fracture_passes(state, sim.world(), threads);
}

// Each iteration copies the saved world and runs its next kTearSteps steps, timing the RK4
// step and the fracture pass apart; the time reported is the fracture pass's per step.
// (One untimed step first: a copied world's solver tables are built on its first step.)
// A fixed number of iterations: the reported time is a small part of each iteration's.
void fracture_default(benchmark::State& state, int threads) {
  tbb::task_arena arena(threads);
  double step_seconds = 0.0, fracture_seconds = 0.0;
  std::size_t splits = 0;
  for (auto _ : state) {
    World world = default_scene_at(kTearFrom);
    SolverScratch solver;
    FractureScratch fracture;
    struct Advanced {
      double step_time, fracture_time;
      std::size_t splits;
    };
    auto advance = [&] {
      Advanced a{};
      a.step_time = timed([&] { arena.execute([&] { integrate_step(world, solver); }); });
      a.fracture_time = timed([&] { arena.execute([&] { a.splits = fracture_pass(world, fracture); }); });
      ++world.step;
      return a;
    };
    advance();
    double fracture_time = 0.0;
    for (int i = 0; i < kTearSteps; ++i) {
      const Advanced a = advance();
      step_seconds += a.step_time;
      fracture_time += a.fracture_time;
      splits += a.splits;
    }
    state.SetIterationTime(fracture_time / kTearSteps);
    fracture_seconds += fracture_time;
  }
  const double steps = double(state.iterations()) * kTearSteps;
  state.counters["splits_per_step"] = steps > 0 ? double(splits) / steps : 0.0;
  state.counters["share_of_step"] = step_seconds > 0 ? fracture_seconds / step_seconds : 0.0;
}

}  // namespace

void register_fracture_benchmarks() {
  for (const Case& c : papertear_cases()) {
    register_timed(case_name("fracture", "quiet", c), benchmark::kMicrosecond, fracture_quiet, c);
  }
  for (int threads : {1, 2}) {
    const std::string name = "fracture/tearing/30x20x3/threads:" + std::to_string(threads);
    register_timed(name, benchmark::kMicrosecond, fracture_tearing, threads);
    const std::string during = "fracture/default/" + default_scene_size() + "/threads:" + std::to_string(threads);
    register_timed(during, benchmark::kMicrosecond, fracture_default, threads)->Iterations(kTearIterations);
  }
}

}  // namespace papertear::bench
