// Forces of the block-lattice ("coarse") springs, MODEL.md §4.
//
// The solver's path (BlockLattice): a block's springs join its 8 corners, so a block is
// evaluated like a cell whose 28 slots have their own rest length, stiffness and damping.
//   refresh (before pass 1 whenever fracture may have split nodes or entered blocks): per
//     block corner the node that the corner's (cell, corner) names NOW, and per block
//     whether it is still intact; then, per vertex, the node of each of its entries
//     (refresh_block_entries), so that pass 2 reads them in order;
//   pass 1, parallel over blocks (block_lattice_forces): loads each block's 8 corners once,
//     runs its springs in slot order and writes one force sum per block corner (zero for a
//     block a crack has entered). The corners come from a pack: per kPackLanes lanes, the
//     stage state of the distinct nodes their corners name, copied into one row of 8 floats
//     per node (x y z vx vy vz, 0, 0); a corner of 8 lanes is then 8 row loads and a
//     transpose (of 16 lanes in AVX-512 builds: 16 row loads into 8 registers, and the same
//     transpose in each 256-bit half). Why: 6 hardware gathers per corner cost Zen 3 more
//     than the pass's arithmetic (58 % of the pass's time, cache hits or not), and the pack
//     reads each node once however many of its blocks' corners name it;
//   pass 2, parallel over lattice vertices (gather_block_lattice_forces): each vertex adds
//     the corner sums of the blocks with a corner there, in ascending block id, to the
//     corner's node.
// Why pass 2 is race-free: a node always sits at one lattice vertex (core/world.hpp), and a
// block corner named (cell, corner) lies at a fixed vertex, so only the task owning that
// vertex ever writes the nodes there, however fracture has split them. Why it is
// deterministic: every sum has a fixed order (slots within a block, blocks within a node).
// The table names cells and corners, not nodes, so splits never invalidate it; it is
// rebuilt only when the set of springs is. A block a crack has entered (Block::intact
// false, its springs zeroed) adds exact zeros: a node's force sum starts at +0 and so can
// never be -0, and x + (+-0) == x bit for bit for every other x, so adding a zero is the
// same as skipping the block.
//
// The per-spring path (coarse_spring_forces + scatter_coarse_forces) computes the same
// springs one by one and scatters them serially in spring id order: the plain definition,
// kept for tests and tools that want one force per spring.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/world.hpp"
#include "kernels/cell_forces.hpp"

namespace papertear {

struct CoarseForceScratch {
  std::vector<float> fx, fy, fz;  // force on end a of each spring (end b gets the opposite)
};

// Lanes hold blocks that have springs, padded to a multiple of kBlockLanes.
inline constexpr std::size_t kBlockLanes = 16;
// Lanes per pack (see pass 1 above); its rows (at most one per block corner, 16 KiB) stay in L1.
inline constexpr std::size_t kPackLanes = 64;
inline constexpr std::size_t kPackRows = 8 * kPackLanes;
static_assert(kPackLanes % kBlockLanes == 0, "a pack holds whole vectors");
// Spring parameters are stored in groups of this many lanes, a group's 28 slots back to back:
// one vector evaluation then reads 3 contiguous runs instead of 84 cache lines far apart. A
// group is one vector of pass 1: 16 blocks in AVX-512 builds (define PAPERTEAR_BLOCK8 for 8),
// else 8.
#if !defined(PAPERTEAR_NO_SIMD) && defined(__AVX512F__) && !defined(PAPERTEAR_BLOCK8)
inline constexpr std::size_t kBlockGroup = 16;
#else
inline constexpr std::size_t kBlockGroup = 8;
#endif
static_assert(kBlockLanes % kBlockGroup == 0, "lane padding holds whole groups");
struct BlockLattice {
  std::size_t lanes = 0;                       // padded lane count
  std::vector<std::uint32_t> block;            // per lane: block id (lanes by row), or UINT32_MAX (padding)
  AlignedArray<std::uint32_t> corner_slot{0};  // [corner * lanes + lane]: cell * 8 + corner
  // Refreshed state: [corner * lanes + lane] the node at corner_slot, and per lane 1 for an
  // intact block, 0 for an entered one or padding.
  AlignedArray<std::uint32_t> corner_node{7};
  AlignedArray<float> live{8};
  // Refreshed with corner_node, per pack: its distinct corner nodes in ascending order,
  // pack_node[pack * kPackRows + row] for row < pack_rows[pack] (0: not built yet), and per
  // block corner its row, corner_row[row_at(lane, corner)].
  std::vector<std::uint32_t> pack_node;
  std::vector<std::uint16_t> pack_rows;
  std::vector<std::uint16_t> corner_row;
  AlignedArray<float> rest{1}, stiffness{2}, damping{3};  // at param_at(lane, slot); absent: 0
  AlignedArray<float> fx{4}, fy{5}, fz{6};     // pass 1 output: [corner * lanes + lane]
  std::vector<std::uint32_t> first;            // per vertex + 1: offsets into entry
  std::vector<std::uint32_t> entry;            // corner * lanes + lane, ascending block id per vertex
  // Per entry, the node its block corner names (corner_node[entry]), recorded by
  // refresh_block_entries: the gather then reads nodes in order instead of one cache miss
  // into corner_node per entry (41 % of the gather's time).
  std::vector<std::uint32_t> entry_node;
  std::size_t springs = 0;                     // the CoarseSprings it was built for
  const std::uint32_t* built_from = nullptr;

