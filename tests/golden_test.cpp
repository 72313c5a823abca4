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
// |d| / |d|^2 (a new summation order and rounding; the same splits); 2026-12-07 the
// material from paper's constants in mm, µs, mg (springs fitted to the cell's shape), delayed
// bond failure, the crack-tip rule and fibre bridging (new physics: new bits, fewer splits;
// the intact scene's pull and gravity scaled to the new units so that it stays intact);
// then fibres bridging a fresh crack for 20 bond failure times instead of 4 (fewer splits);
// then z-direction bonds inside a block judged as the sheet's z bond, and bonds opened by
// tension across the grain stretching cross_stretch = 1.3 further (fewer splits); then the
// in-plane bond failure time from the longitudinal wave instead of the Rayleigh wave, and no
// tip discount one cell beside a crack of the same plane (fewer splits, no branching).
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
  const std::uint64_t golden[] = {0x9b4a86698e8c0bd4ull, 0xc3c113919d722d70ull, 0x3993a11a14bee178ull,
                                  0xee1fa3114fd749fbull, 0xad47d58f8eba96b0ull};
  const std::size_t splits[] = {0, 233, 276, 124, 139};
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
