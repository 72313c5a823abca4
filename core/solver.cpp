#include "core/solver.hpp"

#include <algorithm>
#include <limits>
#include <sstream>

#include "core/contact.hpp"
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

// Runs two independent chunked loops as one parallel region: one barrier instead of two.
// Chunk boundaries are those each loop would have alone, so nothing depends on the thread
// count.
template <class BodyA, class BodyB>
void parallel_chunks_pair(std::size_t na, std::size_t chunk_a, const BodyA& body_a, std::size_t nb,
                          std::size_t chunk_b, const BodyB& body_b) {
  const std::size_t ca = chunk_count(na, chunk_a), cb = chunk_count(nb, chunk_b);
  parallel_chunks(ca + cb, 1, [&](std::size_t c, std::size_t, std::size_t) {
    if (c < ca) {
      const std::size_t b = c * chunk_a;
      body_a(b, std::min(b + chunk_a, na));
    } else {
      const std::size_t b = (c - ca) * chunk_b;
      body_b(b, std::min(b + chunk_b, nb));
    }
  });
}

}  // namespace

void evaluate_forces(World& w, SolverScratch& scratch) {
  const CellForceInputs in = stage_inputs(w);
  const ForceOutputs out{w.scratch.fx.data(), w.scratch.fy.data(), w.scratch.fz.data()};
  BlockLattice& lattice = scratch.lattice;
  if (!lattice.matches(w.coarse)) build_block_lattice(w.coarse, w.blocks, w.topo.dims, lattice);
  // Colour 0 shares its region with pass 1 of the block lattice: both read the stage state
  // and they write disjoint outputs (node forces vs per-block corner sums).
  const auto& first = w.topo.colour_cells[0];
  parallel_chunks_pair(
      first.size(), kCellChunk, [&](std::size_t b, std::size_t e) { add_cell_forces(b, e, first.data(), in, out); },
      lattice.lanes, kBlockChunk, [&](std::size_t b, std::size_t e) { block_lattice_forces(b, e, in, lattice); });
  for (std::size_t colour = 1; colour < w.topo.colour_cells.size(); ++colour) {
    const auto& cells = w.topo.colour_cells[colour];
    parallel_chunks(cells.size(), kCellChunk, [&](std::size_t b, std::size_t e, std::size_t) {
      add_cell_forces(b, e, cells.data(), in, out);
    });
  }
  if (lattice.lanes == 0) return;
  parallel_chunks(lattice.first.size() - 1, kVertexChunk, [&](std::size_t b, std::size_t e, std::size_t) {
    gather_block_lattice_forces(b, e, lattice, w.blocks, w.topo, out);
  });
}

void integrate_step(World& w, SolverScratch& scratch) {
  drive_grips(w);
  const std::size_t n = w.nodes.count;
  scratch.bad.assign(chunk_count(n, kNodeChunk), kNone);
  // The indenter (pierce only) is where it is at each stage's time: t, t + dt/2 twice, t + dt.
  const std::optional<Indenter> indenter = make_indenter(w);
  constexpr double kStageTime[4] = {0.0, 0.5, 0.5, 1.0};
  for (int stage = 1; stage <= 4; ++stage) {
    evaluate_forces(w, scratch);
    if (indenter) apply_contact(w, *indenter, w.time + kStageTime[stage - 1] * w.dt);
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
