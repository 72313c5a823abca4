#include "core/solver.hpp"

#include <limits>
#include <sstream>

#include "core/lattice_builder.hpp"
#include "core/simulation.hpp"
#include "kernels/cell_forces.hpp"
#include "kernels/parallel.hpp"
#include "kernels/rk4.hpp"

namespace papertear {
namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

CellForceInputs stage_inputs(const World& w) {
  const IntegratorScratch& s = w.scratch;
  return {s.sx.data(), s.sy.data(), s.sz.data(), s.svx.data(), s.svy.data(), s.svz.data(),
          w.topo.cell_nodes.data(), w.topo.cell_scale.data(), &w.springs};
}

// Gripped nodes move at the grip's (ramped) velocity for the whole step: their acceleration
// is 0 in every stage, so setting v (and the stage velocity) once is enough.
void drive_grips(World& w) {
  const float ramp = grip_ramp(w.scene.load, w.time);
  for (std::uint32_t n : w.gripped_nodes) {
    const Grip& g = w.grips[w.nodes.grip[n] - 1u];
    w.nodes.vx[n] = w.scratch.svx[n] = g.velocity[0] * ramp;
    w.nodes.vy[n] = w.scratch.svy[n] = g.velocity[1] * ramp;
    w.nodes.vz[n] = w.scratch.svz[n] = g.velocity[2] * ramp;
  }
}

StageParams stage_params(const World& w, int stage) {
  StageParams p;
  p.stage = stage;
  p.dt = float(w.dt);
  for (int a = 0; a < 3; ++a) p.gravity[a] = float(w.scene.world.gravity[std::size_t(a)]);
  p.drag = float(w.scene.world.drag);
  return p;
}

[[noreturn]] void report_blow_up(const World& w, std::uint32_t node) {
  std::ostringstream msg;
  msg << "numerical blow-up at step " << w.step + 1 << ": node " << node
      << " (lattice vertex " << w.nodes.vertex[node] << ") reached position (" << w.nodes.px[node]
      << ", " << w.nodes.py[node] << ", " << w.nodes.pz[node] << ") velocity (" << w.nodes.vx[node]
      << ", " << w.nodes.vy[node] << ", " << w.nodes.vz[node]
      << "); the time step is probably too large for the material (try a smaller run.dt or dt_safety)";
  throw BlowUpError(msg.str(), w.step + 1, node);
}

}  // namespace

void evaluate_forces(World& w, SolverScratch& scratch) {
  const CellForceInputs in = stage_inputs(w);
  const ForceOutputs out{w.scratch.fx.data(), w.scratch.fy.data(), w.scratch.fz.data()};
  for (const auto& cells : w.topo.colour_cells)
    parallel_chunks(cells.size(), kCellChunk, [&](std::size_t b, std::size_t e, std::size_t) {
      add_cell_forces(b, e, cells.data(), in, out);
    });
  const std::size_t n = w.coarse.size();
  if (n == 0) return;
  scratch.coarse.fx.resize(n);
  scratch.coarse.fy.resize(n);
  scratch.coarse.fz.resize(n);
  parallel_chunks(n, kSpringChunk, [&](std::size_t b, std::size_t e, std::size_t) {
    coarse_spring_forces(b, e, w.coarse, w.topo, in, scratch.coarse);
  });
  scatter_coarse_forces(w.coarse, w.topo, scratch.coarse, out);
}

void integrate_step(World& w, SolverScratch& scratch) {
  drive_grips(w);
  const std::size_t n = w.nodes.count;
  scratch.bad.assign(chunk_count(n, kNodeChunk), kNone);
  for (int stage = 1; stage <= 4; ++stage) {
    evaluate_forces(w, scratch);
    const StageParams params = stage_params(w, stage);
    parallel_chunks(n, kNodeChunk, [&](std::size_t b, std::size_t e, std::size_t c) {
      scratch.bad[c] = rk4_stage(b, e, params, w.nodes, w.scratch);
    });
  }
  for (std::uint32_t bad : scratch.bad)
    if (bad != kNone) report_blow_up(w, bad);
  w.time += w.dt;
}

}  // namespace papertear
