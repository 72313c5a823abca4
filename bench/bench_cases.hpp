// What every benchmark case shares: the sheet sizes and thread counts swept, the scene they
// run, the case names and the counters. The cases themselves live in step_bench.cpp (a
// whole RK4 step) and force_bench.cpp (the fine-spring kernel alone).
#pragma once
#include <array>
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "core/scene.hpp"

namespace papertear::bench {

struct Size {
  int nx, ny, nl;
  std::int64_t cells() const { return std::int64_t(nx) * ny * nl; }
};

struct Case {
  Size size;
  int threads;
};

// The paper's experiment (90 × 90 × 5) and a small sheet, each on 1 and 2 threads.
std::vector<Case> papertear_cases();

// "<family>/<impl>/<nx>x<ny>x<nl>/threads:<t>", e.g. "step/papertear/90x90x5/threads:2".
std::string case_name(const char* family, const char* impl, const Case& c);

// A pulled sheet whose grips move slowly enough that no bond opens while a benchmark runs,
// so every timed step does the same work.
Scene quiet_pull_scene(const Size& size);

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

// Each registers its cases with Google Benchmark (called once, from main).
void register_step_benchmarks();
void register_force_benchmarks();

}  // namespace papertear::bench
