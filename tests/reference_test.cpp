// The SIMD/TBB solver against the plain double-precision reference model
// (kernels/reference.hpp): whole runs, and the per-node forces of the fine-spring kernel.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <catch2/catch.hpp>
#include <oneapi/tbb/task_arena.h>

#include "core/simulation.hpp"
#include "core/solver.hpp"
#include "fracture/fracture_pass.hpp"
#include "kernels/cell_forces.hpp"
#include "kernels/coarse_forces.hpp"
#include "kernels/reference.hpp"
#include "tests/random_state.hpp"
#include "tests/spring_bounds.hpp"

namespace pt = papertear;

namespace {

constexpr double kEpsF = std::numeric_limits<float>::epsilon();  // 2^-23

// A small sheet with every part of the elastic model switched on (fibre blocks with their
// coarse springs, damping, a drag strong enough to matter), pulled along x. Bonds are made
// strong enough that nothing breaks during the comparison: fracture is not part of the
// reference model. The notch cut at the start (fracture/notch.hpp) gives the reference a
// split topology to read, as it would after tearing.
pt::Scene small_pull_scene() {
  pt::Scene s;
  s.sheet.cells = {6, 5, 3};
  s.material.fiber_length = 3.0;
  s.material.strain_intra = s.material.strain_inter = 5.0;
  s.material.strain_layer = s.material.strain_surface = 5.0;
  s.load.kind = "pull";
  s.load.grip_cells = 1;
  s.load.speed = 0.05;
  s.load.ramp_time = 2.0;
  s.world.drag = 0.05;
  s.load.notch = 2;
  return s;
}

struct Deviation {
  double position = 0.0, velocity = 0.0;  // largest |Δ| over nodes and axes
  double extent = 0.0, speed = 0.0;       // largest |p| and |v| of the reference
};

Deviation compare(const pt::Simulation& sim, const pt::ReferenceModel& ref) {
  const pt::NodeView n = sim.nodes();
  REQUIRE(n.count == ref.nodes().size());
  Deviation d;
  for (std::size_t i = 0; i < n.count; ++i) {
    const auto& r = ref.nodes()[i];
    const double p[3] = {n.px[i], n.py[i], n.pz[i]};
    const double v[3] = {n.vx[i], n.vy[i], n.vz[i]};
    for (std::size_t a = 0; a < 3; ++a) {
      d.position = std::max(d.position, std::fabs(p[a] - r.p[a]));
      d.velocity = std::max(d.velocity, std::fabs(v[a] - r.v[a]));
      d.extent = std::max(d.extent, std::fabs(r.p[a]));
      d.speed = std::max(d.speed, std::fabs(r.v[a]));
    }
  }
  return d;
}

using papertear::testing::perturb;  // tests/random_state.hpp

// The world a Simulation builds for the scene (fibre blocks included), perturbed, with
// per-cell stiffness factors in [0.7, 1.3] so that the kernels' scaling is exercised too.
// (The step stays stable: the scene's dt is half the limit at factor 1, and the limit only
// shrinks by 1/sqrt(1.3).)
// With random_scales, every cell gets its own stiffness factor, so no two cells' springs
// coincide (kernels/fine_springs.hpp) and each cell evaluates all 28; without, coincident
// springs are merged as in every scene the library builds.
pt::World perturbed_world(const pt::Scene& scene, std::uint32_t seed, float dp, float dv, bool random_scales = true) {
  pt::World w = pt::Simulation(scene, {.threads = 1}).world();
  perturb(w, seed, dp, dv);
  std::mt19937 rng(seed + 1);
  std::uniform_real_distribution<float> factor(0.7f, 1.3f);
  if (random_scales)
    for (float& f : w.topo.cell_scale) f = factor(rng);
  return w;
}

// Runs the solver and the reference side by side and checks they agree.
//
// Tolerance: the reference is the same equations in double, so the difference is the
// solver's float rounding.
//  * positions: each step rounds the stored position by up to kEpsF/2 of the largest
//    coordinate, a few times over the RK4 sums. These roundings can all have the same sign
//    (a gripped node adds the same small increment every step and rounds the same way each
//    time), so they are budgeted linearly: 4 n kEpsF |p|max. Velocity errors do not add up
//    into a growing position error: the grips pin the sheet (their velocity is prescribed
//    in both models) and the damping keeps the sheet's oscillations small.
//  * velocities: each step rounds the stored velocity (kEpsF |v|max) and, through the force
//    sums, the acceleration by a few kEpsF Σ k L0 / m (a spring's force k (L - L0) comes from
//    L, which carries an error of ~kEpsF L), for dt. These change sign from step to step and
//    node to node and grow like sqrt(n) (as measured); 16 sqrt(n) times the per-step amount
//    (4 stages of a few roundings each) is ~7x above the largest measured deviation.
// Against deliberately broken reference models — no drag, wrong RK4 weights or stage
// inputs, undamped block springs, no cell factor on k or c, a grip ramp one step late, no
// gravity — the runs below exceed these bounds by 5x to several hundred x.
void run_side_by_side(pt::World world, int steps) {
  pt::ReferenceModel ref(world);
  const std::size_t events = world.events.size();
  pt::Simulation sim(std::move(world), {.threads = 2});
  const double accel_scale = sim.dt() * pt::testing::max_spring_scale(ref);
  // Compared after every step, so that a difference in the fast early transient is seen
  // even after the damping has smoothed it out.
  double extent = 0.0, speed = 0.0, worst = 0.0;
  std::string report;
  for (int step = 1; step <= steps; ++step) {
    sim.step(1);
    ref.step(1);
    const Deviation d = compare(sim, ref);
    extent = std::max(extent, d.extent);
    speed = std::max(speed, d.speed);
    const double pos_tol = 4.0 * step * kEpsF * extent;
    const double vel_tol = 16.0 * std::sqrt(double(step)) * kEpsF * (speed + accel_scale);
    const double ratio = std::max(d.position / pos_tol, d.velocity / vel_tol);
    if (ratio > worst || step == 1) {
      worst = ratio;
      std::ostringstream msg;
      msg << "step " << step << " of " << steps << " (dt " << sim.dt() << "): position deviation "
          << d.position << " (tolerance " << pos_tol << "), velocity deviation " << d.velocity
          << " (tolerance " << vel_tol << ")";
      report = msg.str();
    }
  }
  REQUIRE(sim.world().events.size() == events);  // nothing tore: the reference has no fracture
  REQUIRE(ref.time() == Approx(sim.time()).epsilon(1e-6));
  INFO("worst " << report);
  CHECK(worst <= 1.0);
  // The run did move the sheet, so the comparison is not between two resting lattices.
  CHECK(speed > 1e-3);
}

struct Forces {
  std::vector<float> x, y, z;
  explicit Forces(std::size_t n) : x(n, 0.0f), y(n, 0.0f), z(n, 0.0f) {}
  pt::ForceOutputs outputs() { return {x.data(), y.data(), z.data()}; }
};

// The kernels' inputs at the node state, with the merged fine springs built for w (kept
// alive in `fine` while the inputs are used).
pt::CellForceInputs cell_inputs(const pt::World& w, pt::FineSprings& fine) {
  pt::build_fine_springs(w.topo, w.springs, fine);
  const pt::NodeStore& n = w.nodes;
  return {n.px.data(), n.py.data(), n.pz.data(), n.vx.data(), n.vy.data(), n.vz.data(),
          w.topo.cell_nodes.data(), w.topo.cell_scale.data(), &w.springs, &fine, &w.topo.dims};
}

using RowKernel = void (*)(int, int, const pt::CellForceInputs&, const pt::ForceOutputs&);

// The fine-spring kernel over rows of cells j in [j0, j1) (every row if j1 < 0), in one call.
Forces cell_forces(const pt::World& w, RowKernel kernel, int j0 = 0, int j1 = -1) {
  Forces f(w.nodes.count);
  pt::FineSprings fine;
  const pt::CellForceInputs in = cell_inputs(w, fine);
  kernel(j0, j1 < 0 ? w.topo.dims.ny : j1, in, f.outputs());
  return f;
}

// Adds the block springs' forces by the per-spring path and returns each spring's force.
pt::CoarseForceScratch add_coarse_forces(const pt::World& w, Forces& f) {
  const std::size_t n = w.coarse.size();
  pt::CoarseForceScratch scratch{std::vector<float>(n), std::vector<float>(n), std::vector<float>(n)};
  pt::FineSprings fine;
  pt::coarse_spring_forces(0, n, w.coarse, w.topo, cell_inputs(w, fine), scratch);
  pt::scatter_coarse_forces(w.coarse, w.topo, scratch, f.outputs());
  return scratch;
}

// Per-node bound on the float kernel's rounding error, from the springs at that node.
// One spring in float: d = x_b - x_a is exact to kEpsF/2 |d|; L = sqrt(d·d) to ~2 kEpsF L;
// so k (L - L0) is off by ~3 kEpsF k L, and c (Δv·d)/L by ~4 kEpsF c |Δv|; scaling by d/L
// adds ~3 kEpsF |f|. Summing m terms into a node adds at most m kEpsF Σ|f|. Twice that,
// for margin.
std::vector<double> force_tolerance(const pt::ReferenceModel& ref) {
  const auto& nodes = ref.nodes();
  std::vector<double> spring_part(nodes.size(), 0.0), force_sum(nodes.size(), 0.0);
  std::vector<int> terms(nodes.size(), 0);
  for (const auto& s : ref.springs()) {
    double d2 = 0.0, dv2 = 0.0;
    for (std::size_t a = 0; a < 3; ++a) {
      const double d = nodes[s.b].p[a] - nodes[s.a].p[a];
      const double dv = nodes[s.b].v[a] - nodes[s.a].v[a];
      d2 += d * d;
      dv2 += dv * dv;
    }
    const double len = std::sqrt(d2);
    const double f = std::fabs(s.k * (len - s.rest)) + s.c * std::sqrt(dv2);
    const double part = 3.0 * s.k * len + 4.0 * s.c * std::sqrt(dv2) + 3.0 * f;
    for (std::uint32_t node : {s.a, s.b}) {
      spring_part[node] += part;
      force_sum[node] += f;
      terms[node] += 1;
    }
  }
  std::vector<double> tol(nodes.size());
  for (std::size_t i = 0; i < nodes.size(); ++i)
    tol[i] = 2.0 * kEpsF * (spring_part[i] + terms[i] * force_sum[i]);
  return tol;
}

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::bit_cast<std::uint32_t>(a[i]) != std::bit_cast<std::uint32_t>(b[i])) return false;
  return true;
}

}  // namespace

