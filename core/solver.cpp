#include "core/solver.hpp"

#include <algorithm>
#include <atomic>
#include <cassert>
#include <cmath>
#include <limits>
#include <sstream>

#include "core/contact.hpp"
#include "core/lattice_builder.hpp"
#include "core/simulation.hpp"
#include "core/timestep.hpp"
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
      << "), speed " << std::sqrt(double(w.nodes.vx[node]) * w.nodes.vx[node] + double(w.nodes.vy[node]) * w.nodes.vy[node] +
                                 double(w.nodes.vz[node]) * w.nodes.vz[node])
      << " mm/µs; " << blow_up_cause(w);
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

// Builds the block lattice if the block springs changed since it was built; returns whether it did.
bool sync_block_lattice(const World& w, BlockLattice& lattice) {
  if (lattice.matches(w.coarse)) return false;
  build_block_lattice(w.coarse, w.blocks, w.topo.dims, lattice);
  return true;
}

// All fine springs and pass 1 of the block lattice (which shares the first phase's region:
// both read the stage state and they write disjoint outputs, node forces vs per-block
// corner sums). The block sums still have to be gathered. `new_topology`: nodes may have been
// split or blocks entered since the last call, so the block lattice is refreshed. Returns
// whether it was (also when it had to be built), i.e. whether the gather's entries must be.
bool add_fine_and_block_forces(World& w, SolverScratch& scratch, const CellForceInputs& in,
                               const ForceOutputs& out, bool new_topology) {
  BlockLattice& lattice = scratch.lattice;
  if (sync_block_lattice(w, lattice)) new_topology = true;
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

// One stage's forces and node update as a graph of tasks (kernels/parallel.hpp):
//   even strip 2t, block chunk c   no predecessors
//   odd strip 2t + 1               after the even strips 2t and 2t + 2 (a node on the row
//                                  between two strips gets the even strip's terms first)
//   band s                         after the strips s - 1 and s, whose cells touch its rows,
//                                  and every block chunk with a corner in its rows (the gather
//                                  needs their corner sums, and their pass must read the stage
//                                  state before the band overwrites it)
// Band s is the vertex rows [s * kStripRows, (s + 1) * kStripRows) (the last band up to row
// ny) in every layer: nl + 1 runs of node ids. Node n < vertices sits at vertex n (splits
// append new ids), so once a band has gathered its vertices' block sums, their original
// nodes have their whole force, and the band updates them at once, while they are in cache.
// Why bands and not chunks of ids: ids run layer after layer, so a chunk of ids holds rows of
// every strip, and about half of the nodes would be summed on one core and updated on the
// other (bench/README.md, rounds 19 and 20). The thread that makes a task ready runs it next
// unless the other takes it, so a band mostly runs where its strips just ran. Every node's
// force is the same terms in the same order as with one parallel region per pass, and the
// update is per node, so nothing depends on the thread count or on when a task runs.
// Nodes from splits sit anywhere in the sheet; they are updated after the graph.
struct StageGraph {
  FineStrips strips;
  std::size_t even = 0, blocks = 0, odd = 0, bands = 0;  // task counts, in task id order
  std::size_t row_len = 0, layer_rows = 0;                // vertices per row, rows per layer
  int layers = 0, ny = 0;
  std::vector<std::uint32_t> band_waits;  // per band: its predecessors
  std::vector<std::size_t> roots;         // the even strips and block chunks, in spawn order

  std::size_t tasks() const { return even + blocks + odd + bands; }
  std::size_t band_of_row(std::uint32_t row) const { return std::min(std::size_t(row) / kStripRows, bands - 1); }
  // First node id of band s's run in layer K (s == bands: the next layer's first). Inside a
  // layer rounded down to a multiple of 16, so that the update's vector loads are aligned
  // and two bands share no cache line of a column: band s then also holds the last few
  // vertices of row s * kStripRows - 1, which only strip s - 1 and blocks with a corner on
  // that row touch. Not when a row is shorter than 16 vertices (the rounding would reach
  // back further than one row), and never at a layer's start, which belongs to band 0.
  std::size_t at(std::size_t s, int K) const {
    if (s == bands) return row_len * layer_rows * std::size_t(K + 1);
    const std::size_t id = row_len * (layer_rows * std::size_t(K) + s * std::size_t(kStripRows));
    return s > 0 && row_len >= 16 ? id / 16 * 16 : id;
  }
  // Node ids [first, second) of band s in layer K.
  std::pair<std::size_t, std::size_t> run(std::size_t s, int K) const { return {at(s, K), at(s + 1, K)}; }
  void reset(std::vector<std::atomic<std::uint32_t>>& waits) const {
    for (std::size_t t = 0; t < even + blocks; ++t) waits[t].store(0, std::memory_order_relaxed);
    for (std::size_t t = 0; t < odd; ++t)
      waits[even + blocks + t].store(2 * t + 2 < strips.strips ? 2 : 1, std::memory_order_relaxed);
    for (std::size_t s = 0; s < bands; ++s)
      waits[even + blocks + odd + s].store(band_waits[s], std::memory_order_relaxed);
  }
};

// Per block chunk, the first and last band that holds a corner of its blocks (lanes run by
// the blocks' first row, so these are a few bands; a corner on the row before a band's
// first may be in that band, see StageGraph::at); recomputed when the lattice is rebuilt.
// These are all the nodes the chunk's pass reads (padding lanes and corners no spring joins
// load corners of its blocks, kernels/coarse_forces.cpp), apart from nodes made by splits,
// which no band updates.
void plan_block_chunk_bands(const World& w, const StageGraph& g, SolverScratch& scratch) {
  const BlockLattice& L = scratch.lattice;
  if (scratch.chunk_bands_for == L.built_from && scratch.chunk_bands_lanes == L.lanes &&
      scratch.chunk_bands_count == g.bands)
    return;
  scratch.chunk_bands.assign(chunk_count(L.lanes, kBlockChunk), {std::uint32_t(g.bands - 1), 0u});
  for (std::size_t lane = 0; lane < L.lanes; ++lane) {
    if (L.block[lane] == UINT32_MAX) continue;
    const Block& blk = w.blocks[L.block[lane]];  // corners on vertex rows lo[1] and hi[1]
    auto& [first, last] = scratch.chunk_bands[lane / kBlockChunk];
    first = std::min(first, std::uint32_t(g.band_of_row(std::uint32_t(blk.lo[1]))));
    last = std::max(last, std::uint32_t(g.band_of_row(std::uint32_t(std::min(blk.hi[1] + 1, g.ny)))));
  }
  scratch.chunk_bands_for = L.built_from;
  scratch.chunk_bands_lanes = L.lanes;
  scratch.chunk_bands_count = g.bands;
}

StageGraph stage_graph(const World& w, SolverScratch& scratch) {
  const LatticeDims& d = w.topo.dims;
  StageGraph g;
  g.strips = fine_strips(w.topo);
  g.even = g.strips.even_strips();
  g.odd = g.strips.odd_strips();
  g.blocks = chunk_count(scratch.lattice.lanes, kBlockChunk);
  g.bands = g.strips.strips;
  g.row_len = std::size_t(d.nx) + 1;
  g.layer_rows = std::size_t(d.ny) + 1;
  g.layers = d.nl + 1;
  g.ny = d.ny;
  plan_block_chunk_bands(w, g, scratch);
  g.band_waits.assign(g.bands, 0);
  for (std::size_t s = 0; s < g.bands; ++s) g.band_waits[s] = s > 0 ? 2 : 1;
  for (const auto& [first, last] : scratch.chunk_bands)
    for (std::size_t s = first; s <= last; ++s) ++g.band_waits[s];
  // The first half of the even strips and of the block chunks, then the second halves: the
  // calling thread spawns them and runs the newest first, an idle thread takes the oldest,
  // so each takes about one half of the sheet, the same half every stage.
  const std::size_t he = (g.even + 1) / 2, hb = (g.blocks + 1) / 2;
  for (std::size_t t = 0; t < he; ++t) g.roots.push_back(t);
  for (std::size_t c = 0; c < hb; ++c) g.roots.push_back(g.even + c);
  for (std::size_t t = he; t < g.even; ++t) g.roots.push_back(t);
  for (std::size_t c = hb; c < g.blocks; ++c) g.roots.push_back(g.even + c);
  return g;
}

// Runs one stage's graph, then the update of the split nodes. `refresh`: nodes may have been
// split or blocks entered since the last stage, so the block chunks refresh their lanes and
// the bands their vertices' entry nodes. scratch.bad gets per band and per chunk of split
// nodes the first node that blew up.
void run_stage(World& w, SolverScratch& scratch, const StageGraph& g, std::vector<std::atomic<std::uint32_t>>& waits,
               const CellForceInputs& in, const ForceOutputs& out, const StageParams& params, bool refresh) {
  BlockLattice& lattice = scratch.lattice;
  g.reset(waits);
  const std::size_t odd0 = g.even + g.blocks, band0 = odd0 + g.odd;
  run_task_graph(g.tasks(), g.roots, waits.data(), [&](std::size_t t, const auto& release) {
    auto release_band = [&](std::size_t s) {
      if (s < g.bands) release(band0 + s);
    };
    if (t < g.even) {
      g.strips.run(2 * t, in, out);
      if (t > 0) release(odd0 + t - 1);
      if (t < g.odd) release(odd0 + t);
      release_band(2 * t);
      release_band(2 * t + 1);
    } else if (t < odd0) {
      const std::size_t c = t - g.even, b = c * kBlockChunk, e = std::min(lattice.lanes, b + kBlockChunk);
      if (refresh) refresh_block_lattice(b, e, w.topo, w.blocks, lattice);
      block_lattice_forces(b, e, in, lattice);
      const auto [first, last] = scratch.chunk_bands[c];
      for (std::size_t s = first; s <= last; ++s) release_band(s);
    } else if (t < band0) {
      const std::size_t strip = 2 * (t - odd0) + 1;
      g.strips.run(strip, in, out);
      release_band(strip);
      release_band(strip + 1);
    } else {
      const std::size_t s = t - band0;
      std::uint32_t bad = kNone;
      for (int K = 0; K < g.layers; ++K) {
        const auto [b, e] = g.run(s, K);
        if (lattice.lanes != 0) {
          if (refresh) refresh_block_entries(b, e, lattice);
          gather_block_lattice_forces(b, e, lattice, out);
        }
        bad = std::min(bad, rk4_stage(b, e, params, w.nodes, w.scratch));
      }
      scratch.bad[s] = bad;
    }
  });
  const std::size_t split0 = std::size_t(w.topo.dims.vertices());
  parallel_chunks(w.nodes.count - split0, kNodeChunk, [&](std::size_t b, std::size_t e, std::size_t c) {
    scratch.bad[g.bands + c] = rk4_stage(split0 + b, split0 + e, params, w.nodes, w.scratch);
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
  const bool new_topology = sync_fine_springs(w, scratch);
  const bool rebuilt = sync_block_lattice(w, scratch.lattice);
  const StageGraph graph = stage_graph(w, scratch);
  std::vector<std::atomic<std::uint32_t>> waits(graph.tasks());
  scratch.bad.assign(graph.bands + chunk_count(w.nodes.count - std::size_t(w.topo.dims.vertices()), kNodeChunk), kNone);
  const CellForceInputs in = stage_inputs(w, scratch);
  const ForceOutputs out = force_outputs(w);
  // The indenter (pierce only) is where it is at each stage's time: t, t + dt/2 twice, t + dt.
  // Its push goes in first, while the force columns are still zero (the previous stage's
  // RK4 update cleared them): the springs then add to it, and the bands see every force a
  // node gets.
  const std::optional<Indenter> indenter = make_indenter(w);
  constexpr double kStageTime[4] = {0.0, 0.5, 0.5, 1.0};
  for (int stage = 1; stage <= 4; ++stage) {
    if (indenter) apply_contact(w, *indenter, w.time + kStageTime[stage - 1] * w.dt);
    // Splits come between steps, so only the first stage may see a new topology.
    run_stage(w, scratch, graph, waits, in, out, stage_params(w, stage), stage == 1 && (new_topology || rebuilt));
  }
  // The first node in id order (the bands' runs interleave across layers).
  const std::uint32_t bad = scratch.bad.empty() ? kNone : *std::min_element(scratch.bad.begin(), scratch.bad.end());
  if (bad != kNone) report_blow_up(w, bad);
  w.time += w.dt;
}

}  // namespace papertear
