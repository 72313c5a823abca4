// What every benchmark case shares: the sheet sizes and thread counts swept, the scene they
// run, the case names, their registration and the counters. The cases themselves live in
// step_bench.cpp (a whole RK4 step), force_bench.cpp (the fine-spring kernel alone),
// fracture_bench.cpp, render_bench.cpp, probe_bench.cpp (the machine's ceilings) and
// paired_bench.cpp (the step's ratios measured pair by pair).
#pragma once
#include <array>
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <oneapi/tbb/task_arena.h>

#include "core/scene.hpp"
#include "core/world.hpp"

namespace papertear::bench {

struct Size {
  int nx, ny, nl;
  std::int64_t cells() const { return std::int64_t(nx) * ny * nl; }
};

struct Case {
  Size size;
  int threads;
};

// 30 × 30 × 5, the paper's experiment (90 × 90 × 5), 300 × 300 × 5 and 1000 × 1000 × 5, each
// on 1 and 2 threads. bench/run.sh leaves the 1000 × 1000 × 5 cases out unless asked: their
// setup alone takes minutes and about 1.3 GB.
std::vector<Case> papertear_cases();

// Force evaluations in one RK4 step (its stages).
inline constexpr double kForceEvaluationsPerStep = 4.0;

// "<family>/<impl>/<nx>x<ny>x<nl>/threads:<t>", e.g. "step/papertear/90x90x5/threads:2".
std::string case_name(const char* family, const char* impl, const Case& c);

// A pulled sheet whose grips move slowly enough that no bond opens while a benchmark runs,
// so every timed step does the same work.
Scene quiet_pull_scene(const Size& size);

// The default scene's sheet, "<nx>x<ny>x<nl>", for case names.
std::string default_scene_size();

// The default scene run to `step` on 2 threads, made once per
// process and step (seconds each) and kept for the cases that start from it.
const World& default_scene_at(int step);

// The sheet of the torn render cases: the default scene pulled 4x faster, so that it comes
// apart in two within a few hundred steps (seconds), and 50 steps more to move the pieces
// apart a little; its mesh has the fibres and skins a torn frame of a real run has. Made
// once per process and kept.
const World& torn_render_sheet();

// Registers a case that times itself (UseManualTime: the wall clock around its work only),
// reported in `unit`; `args` follow the state in each call of `fn`.
template <class Fn, class... Args>
benchmark::internal::Benchmark* register_timed(const std::string& name, benchmark::TimeUnit unit, Fn fn,
                                               Args... args) {
  return benchmark::RegisterBenchmark(name.c_str(), fn, args...)->UseManualTime()->Unit(unit);
}

// Times one call of `body` for UseManualTime benchmarks and returns the seconds it took.
template <class Body>
double timed(const Body& body) {
  const auto start = std::chrono::steady_clock::now();
  body();
  const auto stop = std::chrono::steady_clock::now();
  return std::chrono::duration<double>(stop - start).count();
}

// Sets `springs_per_s` (fine springs evaluated per second) and `per_cell_counter` (wall
// nanoseconds per cell and iteration). `springs_per_iteration` is 28 × cells × the number of
// force evaluations in one iteration (4 for an RK4 step).
void set_throughput_counters(benchmark::State& state, const Size& size, double springs_per_iteration,
                             double total_seconds, const char* per_cell_counter);

struct SolverFootprint {
  // Bytes of solver state per cell (node columns, RK4 scratch, cell table and per-cell data,
  // block-lattice springs, and the solver's merged-spring and block-lattice tables) of a
  // built world: what one step streams through at least once.
  double bytes_per_cell = 0.0;
  // Springs one force evaluation computes: the distinct fine springs (coincident ones merged,
  // kernels/fine_springs.hpp) and the block-lattice springs. Each costs a sqrt and a division.
  double evaluated_springs = 0.0;
};
SolverFootprint solver_footprint(const World& world);

// The sqrt+div probe's kernel (probe_bench.cpp): one run on `threads` threads of `arena`,
// its wall time and the square root + division pairs it did.
struct SqrtDivRun {
  double seconds = 0.0, pairs = 0.0;
};
SqrtDivRun sqrt_div_run(tbb::task_arena& arena, int threads);

// Each registers its cases with Google Benchmark (called once, from main).
void register_step_benchmarks();
void register_force_benchmarks();
void register_fracture_benchmarks();
void register_probe_benchmarks();
void register_paired_benchmarks();
void register_render_benchmarks();  // only when the renderer is built (PAPERTEAR_BENCH_RENDER)

}  // namespace papertear::bench
