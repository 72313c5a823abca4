#include "core/solver.hpp"

#include <algorithm>
#include <cassert>
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

CellForceInputs stage_inputs(const World& w, const SolverScratch& scratch) {
  const IntegratorScratch& s = w.scratch;
  return {s.sx.data(),   s.sy.data(),   s.sz.data(), s.svx.data(), s.svy.data(), s.svz.data(), w.topo.cell_nodes.data(),
          w.topo.cell_scale.data(), &w.springs, &scratch.fine, &w.topo.dims};
}

// Brings the merged fine springs, and the kernel's plan of each row of cells, up to date with
// the topology. Fracture records every split as an event and adds one node per split, so
// when the counts agree only the cells around the new events' vertices can have changed;
// anything else (a new world, splits made outside the fracture pass) rebuilds the table.
// Returns false when nothing had changed since the last call (no split: the block lattice's
// refresh can be skipped too, since a block is entered only by a split).
bool sync_fine_springs(const World& w, SolverScratch& scratch) {
  const std::size_t cells = std::size_t(w.topo.dims.cells());
  const bool incremental = scratch.fine_topology == w.topo.cell_nodes.data() && scratch.fine.cells == cells &&
                           w.nodes.count >= scratch.fine_nodes && w.events.size() >= scratch.fine_events &&
                           w.nodes.count - scratch.fine_nodes == w.events.size() - scratch.fine_events;
  const bool changed = !incremental || w.nodes.count != scratch.fine_nodes;
  if (!incremental) {
    const FineSpringsBuild build = prepare_fine_springs(w.topo, w.springs, scratch.fine);
    parallel_chunks(cells, kCellChunk, [&](std::size_t b, std::size_t e, std::size_t) {
      assign_fine_springs(b, e, w.topo, w.springs, build, scratch.fine);
    });
    constexpr std::size_t kPlanRows = 16;
    parallel_chunks(scratch.fine.rows.size(), kPlanRows,
                    [&](std::size_t b, std::size_t e, std::size_t) { plan_fine_rows(b, e, w.topo, scratch.fine); });
  } else if (changed) {
    for (std::size_t e = scratch.fine_events; e < w.events.size(); ++e)
      update_fine_springs_at(w.topo, w.springs, w.nodes.vertex[w.events[e].node], scratch.fine);
    plan_stale_dirty_cells(w.topo, scratch.fine);
  }
  scratch.fine_topology = w.topo.cell_nodes.data();
  scratch.fine_nodes = w.nodes.count;
  scratch.fine_events = w.events.size();
  return changed;
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
// count. The region's chunks are A's first half, B's first half, A's second half, B's second
// half: TBB hands the first half of a range to the calling thread and the second to the
// thread that steals it, so on 2 threads each takes about half of each loop, and with A the
// strips, the same half of the sheet as in the regions before and after (see NodeBands).
template <class BodyA, class BodyB>
void parallel_chunks_pair(std::size_t na, std::size_t chunk_a, const BodyA& body_a, std::size_t nb,
                          std::size_t chunk_b, const BodyB& body_b) {
  const std::size_t ca = chunk_count(na, chunk_a), cb = chunk_count(nb, chunk_b);
  const std::size_t ha = (ca + 1) / 2, hb = (cb + 1) / 2;
  auto run_a = [&](std::size_t c) {
    const std::size_t b = c * chunk_a;
    body_a(b, std::min(b + chunk_a, na));
  };
  auto run_b = [&](std::size_t c) {
    const std::size_t b = c * chunk_b;
    body_b(b, std::min(b + chunk_b, nb));
  };
  parallel_chunks(ca + cb, 1, [&](std::size_t c, std::size_t, std::size_t) {
    if (c < ha) run_a(c);
    else if (c < ha + hb) run_b(c - ha);
    else if (c < ca + hb) run_a(c - hb);
    else run_b(c - ca);
  });
}

// The fine springs by strips of rows: a strip is kStripRows consecutive values of j (all k);
// its task sweeps its rows of cells (kernels/cell_forces.hpp) one after another while the
// strip's nodes are in cache. Even strips run in one parallel region, odd strips in the
// next: strips of one parity are at least a strip apart, so they never share a node. A node
// inside a strip gets its terms in the strip's row order; a node on the row of vertices
// between two strips gets the even strip's terms, then the odd strip's. Strips depend on
// the lattice size alone, so the order, and the bits, do not depend on the thread count.
struct FineStrips {
  const Topology* topo = nullptr;
  std::size_t strips = 0;

  void run(std::size_t strip, const CellForceInputs& in, const ForceOutputs& out) const {
    const int j0 = int(strip) * kStripRows, j1 = std::min(topo->dims.ny, j0 + kStripRows);
    add_cell_row_forces(j0, j1, in, out);
  }
  std::size_t even_strips() const { return (strips + 1) / 2; }
  std::size_t odd_strips() const { return strips / 2; }
  // The region of the odd strips (whose neighbours, the even strips, have run).
  void run_odd(const CellForceInputs& in, const ForceOutputs& out) const {
    parallel_chunks(odd_strips(), 1, [&](std::size_t t, std::size_t, std::size_t) { run(2 * t + 1, in, out); });
  }
};

FineStrips fine_strips(const Topology& topo) {
  return {&topo, chunk_count(std::size_t(std::max(topo.dims.ny, 0)), std::size_t(kStripRows))};
}

// All fine springs and pass 1 of the block lattice (which shares the first phase's region:
// both read the stage state and they write disjoint outputs, node forces vs per-block
// corner sums). The block sums still have to be gathered. `new_topology`: nodes may have been
// split or blocks entered since the last call, so the block lattice is refreshed. Returns
// whether it was (also when it had to be built), i.e. whether the gather's entries must be.
bool add_fine_and_block_forces(World& w, SolverScratch& scratch, const CellForceInputs& in,
                               const ForceOutputs& out, bool new_topology) {
  BlockLattice& lattice = scratch.lattice;
  if (!lattice.matches(w.coarse)) {
    build_block_lattice(w.coarse, w.blocks, w.topo.dims, lattice);
    new_topology = true;
  }
  const FineStrips strips = fine_strips(w.topo);
  parallel_chunks_pair(
      strips.even_strips(), 1, [&](std::size_t t, std::size_t) { strips.run(2 * t, in, out); },
      lattice.lanes, kBlockChunk, [&](std::size_t b, std::size_t e) {
        if (new_topology) refresh_block_lattice(b, e, w.topo, w.blocks, lattice);
        block_lattice_forces(b, e, in, lattice);
      });
  strips.run_odd(in, out);
  return new_topology;
}

ForceOutputs force_outputs(World& w) { return {w.scratch.fx.data(), w.scratch.fy.data(), w.scratch.fz.data()}; }

// Nodes below this id are updated in the gather's region (see stage_nodes); a multiple of
// every vector width, so the rest starts aligned.
std::size_t fused_node_end(const World& w) {
  const std::size_t vertices = std::size_t(w.topo.dims.vertices());
  return std::min(w.nodes.count, vertices / 64 * 64);
}

// The fused region's nodes by bands of vertex rows, one band per strip of fine springs: band s
// holds, in every layer K, the vertices of rows [s * kStripRows, (s + 1) * kStripRows) (the
// last band up to row ny), i.e. nl + 1 runs of node ids. Why bands and not chunks of ids: ids
// run layer after layer, so a chunk of ids is a few rows of every strip, and the update of
// nodes whose forces the other thread has just summed, and whose new state it will read in
// the next stage's sweep, moves their cache lines between cores four times a stage. A band
// is the nodes of one strip (TBB hands out both in the same order, so on 2 threads mostly
// to the same thread). Run boundaries are rounded down to multiples of 64 ids, so updates
// start aligned and two bands never write one cache line.
struct NodeBands {
  std::size_t bands = 0, vertices = 0, fused = 0;
  std::size_t row_len = 0, layer_rows = 0;  // vertices per row, rows per layer
  int layers = 0, ny = 0;

  // First node of band s's run in layer K (s == bands: the next layer's first run).
  std::size_t at(std::size_t s, int K) const {
    const std::size_t row = s < bands ? s * std::size_t(kStripRows) : std::size_t(ny) + 1;
    return std::min(fused, row_len * (row + layer_rows * std::size_t(K)) / 64 * 64);
  }
  // Calls run(begin, end, gather_end) for band s's runs: nodes [begin, end) are updated and
  // vertices [begin, gather_end) gathered; the last run gathers up to the last vertex, whose
  // nodes past `fused` the tail region updates.
  template <class Run>
  void for_each_run(std::size_t s, const Run& run) const {
    for (int K = 0; K < layers; ++K) {
      const std::size_t b = at(s, K), e = at(s + 1, K);
      run(b, e, s + 1 == bands && K + 1 == layers ? vertices : e);
    }
  }
};

NodeBands node_bands(const World& w) {
  const LatticeDims& d = w.topo.dims;
  NodeBands nb;
  nb.bands = fine_strips(w.topo).strips;
  nb.vertices = std::size_t(d.vertices());
  nb.fused = fused_node_end(w);
  nb.row_len = std::size_t(d.nx) + 1;
  nb.layer_rows = std::size_t(d.ny) + 1;
  nb.layers = d.nl + 1;
  nb.ny = d.ny;
  return nb;
}

// Gathers the block sums and runs the RK4 node stage in one region. Node n < vertices sits
// at vertex n (splits append new ids), so once a task has gathered a run of vertices the
// nodes of that run have their whole force and it updates them at once, while they are in
// cache. Nodes from splits (and the few original ones past the last multiple of 64) wait for
// all gathers and are updated after the region. RK4 is per node and a vertex's gather sums
// its entries in a fixed order, so the partition cannot change the bits; `bad` holds per
// task the first node that blew up, in node order.
// `refreshed`: pass 1 has just refreshed the block lattice, so each task first records its
// vertices' entry nodes for the gather.
void stage_nodes(World& w, SolverScratch& scratch, const ForceOutputs& out, const StageParams& params,
                 bool refreshed) {
  BlockLattice& lattice = scratch.lattice;
  const NodeBands bands = node_bands(w);
  parallel_chunks(bands.bands, 1, [&](std::size_t s, std::size_t, std::size_t) {
    std::uint32_t bad = kNone;
    bands.for_each_run(s, [&](std::size_t b, std::size_t e, std::size_t gather_end) {
      if (lattice.lanes != 0) {
        if (refreshed) refresh_block_entries(b, gather_end, lattice);
        gather_block_lattice_forces(b, gather_end, lattice, out);
      }
      if (b < e) bad = std::min(bad, rk4_stage(b, e, params, w.nodes, w.scratch));
    });
    scratch.bad[s] = bad;
  });
  const std::size_t fused = bands.fused;
  parallel_chunks(w.nodes.count - fused, kNodeChunk, [&](std::size_t b, std::size_t e, std::size_t c) {
    scratch.bad[bands.bands + c] = rk4_stage(fused + b, fused + e, params, w.nodes, w.scratch);
  });
}

}  // namespace