TEST_CASE("the solver's strips add the same bits as one sweep of the rows when there is one strip", "[reference]") {
  // 37 cells per row: whole vectors and an overlapping last one; 7 cells per row: rows shorter
  // than a vector. The splits put split copies among the corners. One strip of rows: the
  // solver's region then runs the same rows in the same order as one call.
  for (int nx : {37, 7}) {
    pt::Scene scene = small_pull_scene();
    scene.sheet.cells = {nx, pt::kStripRows, 3};
    pt::World w = perturbed_world(scene, 41, 0.1f, 0.05f);
    const pt::LatticeDims& d = w.topo.dims;
    for (int i = 2; i < nx; i += 5)
      REQUIRE(pt::split_node(w, pt::NodeId(d.vertex_index(i, 2, 1)), i % 2 == 0 ? 0 : 1, 1).valid());
    const Forces rows = cell_forces(w, pt::add_cell_row_forces);
    Forces strips(w.nodes.count);
    pt::FineSprings fine;
    pt::add_fine_forces(w.topo, cell_inputs(w, fine), strips.outputs());
    INFO("cells per row " << nx);
    CHECK(same_bits(rows.x, strips.x));
    CHECK(same_bits(rows.y, strips.y));
    CHECK(same_bits(rows.z, strips.z));
    CHECK(*std::max_element(strips.x.begin(), strips.x.end()) > 1e-3f);  // the springs are loaded
  }
}

