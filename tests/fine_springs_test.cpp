// Merged coincident fine springs (kernels/fine_springs.hpp): who evaluates which spring, for
// how many, and that the merged kernel pulls as hard as the 28 springs of every cell.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <tuple>
#include <vector>

#include <catch2/catch.hpp>

#include "core/simulation.hpp"
#include "core/solver.hpp"
#include "fracture/fracture_pass.hpp"
#include "kernels/cell_forces.hpp"
#include "kernels/fine_springs.hpp"
#include "tests/random_state.hpp"
#include "tests/standard_scenes.hpp"

namespace pt = papertear;

namespace {

pt::Scene small_sheet(int notch) {
  pt::Scene s;
  s.sheet.cells = {9, 7, 4};
  s.load.grip_cells = 1;
  s.load.notch = notch;
  return s;
}

// The plain definition: springs coincide when they join the same two nodes and belong to
// slots of one family and axis; the set's owner is its largest cell id.
pt::FineSprings brute_force(const pt::World& w) {
  using Key = std::tuple<std::uint32_t, std::uint32_t, int, int>;
  std::map<Key, std::vector<std::uint32_t>> sets;
  const std::size_t cells = std::size_t(w.topo.dims.cells());
  auto key = [&](std::uint32_t c, int s) {
    const pt::SpringSlot& sl = pt::kSpringSlots[std::size_t(s)];
    const std::uint32_t a = w.topo.node(c, sl.a), b = w.topo.node(c, sl.b);
    return Key{std::min(a, b), std::max(a, b), int(sl.family), int(sl.axis)};
  };
  for (std::uint32_t c = 0; c < cells; ++c)
    for (int s = 0; s < pt::kSpringsPerCell; ++s) sets[key(c, s)].push_back(c);
  pt::FineSprings f;
  f.resize_counts(cells, std::size_t(w.topo.dims.nx), 0);
  f.owned.assign(cells + 32, 0);
  for (std::uint32_t c = 0; c < cells; ++c)
    for (int s = 0; s < pt::kSpringsPerCell; ++s) {
      const auto& set = sets[key(c, s)];
      const bool owner = c == *std::max_element(set.begin(), set.end());
      f.set(c, s, owner ? std::uint8_t(set.size()) : 0);
      if (owner) f.owned[c] |= 1u << s;
    }
  return f;
}

// Counts and owned slots as the brute force has them, and the split-corner flag exactly on
// the cells that have a corner whose node is not its vertex's original one.
void require_same(const pt::World& w, const pt::FineSprings& got, const pt::FineSprings& want) {
  REQUIRE(got.cells == want.cells);
  std::size_t wrong = 0, total = 0, wrong_slots = 0, wrong_flags = 0;
  const pt::LatticeDims& d = w.topo.dims;
  for (std::uint32_t c = 0; c < got.cells; ++c) {
    for (int s = 0; s < pt::kSpringsPerCell; ++s) {
      wrong += got.at(c, s) != want.at(c, s) ? 1 : 0;
      total += got.at(c, s);
    }
    wrong_slots += (got.owned[c] & pt::kAllSlots) != want.owned[c] ? 1 : 0;
    const auto ijk = d.cell_ijk(c);
    bool split = false;
    for (int q = 0; q < pt::kCornersPerCell; ++q)
      split |= w.topo.node(c, q) != d.corner_vertex(ijk, q);
    wrong_flags += ((got.owned[c] & pt::kSplitCorner) != 0) != split ? 1 : 0;
  }
  CHECK(wrong == 0);
  CHECK(wrong_slots == 0);
  CHECK(wrong_flags == 0);
  CHECK(total == got.cells * pt::kSpringsPerCell);  // every cell's every spring counted once
}

// A FineSprings in which every cell evaluates its own 28 springs: the unmerged model.
pt::FineSprings unmerged(const pt::World& w) {
  const std::size_t cells = std::size_t(w.topo.dims.cells());
  pt::FineSprings f;
  f.resize_counts(cells, std::size_t(w.topo.dims.nx), 1);
  f.owned.assign(cells, pt::kAllSlots);
  f.owned.resize(cells + 32, 0);
  pt::plan_all_fine_rows(w.topo, f);
  return f;
}

std::array<std::vector<float>, 3> fine_forces(const pt::World& w, const pt::FineSprings& fine) {
  std::array<std::vector<float>, 3> f;
  for (auto& col : f) col.assign(w.nodes.count, 0.0f);
  const pt::NodeStore& n = w.nodes;
  const pt::CellForceInputs in{n.px.data(), n.py.data(), n.pz.data(), n.vx.data(), n.vy.data(), n.vz.data(),
                               w.topo.cell_nodes.data(), w.topo.cell_scale.data(), &w.springs, &fine, &w.topo.dims};
  pt::add_fine_forces(w.topo, in, {f[0].data(), f[1].data(), f[2].data()});
  return f;
}

// The counts the kernel reads for each row (a shared row's where the row has one) are the
// row's own. Returns how many rows read a shared row.
std::size_t require_kernel_counts(const pt::World& w, const pt::FineSprings& fine) {
  const pt::LatticeDims& d = w.topo.dims;
  std::size_t wrong = 0, shared = 0;
  for (std::size_t r = 0; r < fine.rows.size(); ++r) {
    const std::size_t first = r * std::size_t(d.nx);
    shared += fine.rows[r].shared >= 0 ? 1 : 0;
    for (int s = 0; s < pt::kSpringsPerCell; ++s) {
      const std::uint8_t* got = fine.kernel_counts(fine.rows[r], first, s);
      for (std::size_t i = 0; i < std::size_t(d.nx); ++i) wrong += got[i] != fine.at(first + i, s) ? 1 : 0;
    }
  }
  CHECK(wrong == 0);
  return shared;
}

// Every owner of a slot lies within its row's range, and the row's flags are set where a
// cell has a split copy or a stiffness factor; the copies bytes and the dirty cells' groups
// are exact; the counts the kernel reads are the row's own.
void require_rows_cover(const pt::World& w, const pt::FineSprings& got) {
  pt::FineSprings fresh = got;
  pt::plan_all_fine_rows(w.topo, fresh);
  REQUIRE(got.rows.size() == fresh.rows.size());
  std::size_t uncovered = 0, wrong_flags = 0;
  for (std::size_t r = 0; r < got.rows.size(); ++r) {
    const pt::FineRow &kept = got.rows[r], &want = fresh.rows[r];
    for (int s = 0; s < pt::kSpringsPerCell; ++s)
      if (want.lo[s] < want.hi[s] && (kept.lo[s] > want.lo[s] || kept.hi[s] < want.hi[s])) ++uncovered;
    wrong_flags += (want.copies && !kept.copies) || want.scaled != kept.scaled ? 1 : 0;
  }
  CHECK(uncovered == 0);
  CHECK(wrong_flags == 0);
  CHECK(got.copies == fresh.copies);
  // The dirty cells' groups as the kernel reads them: the same cells, corners and counts as
  // planned from scratch (stale ones would feed the kernel nodes from before a split).
  CHECK(got.stale_rows.empty());
  std::size_t stale_groups = 0;
  for (std::size_t r = 0; r < got.rows.size(); ++r) stale_groups += got.dirty[r] == fresh.dirty[r] ? 0 : 1;
  CHECK(stale_groups == 0);
  require_kernel_counts(w, got);
}

}  // namespace

