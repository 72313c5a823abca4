// Bit-for-bit reproducibility: the same scene gives the same digest on any thread count and
// on every run (kernels/parallel.hpp explains why; this is the check).
#include <catch2/catch.hpp>

#include <ios>

#include "core/simulation.hpp"
#include "tests/standard_scenes.hpp"

using namespace papertear;

namespace {

// A pulled sheet that tears during the run, so fracture's serial pass is exercised too.
Scene tearing_scene() { return standard::small("copy"); }

std::uint64_t digest_after(const Scene& s, int threads, int steps) {
  Simulation sim(s, {.threads = threads});
  sim.step(steps);
  return sim.digest();
}

}  // namespace

TEST_CASE("the same digest on 1, 2, 3, 4, 7, 8 and 16 threads and on two runs", "[determinism]") {
  const Scene s = tearing_scene();
  const int steps = 400;
  Simulation first(s, {.threads = 1});
  first.step(steps);
  REQUIRE(!first.world().events.empty());  // the sheet tore: splits are part of the check
  const std::uint64_t expected = first.digest();
  for (int threads : {1, 2, 3, 4, 7, 8, 16}) {
    const std::uint64_t got = digest_after(s, threads, steps);
    INFO("threads " << threads << ": digest " << std::hex << got << ", 1 thread gave " << expected);
    CHECK(got == expected);
  }
}

TEST_CASE("two simulations in one process do not affect each other", "[determinism]") {
  const Scene s = tearing_scene();
  const std::uint64_t alone = digest_after(s, 2, 200);
  Simulation a(s, {.threads = 2}), b(s, {.threads = 1});
  for (int i = 0; i < 20; ++i) {  // interleaved, as an embedding application might
    a.step(10);
    b.step(10);
  }
  CHECK(a.digest() == alone);
  CHECK(b.digest() == alone);
}

TEST_CASE("stepping in chunks gives the same digest as one call", "[determinism]") {
  const Scene s = tearing_scene();
  Simulation chunked(s, {.threads = 2});
  for (int i = 0; i < 300; i += 7) chunked.step(std::min(7, 300 - i));
  CHECK(chunked.digest() == digest_after(s, 2, 300));
}
