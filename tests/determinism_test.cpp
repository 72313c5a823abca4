// Bit-for-bit reproducibility: the same scene gives the same digest on any thread count and
// on every run (kernels/parallel.hpp explains why; this is the check).
#include <catch2/catch.hpp>

#include <atomic>
#include <cstdint>
#include <ios>
#include <vector>

#include <oneapi/tbb/task_arena.h>

#include "core/simulation.hpp"
#include "kernels/parallel.hpp"
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

// The solver's stage is a graph of tasks (core/solver.cpp): a task must start only after each
// of its predecessors has ended, and every task must run exactly once, on any thread count.
// Here a graph of the same shape: roots r, joins j_i after r_i and r_i+1, ends e_i after
// j_i-1 and j_i. Tickets from one counter order the starts and ends.
TEST_CASE("a task graph runs every task once, each after its predecessors", "[determinism]") {
  constexpr std::size_t R = 40, J = R - 1, E = J + 1, n = R + J + E;
  std::vector<std::vector<std::size_t>> preds(n);
  for (std::size_t i = 0; i < J; ++i) preds[R + i] = {i, i + 1};
  for (std::size_t i = 0; i < E; ++i) {
    if (i > 0) preds[R + J + i].push_back(R + i - 1);
    if (i < J) preds[R + J + i].push_back(R + i);
  }
  std::vector<std::vector<std::size_t>> succs(n);
  for (std::size_t t = 0; t < n; ++t)
    for (std::size_t p : preds[t]) succs[p].push_back(t);
  std::vector<std::size_t> roots;
  for (std::size_t t = 0; t < R; ++t) roots.push_back(t);

  for (int threads : {1, 2, 4}) {
    INFO("threads " << threads);
    std::vector<std::atomic<std::uint32_t>> waits(n);
    for (std::size_t t = 0; t < n; ++t) waits[t].store(std::uint32_t(preds[t].size()));
    std::atomic<std::uint64_t> clock{0};
    std::vector<std::atomic<int>> runs(n);
    std::vector<std::uint64_t> start(n, 0), end(n, 0);
    tbb::task_arena arena(threads);
    arena.execute([&] {
      papertear::run_task_graph(n, roots, waits.data(), [&](std::size_t t, const auto& release) {
        start[t] = clock.fetch_add(1);
        runs[t].fetch_add(1);
        volatile double busy = 0;  // long enough that tasks overlap on several threads
        for (int k = 0; k < 2000; ++k) busy = busy + k;
        end[t] = clock.fetch_add(1);
        for (std::size_t u : succs[t]) release(u);
      });
    });
    bool once = true, ordered = true, drained = true;
    for (std::size_t t = 0; t < n; ++t) {
      once &= runs[t].load() == 1;
      drained &= waits[t].load() == 0;
      for (std::size_t p : preds[t]) ordered &= end[p] < start[t];
    }
    CHECK(once);
    CHECK(ordered);
    CHECK(drained);
  }
}