TEST_CASE("cells with split copies summed after the sweep: the same bits as one lane at a time", "[reference]") {
  // 37 cells per row: whole vectors and an overlapping last one; 21 and 7: rows of two
  // vectors or one and a remainder, or shorter than a vector (8 or 16 lanes). Splits all over
  // the sheet leave many vectors with a few lanes whose cell has a split copy among its
  // corners: those lanes add zeros in the sweep, and their cells are summed cell by cell
  // after their chunk (DirtyCells), in cell order whatever the vector width.
  const bool random_scales = GENERATE(true, false);
  const int nx = GENERATE(37, 21, 7);
  INFO("random stiffness factors: " << random_scales << ", cells per row " << nx);
  pt::Scene scene = small_pull_scene();
  scene.sheet.cells = {nx, 6, 3};
  pt::World w = perturbed_world(scene, 47, 0.1f, 0.05f, random_scales);
  const pt::LatticeDims& d = w.topo.dims;
  for (int i = 1; i < d.nx; i += 3)
    for (int j = 1; j < d.ny; j += 2)
      REQUIRE(pt::split_node(w, pt::NodeId(d.vertex_index(i, j, 1 + (i + j) % 2)), (i + j) % 3, j % 2).valid());
  pt::FineSprings fine;
  pt::build_fine_springs(w.topo, w.springs, fine);
  const std::size_t rows_with_copies =
      std::size_t(std::count_if(fine.rows.begin(), fine.rows.end(), [](const pt::FineRow& r) { return r.copies; }));
  const Forces wide = cell_forces(w, pt::add_cell_row_forces);
  const Forces scalar = cell_forces(w, pt::add_cell_row_forces_scalar);
  CHECK(same_bits(wide.x, scalar.x));
  CHECK(same_bits(wide.y, scalar.y));
  CHECK(same_bits(wide.z, scalar.z));
  CHECK(*std::max_element(wide.x.begin(), wide.x.end()) > 1e-3f);  // the springs are loaded
  CHECK(rows_with_copies >= fine.rows.size() / 2);                 // and many rows have copies
}

