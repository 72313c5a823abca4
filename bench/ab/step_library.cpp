// One build of the library behind a plain C interface, compiled into a shared object per
// build (bench/ab/run.sh), so that step_ab can load two builds into one process and time
// them side by side. Each object keeps its own copy of every papertear symbol (linked with
// -Bsymbolic, loaded with RTLD_LOCAL | RTLD_DEEPBIND).
#include <chrono>

#include "bench/bench_cases.hpp"
#include "core/simulation.hpp"

using papertear::Simulation;

// A simulation of the quiet pulled sheet nx x ny x nl after 10 steps, or (torn != 0) of the
// default scene from step 800, after it has torn in two; on `threads` threads.
extern "C" void* ab_make(int nx, int ny, int nl, int threads, int torn) {
  if (torn != 0) return new Simulation(papertear::bench::default_scene_at(800), {.threads = threads});
  auto* sim = new Simulation(papertear::bench::quiet_pull_scene({nx, ny, nl}), {.threads = threads});
  sim->step(10);
  return sim;
}

// Wall milliseconds per step over `steps` steps.
extern "C" double ab_step_ms(void* sim, int steps) {
  const auto start = std::chrono::steady_clock::now();
  static_cast<Simulation*>(sim)->step(steps);
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count() / steps;
}

extern "C" void ab_free(void* sim) { delete static_cast<Simulation*>(sim); }