void add_fine_forces(const Topology& topo, const CellForceInputs& in, const ForceOutputs& out) {
  const FineStrips strips = fine_strips(topo);
  parallel_chunks(strips.even_strips(), 1, [&](std::size_t t, std::size_t, std::size_t) { strips.run(2 * t, in, out); });
  strips.run_odd(in, out);
}

void evaluate_forces(World& w, SolverScratch& scratch) {
  sync_fine_springs(w, scratch);
  const CellForceInputs in = stage_inputs(w, scratch);
  const ForceOutputs out = force_outputs(w);
  add_fine_and_block_forces(w, scratch, in, out, true);
  BlockLattice& lattice = scratch.lattice;
  if (lattice.lanes == 0) return;
  parallel_chunks(lattice.first.size() - 1, kVertexChunk, [&](std::size_t b, std::size_t e, std::size_t) {
    refresh_block_entries(b, e, lattice);
    gather_block_lattice_forces(b, e, lattice, out);
  });
}

void integrate_step(World& w, SolverScratch& scratch) {
  drive_grips(w);
  scratch.bad.assign(fine_strips(w.topo).strips + chunk_count(w.nodes.count - fused_node_end(w), kNodeChunk), kNone);
  const bool new_topology = sync_fine_springs(w, scratch);
  const CellForceInputs in = stage_inputs(w, scratch);
  const ForceOutputs out = force_outputs(w);
  // The indenter (pierce only) is where it is at each stage's time: t, t + dt/2 twice, t + dt.
  // Its push goes in first, while the force columns are still zero (the previous stage's
  // RK4 update cleared them): the springs then add to it, and the fused gather + RK4 region
  // sees every force a node gets.
  const std::optional<Indenter> indenter = make_indenter(w);
  constexpr double kStageTime[4] = {0.0, 0.5, 0.5, 1.0};
  for (int stage = 1; stage <= 4; ++stage) {
    if (indenter) apply_contact(w, *indenter, w.time + kStageTime[stage - 1] * w.dt);
    // Splits come between steps, so only the first stage may see a new topology.
    const bool refreshed = add_fine_and_block_forces(w, scratch, in, out, stage == 1 && new_topology);
    stage_nodes(w, scratch, out, stage_params(w, stage), refreshed);
  }
  // The first node in id order (the bands' runs interleave across layers).
  const std::uint32_t bad = scratch.bad.empty() ? kNone : *std::min_element(scratch.bad.begin(), scratch.bad.end());
  if (bad != kNone) report_blow_up(w, bad);
  w.time += w.dt;
}

}  // namespace papertear