TEST_CASE("a whole sheet's cells own their 13 low springs, the high sides more", "[fine]") {
  const pt::World w = pt::Simulation(small_sheet(0), {.threads = 1}).world();
  pt::FineSprings fine;
  pt::build_fine_springs(w.topo, w.springs, fine);
  require_same(w, fine, brute_force(w));
  const pt::LatticeDims& d = w.topo.dims;
  CHECK(fine.owned[d.cell_index(3, 2, 1)] == pt::kLowSlots);  // no flags either
  CHECK(fine.owned[d.cell_index(d.nx - 1, 2, 1)] == (pt::kLowSlots | pt::kHighXSlots));
  CHECK(fine.owned[d.cell_index(3, 2, d.nl - 1)] == (pt::kLowSlots | pt::kHighZSlots));
  // An interior x edge stands for the 4 cells around it; one on the sheet's bottom face for 2.
  CHECK(fine.at(d.cell_index(3, 2, 1), 0) == 4);
  CHECK(fine.at(d.cell_index(3, 2, 0), 0) == 2);
  CHECK(fine.at(d.cell_index(3, 2, 1), 24) == 1);  // a body diagonal is never shared
  // Every row of a whole sheet reads its kind's shared counts.
  CHECK(require_kernel_counts(w, fine) == fine.rows.size());
}