TEST_CASE("many strips of rows: the same bits on any thread count, one sweep's sums within rounding", "[reference]") {
  // Rows of vertices between strips get the lower strip's terms first, then the upper's: a
  // fixed order, but not the order of one sweep of all rows, so only rounding may differ.
  pt::Scene scene = small_pull_scene();
  scene.sheet.cells = {21, 5 * pt::kStripRows + 2, 3};
  const pt::World w = perturbed_world(scene, 43, 0.1f, 0.05f);
  const Forces rows = cell_forces(w, pt::add_cell_row_forces);
  pt::FineSprings fine;
  const pt::CellForceInputs in = cell_inputs(w, fine);
  Forces one(w.nodes.count);
  tbb::task_arena(1).execute([&] { pt::add_fine_forces(w.topo, in, one.outputs()); });
  for (int threads : {2, 3}) {
    Forces many(w.nodes.count);
    tbb::task_arena(threads).execute([&] { pt::add_fine_forces(w.topo, in, many.outputs()); });
    INFO(threads << " threads");
    CHECK(same_bits(one.x, many.x));
    CHECK(same_bits(one.y, many.y));
    CHECK(same_bits(one.z, many.z));
  }
  double largest = 0.0, worst = 0.0;
  for (std::size_t i = 0; i < w.nodes.count; ++i)
    for (const auto& [a, b] : {std::pair{one.x[i], rows.x[i]}, {one.y[i], rows.y[i]}, {one.z[i], rows.z[i]}}) {
      largest = std::max(largest, double(std::fabs(b)));
      worst = std::max(worst, double(std::fabs(a - b)));
    }
  REQUIRE(largest > 1e-3);
  CHECK(worst <= 1e-5 * largest);
}

TEST_CASE("solver follows the reference model on a pulled sheet", "[reference]") {
  // From rest: the grips and their ramp drive everything.
  run_side_by_side(pt::Simulation(small_pull_scene(), {.threads = 1}).world(), 300);
}

