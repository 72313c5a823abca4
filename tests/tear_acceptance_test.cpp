// The default pull, at the smallest sheet its acceptance names (48 × 32 cells, its 3 thin
// layers), tears like paper: one crack across the sheet and nothing else. Four measures,
// each of which the old board-like model failed (README, model decisions):
//  - exactly two pieces hold more than 1 % of the cells each;
//  - all smaller pieces (fragments) together hold under 0.1 % of the cells;
//  - in-plane splits are at most 3 × (layers + 1) × the tear's length in cells: a clean tear
//    splits each node column it crosses about once per node layer;
//  - the peel along the tear is a thin fringe: the separated faces between layers, over the
//    two torn edges, are on average at most 2 cells wide.
// The run goes on after the sheet is in two, so that a sheet that shatters when its halves
// spring back fails too.
#include <catch2/catch.hpp>

#include <cstdint>

#include "core/scene.hpp"
#include "core/simulation.hpp"
#include "fracture/metrics.hpp"

using namespace papertear;

TEST_CASE("the default pull on a small sheet tears cleanly in two on several seeds", "[acceptance][fracture]") {
  const std::uint64_t seed = GENERATE(1u, 2u, 3u);
  Scene s;  // the default scene: copy paper, thin cells, notched, pulled along the grain
  s.sheet.cells = {48, 32, s.sheet.cells[2]};
  s.run.seed = seed;
  Simulation sim(s, {.threads = 2});
  sim.step(s.run.steps);
  const Metrics m = measure(sim.world());
  INFO("seed " << seed << ": " << m.pieces << " pieces, " << m.fragments << " fragments, "
               << m.splits_inplane << " in-plane splits, tear " << m.tear_length << " cells, peeled "
               << m.peeled_area << " mm²");
  const double cell_area = s.sheet.cell_size[0] * s.sheet.cell_size[1];
  const double tear_cells = m.tear_length / s.sheet.cell_size[1];  // the crack runs along y
  CHECK(m.pieces - m.fragments == 2);
  CHECK(m.fragment_fraction < 0.001);
  REQUIRE(tear_cells >= 0.9 * s.sheet.cells[1]);  // the crack crosses the sheet
  CHECK(double(m.splits_inplane) <= 3.0 * (s.sheet.cells[2] + 1) * tear_cells);
  CHECK(m.peeled_area / cell_area / (2.0 * tear_cells) <= 2.0);
}
