// One time step of the solver: four RK4 stages, each a force evaluation and a node update.
//
// Before stage 1 the merged-spring table (kernels/fine_springs.hpp: which cell evaluates
// which coincident fine springs, and the plan of each row of cells the spring kernel sweeps)
// is brought up to date with the splits since the last step.
// Per stage, as one graph of tasks (core/solver.cpp, StageGraph; kernels/parallel.hpp
// explains why the result does not depend on the thread count):
//   1. fine springs, by strips of rows   a task takes a strip of kStripRows values of j and
//                                        sweeps its rows of cells (j, then k) slot by slot
//                                        (kernels/cell_forces.hpp) while its nodes are in
//                                        cache; an odd strip after its two even neighbours
//                                        (core/solver.cpp: the order each node gets)
//      block lattice, pass 1             by chunks of blocks, alongside the even strips: one
//                                        force sum per block corner
//   2. block lattice, pass 2             by bands of vertex rows (one per strip, all layers),
//      + node update (kernels/rk4.hpp)   a band after the strips and block chunks that touch
//                                        its rows: each vertex adds the corner sums of its
//                                        blocks in ascending block id
//                                        (kernels/coarse_forces.hpp), then the nodes whose id
//                                        is that vertex are updated; clears forces for the next stage
//      node update of split nodes        after the graph (nodes from splits sit anywhere)
// That is one graph and one parallel region per stage. Each node's fine-spring force is its
// terms in the kernel's order (strips, rows, chunks, slots), then its blocks' corner sums in
// block order, whatever the thread count.
// Under a pierce load the indenter's contact force (core/contact.hpp) is added at the start
// of each stage, parallel over nodes. Gripped nodes get their prescribed velocity before stage 1. After stage 4 the step checks
// for a blow-up (non-finite or runaway state) and throws BlowUpError naming the step and node.
// Fracture (fracture/fracture_pass.hpp) runs after the step, serially.
#pragma once
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/world.hpp"
#include "kernels/cell_forces.hpp"
#include "kernels/coarse_forces.hpp"
#include "kernels/fine_springs.hpp"

namespace papertear {

struct SolverScratch {
  BlockLattice lattice;  // built on first use, rebuilt when the block springs are
  std::vector<std::uint32_t> bad;  // per band and node chunk: the first node that blew up
  // Built on first use; then, at the start of each step, updated around the nodes split
  // since (the world's split events), or rebuilt if the topology changed any other way.
  FineSprings fine;
  const std::uint32_t* fine_topology = nullptr;  // the cell table it was built for
  std::size_t fine_nodes = 0, fine_events = 0;   // node and event counts it has seen
  // Per chunk of block lanes, the first and last band of vertex rows its corners lie in
  // (core/solver.cpp), and the lattice and band count they were found for.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> chunk_bands;
  const std::uint32_t* chunk_bands_for = nullptr;
  std::size_t chunk_bands_lanes = 0, chunk_bands_count = 0;
};

// Chunk sizes (elements per task). Fixed numbers, never derived from the thread count.
inline constexpr std::size_t kCellChunk = 512;  // fracture detection, energies, the merged-spring table's build
inline constexpr std::size_t kNodeChunk = 2048;
inline constexpr std::size_t kVertexChunk = 2048;  // evaluate_forces' gather
inline constexpr std::size_t kBlockChunk = 256;  // block-lattice lanes
// Fine springs: cell rows (values of j) per strip. Small enough that a strip's nodes stay in
// cache while its rows are swept and that even a 90-row sheet gives each thread several strips.
inline constexpr int kStripRows = 4;
static_assert(kBlockChunk % kPackLanes == 0, "block chunks hold whole packs (and so whole vectors)");

// Adds the fine spring forces only, by the solver's strips of rows (for benchmarks and tests).
void add_fine_forces(const Topology& topo, const CellForceInputs& in, const ForceOutputs& out);
// Evaluates all spring forces at the stage state into scratch.fx/fy/fz (which must be zero).
void evaluate_forces(World& world, SolverScratch& scratch);
// One RK4 step (no fracture); advances world.time but not world.step.
void integrate_step(World& world, SolverScratch& scratch);

}  // namespace papertear