TEST_CASE("solver follows the reference model from a vibrating state", "[reference]") {
  // Large accelerations make the RK4 stages, damping and drag matter, not just the grips.
  run_side_by_side(perturbed_world(small_pull_scene(), 17, 0.05f, 0.05f), 150);
}

TEST_CASE("solver follows the reference model with gravity", "[reference]") {
  pt::Scene s = small_pull_scene();
  s.world.gravity = {0.0, 0.0, -0.01};
  s.load.speed = 0.01;
  run_side_by_side(perturbed_world(s, 23, 0.02f, 0.02f), 300);
}

TEST_CASE("reference model starts from the world it is given", "[reference]") {
  const pt::World w = perturbed_world(small_pull_scene(), 3, 0.1f, 0.05f);
  const pt::ReferenceModel ref(w);
  REQUIRE(ref.nodes().size() == w.nodes.count);
  std::size_t live_coarse = 0;
  for (std::size_t i = 0; i < w.coarse.size(); ++i)
    live_coarse += (w.coarse.stiffness[i] != 0.0f || w.coarse.damping[i] != 0.0f) ? 1 : 0;
  CHECK(live_coarse > 0);  // the scene has fibre blocks, so the coarse springs are exercised
  CHECK(w.nodes.count > std::size_t(w.topo.dims.vertices()));  // and a notch: split nodes
  CHECK(ref.springs().size() == std::size_t(w.topo.dims.cells()) * pt::kSpringsPerCell + live_coarse);
  CHECK(ref.time() == w.time);
  std::size_t mismatched = 0;
  for (std::size_t i = 0; i < w.nodes.count; ++i) {
    const auto& r = ref.nodes()[i];
    const bool same = r.p == std::array<double, 3>{w.nodes.px[i], w.nodes.py[i], w.nodes.pz[i]} &&
                      r.v == std::array<double, 3>{w.nodes.vx[i], w.nodes.vy[i], w.nodes.vz[i]} &&
                      r.mass == double(w.nodes.mass[i]) && r.free == (w.nodes.grip[i] == 0) &&
                      r.grip == w.nodes.grip[i];
    mismatched += same ? 0 : 1;
  }
  CHECK(mismatched == 0);
}

TEST_CASE("fine and coarse kernels match the reference spring forces", "[reference]") {
  const bool random_scales = GENERATE(true, false);
  INFO("random stiffness factors: " << random_scales);
  const pt::World w = perturbed_world(small_pull_scene(), 11, 0.1f, 0.05f, random_scales);
  const pt::ReferenceModel ref(w);
  Forces f = cell_forces(w, pt::add_cell_row_forces);
  add_coarse_forces(w, f);

  const auto expected = ref.spring_forces();
  const std::vector<double> tol = force_tolerance(ref);
  double worst_ratio = 0.0, largest_force = 0.0;
  std::size_t worst = 0;
  for (std::size_t i = 0; i < w.nodes.count; ++i) {
    const double got[3] = {f.x[i], f.y[i], f.z[i]};
    for (std::size_t a = 0; a < 3; ++a) {
      const double ratio = std::fabs(got[a] - expected[i][a]) / tol[i];
      largest_force = std::max(largest_force, std::fabs(expected[i][a]));
      if (ratio > worst_ratio) { worst_ratio = ratio; worst = i; }
    }
  }
  INFO("worst node " << worst << ": got (" << f.x[worst] << ", " << f.y[worst] << ", "
                     << f.z[worst] << "), reference (" << expected[worst][0] << ", "
                     << expected[worst][1] << ", " << expected[worst][2] << "), tolerance "
                     << tol[worst]);
  CHECK(worst_ratio <= 1.0);
  CHECK(largest_force > 1e-2);  // the perturbation really loads the springs
}

// The solver's block-lattice path (packed corners, per-block sums, the gather) against the
// per-spring path on the same world, node by node: the two add the same terms in different
// orders, so they agree within m kEpsF of the sum of the m terms' sizes at a node (the check
// allows 2 (m + 2) kEpsF). Returns the nodes off and the largest per-spring node force.
struct LatticeComparison {
  std::size_t wrong = 0;
  double largest = 0.0;
};

