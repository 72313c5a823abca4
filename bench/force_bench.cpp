// The fine-spring force kernel alone (kernels/cell_forces.hpp): one force evaluation over
// every row of cells by the solver's strips (add_fine_forces, core/solver.hpp), inside a
// task arena of the case's thread count. This is the solver's hot loop without the node
// update, the block-lattice springs or the fracture pass around it.
#include <cstddef>

#include <oneapi/tbb/task_arena.h>

#include "bench_cases.hpp"
#include "core/aligned_array.hpp"
#include "core/simulation.hpp"
#include "core/solver.hpp"
#include "kernels/cell_forces.hpp"

namespace papertear::bench {
namespace {

// A few steps so that springs are stretched and the forces are not all zero.
constexpr int kWarmupSteps = 10;

struct ForceColumns {
  AlignedArray<float> fx{7}, fy{8}, fz{9};
  explicit ForceColumns(std::size_t n) {
    fx.resize(n);
    fy.resize(n);
    fz.resize(n);
  }
  ForceOutputs outputs() { return {fx.data(), fy.data(), fz.data()}; }
};

CellForceInputs node_state_inputs(const World& w, FineSprings& fine) {
  build_fine_springs(w.topo, w.springs, fine);
  const NodeStore& n = w.nodes;
  return {n.px.data(), n.py.data(), n.pz.data(), n.vx.data(), n.vy.data(), n.vz.data(),
          w.topo.cell_nodes.data(), w.topo.cell_scale.data(), &w.springs, &fine, &w.topo.dims};
}

void force_papertear(benchmark::State& state, Case c) {
  Simulation sim(quiet_pull_scene(c.size), {.threads = 1});
  sim.step(kWarmupSteps);
  const World& world = sim.world();
  FineSprings fine;
  const CellForceInputs in = node_state_inputs(world, fine);
  // Forces accumulate over iterations, as they would over a stage's kernels; the values stay finite
  // and the work per iteration is the same.
  ForceColumns forces(world.nodes.count);
  const ForceOutputs out = forces.outputs();
  tbb::task_arena arena(c.threads);
  double seconds = 0.0;
  for (auto _ : state) {
    const double t = timed([&] { arena.execute([&] { add_fine_forces(world.topo, in, out); }); });
    benchmark::ClobberMemory();
    state.SetIterationTime(t);
    seconds += t;
  }
  const double springs = double(kSpringsPerCell) * double(c.size.cells());
  set_throughput_counters(state, c.size, springs, seconds, "ns_per_cell");
}

}  // namespace

void register_force_benchmarks() {
  for (const Case& c : papertear_cases()) {
    register_timed(case_name("force", "papertear", c), benchmark::kMicrosecond, force_papertear, c);
  }
}

}  // namespace papertear::bench