TEST_CASE("split nodes give each side its own springs, updated where the split was", "[fine]") {
  pt::World w = pt::Simulation(small_sheet(3), {.threads = 1}).world();  // the notch splits nodes
  pt::FineSprings fine;
  pt::build_fine_springs(w.topo, w.springs, fine);
  require_same(w, fine, brute_force(w));
  const pt::LatticeDims& d = w.topo.dims;
  for (int i = 2; i < d.nx - 1; i += 3) {
    const std::uint32_t vertex = d.vertex_index(i, 4, 2);
    REQUIRE(pt::split_node(w, pt::NodeId(vertex), i % 2, 1).valid());
    pt::update_fine_springs_at(w.topo, w.springs, vertex, fine);
  }
  CHECK(!fine.stale_rows.empty());
  pt::plan_stale_dirty_cells(w.topo, fine);
  require_same(w, fine, brute_force(w));
  require_rows_cover(w, fine);
  // The rows around the splits read their own counts, the others still the shared ones.
  const std::size_t shared = require_kernel_counts(w, fine);
  CHECK(shared > 0);
  CHECK(shared < fine.rows.size());
  CHECK(fine.rows[std::size_t(2) * std::size_t(d.ny) + 4].shared < 0);
}

TEST_CASE("the solver keeps its merged springs in step with a tearing sheet", "[fine]") {
  const auto scenes = pt::standard::scenes();
  pt::World w = pt::Simulation(scenes[1].scene, {.threads = 1}).world();
  pt::SolverScratch solver;
  pt::FractureScratch fracture;
  // Until the tear has run for a while (a few hundred splits), not the scene's whole length:
  // this test also runs under the sanitizers.
  for (int step = 0; step < scenes[1].steps && w.events.size() < 200; ++step) {
    pt::integrate_step(w, solver);
    pt::fracture_pass(w, fracture);
    ++w.step;
  }
  INFO("steps " << w.step);
  REQUIRE(w.events.size() >= 200);
  pt::integrate_step(w, solver);  // brings the table up to date with the last splits
  require_same(w, solver.fine, brute_force(w));
}

TEST_CASE("the solver keeps the kernel's plan of each row in step with a tearing sheet", "[fine]") {
  pt::Scene scene = pt::standard::scenes()[1].scene;
  scene.sheet.cells = {34, 12, 3};
  pt::World w = pt::Simulation(scene, {.threads = 1}).world();
  pt::SolverScratch solver;
  pt::FractureScratch fracture;
  int steps_with_splits = 0;
  for (int step = 0; step < 600 && w.events.size() < 200; ++step) {
    pt::integrate_step(w, solver);
    steps_with_splits += pt::fracture_pass(w, fracture) > 0 ? 1 : 0;
    ++w.step;
  }
  INFO("steps " << w.step << ", events " << w.events.size());
  REQUIRE(steps_with_splits >= 5);  // the plan was brought up to date split by split
  pt::integrate_step(w, solver);   // ... and once more for the last splits
  require_rows_cover(w, solver.fine);
  const std::size_t rows_with_copies = std::size_t(
      std::count_if(solver.fine.rows.begin(), solver.fine.rows.end(), [](const pt::FineRow& r) { return r.copies; }));
  CHECK(rows_with_copies > 0);
  std::size_t dirty_groups = 0;
  for (const auto& groups : solver.fine.dirty) dirty_groups += groups.size();
  CHECK(dirty_groups >= rows_with_copies);  // every such row has some
}

TEST_CASE("merged springs pull as hard as every cell's own 28", "[fine]") {
  pt::World w = pt::Simulation(small_sheet(3), {.threads = 1}).world();
  const pt::LatticeDims& d = w.topo.dims;
  REQUIRE(pt::split_node(w, pt::NodeId(d.vertex_index(4, 3, 2)), 0, 1).valid());
  pt::testing::perturb(w, 5, 0.1f, 0.05f);
  pt::FineSprings merged;
  pt::build_fine_springs(w.topo, w.springs, merged);
  const auto got = fine_forces(w, merged);
  const auto want = fine_forces(w, unmerged(w));
  // Only rounding differs: one product by the count instead of up to 4 additions per
  // spring. A missing or doubled spring would be off by a whole spring force.
  double largest = 0.0, worst = 0.0;
  for (int a = 0; a < 3; ++a)
    for (std::size_t i = 0; i < w.nodes.count; ++i) {
      largest = std::max(largest, double(std::fabs(want[std::size_t(a)][i])));
      worst = std::max(worst, double(std::fabs(got[std::size_t(a)][i] - want[std::size_t(a)][i])));
    }
  REQUIRE(largest > 1e-2);
  CHECK(worst <= 1e-5 * largest);
}