LatticeComparison compare_block_lattice(const pt::World& w, pt::BlockLattice& L) {
  pt::FineSprings fine;
  const pt::CellForceInputs in = cell_inputs(w, fine);
  for (std::size_t b = 0; b < L.lanes; b += pt::kBlockChunk)
    pt::refresh_block_lattice(b, std::min(L.lanes, b + pt::kBlockChunk), w.topo, w.blocks, L);
  pt::block_lattice_forces(0, L.lanes, in, L);
  const std::size_t vertices = L.first.size() - 1;
  for (std::size_t v = 0; v < vertices; v += 1000) pt::refresh_block_entries(v, std::min(vertices, v + 1000), L);
  Forces lattice(w.nodes.count);
  pt::gather_block_lattice_forces(0, vertices, L, lattice.outputs());

  Forces springs(w.nodes.count);
  const pt::CoarseForceScratch per = add_coarse_forces(w, springs);
  const std::size_t n = w.coarse.size();
  std::vector<double> size(w.nodes.count, 0.0);
  std::vector<int> terms(w.nodes.count, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const double f = std::fabs(per.fx[i]) + std::fabs(per.fy[i]) + std::fabs(per.fz[i]);
    for (std::uint32_t node : {w.topo.node(w.coarse.cell_a[i], w.coarse.corner_a[i]),
                               w.topo.node(w.coarse.cell_b[i], w.coarse.corner_b[i])}) {
      size[node] += f;
      terms[node] += 1;
    }
  }
  LatticeComparison c;
  for (std::size_t i = 0; i < w.nodes.count; ++i) {
    const double tol = 2.0 * kEpsF * (terms[i] + 2) * size[i];
    c.wrong += std::fabs(lattice.x[i] - springs.x[i]) > tol || std::fabs(lattice.y[i] - springs.y[i]) > tol ||
                       std::fabs(lattice.z[i] - springs.z[i]) > tol
                   ? 1
                   : 0;
    c.largest = std::max({c.largest, double(std::fabs(springs.x[i])), double(std::fabs(springs.y[i])),
                          double(std::fabs(springs.z[i]))});
  }
  return c;
}

TEST_CASE("the block lattice's packed corners give the per-spring forces before and after splits", "[reference]") {
  pt::Scene scene = small_pull_scene();
  scene.sheet.cells = {40, 12, 3};
  pt::World w = perturbed_world(scene, 23, 0.1f, 0.05f);
  pt::BlockLattice L;
  pt::build_block_lattice(w.coarse, w.blocks, w.topo.dims, L);
  REQUIRE(L.lanes > 2 * pt::kPackLanes);  // several packs
  const LatticeComparison whole = compare_block_lattice(w, L);
  CHECK(whole.wrong == 0);
  CHECK(whole.largest > 1e-2);  // the perturbation loads the block springs

  // Splits give block corners new nodes; moving every node afterwards makes the copies'
  // state differ from their originals', so a pack left with its old rows reads wrong values.
  const auto before = std::vector<std::uint32_t>(L.corner_node.begin(), L.corner_node.end());
  const pt::LatticeDims& d = w.topo.dims;
  for (int i = 3; i < d.nx; i += 4)
    for (int j = 1; j < d.ny; j += 3)
      REQUIRE(pt::split_node(w, pt::NodeId(d.vertex_index(i, j, 1)), (i + j) % 2, 1).valid());
  perturb(w, 29, 0.05f, 0.05f);
  const LatticeComparison split = compare_block_lattice(w, L);
  CHECK(split.wrong == 0);
  CHECK(split.largest > 1e-2);
  std::size_t moved = 0;
  for (std::size_t i = 0; i < before.size(); ++i) moved += before[i] != L.corner_node[i] ? 1 : 0;
  CHECK(moved > 0);
}

