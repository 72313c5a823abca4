// Golden digests of the standard scenes (tests/standard_scenes.hpp). They pin the bits of
// the whole pipeline — lattice, blocks, kernels, RK4, fracture — so that any change to the
// results is noticed. When a change alters them on purpose (a new summation order, a model
// change), update the values here and say why in the commit message.
// History: 2026-11-21 block springs summed per block and subnormals flushed in the kernels;
// 2026-11-22 coincident fine springs evaluated once, times their number (same splits);
// then fine springs by strips of rows (rows between strips sum strip by strip); the "wide"
// and "narrow" scenes added 2026-11-22 (their digests were the same before and after split
// copies were patched into vector groups and short rows became masked vector groups);
// 2026-12-01 the fine springs swept slot by slot along rows of cells, with 1 / |d| taken as
// |d| / |d|^2 (a new summation order and rounding; the same splits).
#include <catch2/catch.hpp>

#include <cstdint>
#include <iterator>
#include <tuple>
#include <ios>
#include <string>

#include "core/simulation.hpp"
#include "tests/standard_scenes.hpp"

using namespace papertear;

TEST_CASE("the standard scenes keep their golden digests", "[determinism][golden]") {
  const std::uint64_t golden[] = {0x58d3cd9ec4c051e2ull, 0x0a6701385a3860e6ull, 0x30bd71f1225f126full,
                                  0x09d3932aaecc4b09ull, 0x104ac1c8b1972be4ull};
  const std::size_t splits[] = {0, 827, 701, 574, 407};
  static_assert(std::size(golden) == std::tuple_size_v<decltype(standard::scenes())>);
  std::size_t i = 0;
  for (const auto& s : standard::scenes()) {
    Simulation sim(s.scene, {.threads = 2});
    sim.step(s.steps);
    INFO(s.name << ": digest " << std::hex << sim.digest() << std::dec << " after " << sim.world().events.size()
                << " splits");
    CHECK(sim.digest() == golden[i]);
    CHECK(sim.world().events.size() == splits[i]);
    ++i;
  }
}
