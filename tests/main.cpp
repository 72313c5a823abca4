// The test runner. Tests run simulations on up to 16 threads (determinism across thread
// counts). TBB otherwise keeps the worker limit it set when its first arena was created (the
// machine's default: 1 worker on 2 cores) for as long as any arena lives, and quietly runs
// a larger arena with fewer threads than asked; this lifts the limit for the whole run.
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

#include <oneapi/tbb/global_control.h>

int main(int argc, char* argv[]) {
  const tbb::global_control allow(tbb::global_control::max_allowed_parallelism, 16);
  return Catch::Session().run(argc, argv);
}