// The solver orders a block chunk's task only before the bands of rows that hold its blocks'
// corners (core/solver.cpp), so pass 1 may load no other node's state: not for a corner that
// no spring joins, nor for a padding lane. A load of node 0 there raced with band 0's update.
TEST_CASE("a block lane loads only corners of its own block, padding lanes those of the last block", "[reference]") {
  for (const std::array<int, 3> cells : {std::array<int, 3>{40, 12, 3}, std::array<int, 3>{30, 30, 3}}) {
    pt::Scene scene = small_pull_scene();
    scene.sheet.cells = cells;
    const pt::World w = pt::Simulation(scene, {.threads = 1}).world();
    pt::BlockLattice L;
    pt::build_block_lattice(w.coarse, w.blocks, w.topo.dims, L);
    const std::size_t real = std::size_t(std::find(L.block.begin(), L.block.end(), UINT32_MAX) - L.block.begin());
    REQUIRE(real > 0);
    std::size_t unused = 0;  // the cases this test is for: corners no spring joins, padding lanes
    std::vector<std::uint8_t> used(8 * L.lanes, 0);
    for (std::size_t j = 0; j < real; ++j) {
      const pt::Block& blk = w.blocks[L.block[j]];
      for (std::uint32_t i = blk.first_spring; i < blk.first_spring + blk.spring_count; ++i)
        used[w.coarse.corner_a[i] * L.lanes + j] = used[w.coarse.corner_b[i] * L.lanes + j] = 1;
    }
    for (std::size_t j = 0; j < L.lanes; ++j)
      for (int q = 0; q < 8; ++q) {
        unused += used[std::size_t(q) * L.lanes + j] ? 0 : 1;
        const pt::Block& blk = w.blocks[L.block[std::min(j, real - 1)]];
        const std::uint32_t slot = L.corner_slot[std::size_t(q) * L.lanes + j];
        const std::array<int, 3> v = w.topo.dims.vertex_ijk(w.topo.dims.corner_vertex(slot / 8, int(slot % 8)));
        for (int a = 0; a < 3; ++a) {
          INFO("lane " << j << " of " << real << " blocks, corner " << q << ", axis " << a);
          CHECK((v[std::size_t(a)] == blk.lo[std::size_t(a)] || v[std::size_t(a)] == blk.hi[std::size_t(a)]));  // hi: exclusive in cells
        }
      }
    CHECK(unused > 0);
  }
}

// The lanes run by the blocks' first row (the solver's strips and node bands are by rows), but
// a node must still get its blocks' corner sums in ascending block id: the sum below is that
// definition, block by block over the corners their springs join, straight from the blocks.
TEST_CASE("the block gather adds a node's corner sums in block id order, whatever the lane order", "[reference]") {
  pt::Scene scene = small_pull_scene();
  scene.sheet.cells = {40, 12, 3};
  const pt::World w = perturbed_world(scene, 31, 0.1f, 0.05f);
  pt::BlockLattice L;
  pt::build_block_lattice(w.coarse, w.blocks, w.topo.dims, L);
  std::vector<std::uint32_t> lane_of(w.blocks.size(), UINT32_MAX);
  bool by_row = true, reordered = false;
  for (std::size_t j = 0; j < L.lanes && L.block[j] != UINT32_MAX; ++j) {
    lane_of[L.block[j]] = std::uint32_t(j);
    if (j > 0) {
      by_row &= w.blocks[L.block[j - 1]].lo[1] <= w.blocks[L.block[j]].lo[1];
      reordered |= L.block[j - 1] > L.block[j];
    }
  }
  CHECK(by_row);
  REQUIRE(reordered);  // the case this test is for: lane order is not block id order

  pt::FineSprings fine;
  const pt::CellForceInputs in = cell_inputs(w, fine);
  pt::refresh_block_lattice(0, L.lanes, w.topo, w.blocks, L);
  pt::block_lattice_forces(0, L.lanes, in, L);
  const std::size_t vertices = L.first.size() - 1;
  pt::refresh_block_entries(0, vertices, L);
  Forces gathered(w.nodes.count);
  pt::gather_block_lattice_forces(0, vertices, L, gathered.outputs());

  Forces expected(w.nodes.count);
  for (std::uint32_t b = 0; b < w.blocks.size(); ++b) {
    const pt::Block& blk = w.blocks[b];
    if (blk.spring_count == 0) continue;
    REQUIRE(lane_of[b] != UINT32_MAX);
    std::array<std::uint32_t, 8> cell_of{};
    std::array<bool, 8> used{};
    for (std::uint32_t i = blk.first_spring; i < blk.first_spring + blk.spring_count; ++i) {
      used[w.coarse.corner_a[i]] = used[w.coarse.corner_b[i]] = true;
      cell_of[w.coarse.corner_a[i]] = w.coarse.cell_a[i];
      cell_of[w.coarse.corner_b[i]] = w.coarse.cell_b[i];
    }
    for (int q = 0; q < 8; ++q) {
      if (!used[std::size_t(q)]) continue;
      const std::uint32_t node = w.topo.node(cell_of[std::size_t(q)], q);
      const std::size_t at = std::size_t(q) * L.lanes + lane_of[b];
      expected.x[node] += L.fx[at];
      expected.y[node] += L.fy[at];
      expected.z[node] += L.fz[at];
    }
  }
  CHECK(same_bits(gathered.x, expected.x));
  CHECK(same_bits(gathered.y, expected.y));
  CHECK(same_bits(gathered.z, expected.z));
  CHECK(*std::max_element(expected.x.begin(), expected.x.end()) > 1e-3f);  // the block springs are loaded
}

