// papertear_bench: registers every case by its exact name, then hands over to Google
// Benchmark's command line (--benchmark_filter, --benchmark_repetitions, ...).
#include <benchmark/benchmark.h>

#include "bench_cases.hpp"

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  papertear::bench::register_step_benchmarks();
  papertear::bench::register_force_benchmarks();
  papertear::bench::register_fracture_benchmarks();
  papertear::bench::register_probe_benchmarks();
  papertear::bench::register_paired_benchmarks();
#ifdef PAPERTEAR_BENCH_RENDER
  papertear::bench::register_render_benchmarks();
#endif
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