  // A group's 8 corners of 8 lanes back to back (128 bytes): pass 1 reads one vector's corner
  // rows from 2 cache lines rather than from 8 planes.
  static std::size_t row_at(std::size_t lane, std::size_t corner) {
    return (lane / kBlockGroup * 8 + corner) * kBlockGroup + lane % kBlockGroup;
  }
  static std::size_t param_at(std::size_t lane, std::size_t slot) {
    return ((lane / kBlockGroup) * kSpringsPerCell + slot) * kBlockGroup + lane % kBlockGroup;
  }
  bool matches(const CoarseSprings& s) const {
    return springs == s.size() && built_from == s.cell_a.data() && !first.empty();
  }
};

void build_block_lattice(const CoarseSprings& springs, const std::vector<Block>& blocks,
                         const LatticeDims& dims, BlockLattice& out);
// The refresh for lanes [begin, end): needed after build and after any split or entered block.
// begin is a multiple of kPackLanes (a pack is refreshed by one call), end one too or the
// lane count.
void refresh_block_lattice(std::size_t begin, std::size_t end, const Topology& topo,
                           const std::vector<Block>& blocks, BlockLattice& lattice);
// Pass 1 for lanes [begin, end) (multiples of kBlockLanes except at the end; a pack cut by a
// range is packed whole by each call that needs it).
void block_lattice_forces(std::size_t begin, std::size_t end, const CellForceInputs& in, BlockLattice& lattice);
// Each entry's node for lattice vertices [vbegin, vend), after refresh_block_lattice has run
// on every lane (a vertex's entries come from blocks anywhere in the lane order).
void refresh_block_entries(std::size_t vbegin, std::size_t vend, BlockLattice& lattice);
// Pass 2 for lattice vertices [vbegin, vend): needs their entries refreshed.
void gather_block_lattice_forces(std::size_t vbegin, std::size_t vend, const BlockLattice& lattice,
                                 const ForceOutputs& out);

// One force per spring for springs [begin, end) (vectorised; scalar tail, same bits).
void coarse_spring_forces(std::size_t begin, std::size_t end, const CoarseSprings& springs,
                          const Topology& topo, const CellForceInputs& in, CoarseForceScratch& out);
// Adds the per-spring forces to their end nodes, serially in spring id order.
void scatter_coarse_forces(const CoarseSprings& springs, const Topology& topo,
                           const CoarseForceScratch& forces, const ForceOutputs& out);

}  // namespace papertear