TEST_CASE("vector and scalar sweeps give the same bits", "[reference]") {
  const bool random_scales = GENERATE(true, false);
  INFO("random stiffness factors: " << random_scales);
  pt::Scene scene = small_pull_scene();
  scene.sheet.cells = {37, 5, 3};  // rows of whole vectors and an overlapping last one
  const pt::World w = perturbed_world(scene, 29, 0.1f, 0.05f, random_scales);
  const Forces wide = cell_forces(w, pt::add_cell_row_forces);
  const Forces scalar = cell_forces(w, pt::add_cell_row_forces_scalar);
  CHECK(same_bits(wide.x, scalar.x));
  CHECK(same_bits(wide.y, scalar.y));
  CHECK(same_bits(wide.z, scalar.z));

  // Some rows only, as a strip takes them.
  const Forces a = cell_forces(w, pt::add_cell_row_forces, 1, 3), b = cell_forces(w, pt::add_cell_row_forces_scalar, 1, 3);
  CHECK(same_bits(a.x, b.x));
  CHECK(same_bits(a.y, b.y));
  CHECK(same_bits(a.z, b.z));
  CHECK(*std::max_element(a.x.begin(), a.x.end()) > 1e-3f);  // the rows' springs are loaded
}

TEST_CASE("rows longer than a chunk: vector and scalar sweeps give the same bits", "[reference]") {
  // A row of kRowChunk + 19 cells is swept as two chunks; the node between them gets the
  // first chunk's terms, then the second's.
  pt::Scene scene = small_pull_scene();
  scene.sheet.cells = {int(pt::kRowChunk) + 19, 4, 2};
  const pt::World w = perturbed_world(scene, 31, 0.1f, 0.05f);
  const Forces wide = cell_forces(w, pt::add_cell_row_forces);
  const Forces scalar = cell_forces(w, pt::add_cell_row_forces_scalar);
  CHECK(same_bits(wide.x, scalar.x));
  CHECK(same_bits(wide.y, scalar.y));
  CHECK(same_bits(wide.z, scalar.z));
  const pt::ReferenceModel ref(w);
  const auto expected = ref.spring_forces();
  Forces with_coarse = wide;
  add_coarse_forces(w, with_coarse);
  const std::vector<double> tol = force_tolerance(ref);
  std::size_t off = 0;
  for (std::size_t i = 0; i < w.nodes.count; ++i)
    off += std::fabs(with_coarse.x[i] - expected[i][0]) > tol[i] || std::fabs(with_coarse.y[i] - expected[i][1]) > tol[i] ||
                   std::fabs(with_coarse.z[i] - expected[i][2]) > tol[i]
               ? 1
               : 0;
  CHECK(off == 0);  // and both chunks' springs are all there
}
