// The simulation's whole state as structure-of-arrays, split into hot solver columns and
// cold records (Box2D v3 style). Only fracture/ edits the topology; kernels/ read it.
//
// Invariants (checked by check_invariants):
//  * every cell's 8 corners are live nodes, and a node is always at one lattice vertex
//    (`vertex`), used only by cells around that vertex at the matching corner;
//  * hence cells of one colour (i%2, j%2, k%2) never share a node, before or after splits;
//  * a node's mass is the sum of 1/8 of the masses of the cells that use it.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "core/aligned_array.hpp"
#include "core/lattice.hpp"
#include "core/scene.hpp"

namespace papertear {

enum NodeFlag : std::uint8_t { kNodeFree = 0, kNodeGripped = 1 };

// Hot per-node columns. The state is (p, v); everything else is derived or static.
struct NodeStore {
  std::size_t count = 0;
  AlignedArray<float> px{0}, py{1}, pz{2};  // position
  AlignedArray<float> vx{3}, vy{4}, vz{5};  // velocity
  AlignedArray<float> inv_mass{6};          // 1 / mass
  AlignedArray<float> free_mask{7};         // 1 for free nodes, 0 for gripped (driven) ones
  AlignedArray<float> mass{8};
  AlignedArray<std::uint32_t> vertex{9};    // lattice vertex the node sits at (never changes)
  AlignedArray<std::uint8_t> grip{10};      // 0: free; g > 0: driven by grip g - 1

  void resize(std::size_t n);
};

// RK4 scratch: the stage state, the RK4 sums and the force accumulator (kernels/rk4.hpp).
struct IntegratorScratch {
  AlignedArray<float> sx{11}, sy{12}, sz{13};    // stage position
  AlignedArray<float> svx{14}, svy{15}, svz{0};  // stage velocity
  AlignedArray<float> ax{1}, ay{2}, az{3};       // Σ weight * dp/dt over stages
  AlignedArray<float> avx{4}, avy{5}, avz{6};    // Σ weight * dv/dt over stages
  AlignedArray<float> fx{7}, fy{8}, fz{9};       // force at the current stage

  void resize(std::size_t n);
};

// The 28 spring slots' parameters, shared by all cells (a uniform lattice); a per-cell
// factor scales stiffness and damping (fibre block irregularity).
struct SpringTable {
  std::array<float, kSpringsPerCell> rest{};
  std::array<float, kSpringsPerCell> stiffness{};
  std::array<float, kSpringsPerCell> damping{};
};

// Block-lattice ("coarse") springs, MODEL.md §4: they join the corners of a fibre block.
// An end is named by (cell, corner) rather than by node, so when fracture splits a node the
// spring follows its cell like the cell's own springs do.
struct CoarseSprings {
  std::vector<std::uint32_t> cell_a, cell_b;
  std::vector<std::uint8_t> corner_a, corner_b;
  std::vector<float> rest, stiffness, damping;
  std::vector<std::uint32_t> block;
  std::size_t size() const { return cell_a.size(); }
};

// A fibre block: a box of cells [lo, hi) (MODEL.md §3).
struct Block {
  std::array<int, 3> lo{}, hi{};
  float strength = 1.0f;  // random strength factor
  bool intact = true;     // false once a crack has entered: its coarse springs are gone
  std::uint32_t first_spring = 0, spring_count = 0;  // its springs in CoarseSprings
};

struct SplitEvent {
  std::int64_t step = 0;
  std::uint32_t node = 0;      // the node that was split
  std::uint32_t new_node = 0;  // the copy given to the cells on one side
  std::uint8_t axis = 0;       // axis of the broken edge spring (the split plane's normal)
  bool interlayer = false;     // the opened bond joins two layers (axis z)
  std::uint32_t cell = 0;      // the broken spring: cell * 28 + slot
  std::uint8_t slot = 0;
};

struct Topology {
  LatticeDims dims;
  AlignedArray<std::uint32_t> cell_nodes;                // 8 per cell, by corner
  std::array<std::vector<std::uint32_t>, 8> colour_cells;  // cells of each colour, ascending
  std::vector<float> cell_scale;                         // per-cell stiffness factor
  std::vector<std::uint32_t> cell_block;                 // the block each cell belongs to
  std::vector<float> face_strain;                        // 6 per cell: strain that opens the face's bond
  std::vector<float> face_damage;                        // 6 per cell: how far the bond has failed, 0..1

  std::uint32_t node(std::uint32_t cell, int corner) const {
    return cell_nodes[std::size_t(cell) * 8 + std::size_t(corner)];
  }
};

struct Grip {
  std::array<float, 3> velocity{};  // full speed; the ramp scales it
};

struct World {
  Scene scene;
  NodeStore nodes;
  IntegratorScratch scratch;
  Topology topo;
  SpringTable springs;
  CoarseSprings coarse;
  std::vector<Block> blocks;
  std::vector<Grip> grips;
  std::vector<std::uint32_t> gripped_nodes;  // ascending
  std::vector<SplitEvent> events;
  std::int64_t step = 0;
  double time = 0.0;
  double dt = 0.0;
};

}  // namespace papertear
