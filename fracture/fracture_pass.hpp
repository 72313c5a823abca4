// The fracture pass (MODEL.md §5), run after every step.
//
//  1. Detection, parallel over cells: an EDGE spring whose strain (L - L0)/L0 exceeds the
//     strength of the bond at either of its ends (the cell face the end lies on,
//     topo.face_strain) becomes a candidate. At a crack tip (an end whose vertex holds no split
//     copies yet while one next to it in its layer does) the strength is material.tip_strength of that:
//     a lattice cannot resolve the stress singularity at a tip (it averages it over a cell),
//     so the tip's bond is judged weaker than intact material, and a crack that has started
//     runs ahead of the load instead of the whole sheet reaching its strength at once. Diagonal springs never break. Each fixed chunk
//     of cells writes its own candidate list; the lists are joined in chunk order.
//  2. Delayed failure, serial: a bond (a cell face) over its strength this step gains
//     dt / τ_axis of damage (core/elasticity.hpp, bond_failure_time), once per step however
//     many of the cell's edges exceed it; it can open only once its damage reaches 1. So a
//     bond fails after it has been over its strength for the time a crack front needs to
//     cross the cell at the material's in-plane longitudinal wave speed: the short strain
//     spikes that a split sends to its neighbours (and the ringing of a sheet that has just
//     come apart) no longer break them.
//  3. One serial pass in a fixed order — largest overstrain (strain / strength) first, then
//     lowest spring id — applies the splits: of the ends whose bond is exceeded and that are
//     still shared with cells across the plane through the end perpendicular to the spring,
//     the one whose force sum Σ|f| is larger is split (MODEL.md decision). The cells on the
//     spring's side of that plane get a new node (same position and velocity); their fine and
//     block springs follow because springs name (cell, corner), not nodes. Masses are
//     recomputed from cells. A block whose cells end up on both sides of a split is entered
//     by the crack: its block springs are removed for good. A node is split only across its
//     most overloaded axis (the mean over its cells of edge strain / bond strength), and
//     after a split every node nearby that joins cells with no bonded face between them (a
//     point contact, not a bond) is separated too, without a split event.
// Being serial and ordered, the pass gives the same result on any number of threads.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "core/ids.hpp"
#include "core/world.hpp"

namespace papertear {

struct FractureCandidate {
  float ratio;       // strain / weaker end's strength, > 1
  std::uint32_t id;  // cell * 28 + slot
};

// One flag per lattice vertex: whether it holds more than one node (fracture_pass.cpp).
using SplitVertices = std::vector<std::uint8_t>;

struct FractureScratch {
  std::vector<std::vector<FractureCandidate>> per_chunk;
  std::vector<FractureCandidate> all;
  std::vector<std::uint32_t> faces;  // cell * 6 + face of every bond over its strength
  std::array<double, 3> failure_time{};  // τ per axis, from the scene (0: not yet set)
  SplitVertices split_vertex;            // vertices that hold split copies
  std::size_t marked_nodes = 0;          // nodes whose vertices split_vertex has marked
};

// Runs detection and the splits for the world's current state; returns the number of splits.
std::size_t fracture_pass(World& world, FractureScratch& scratch);

// Splits `node` by the plane through it normal to `axis`: the cells using it on the side
// given by `side` (1: cells for which the node is on their high face along axis, i.e. cells
// below the plane; 0: cells above) get a new node. Returns the new node, or an invalid id if
// either side has no cell (nothing to split). Updates masses, grips, blocks and scratch sizes.
NodeId split_node(World& world, NodeId node, int axis, int side);

// The general form: the cells using `node` whose bit is set in `moving_mask` (bit i: the
// i-th cell of cells_of_node, fracture/node_cells.hpp, in ascending cell order) get a new
// node. Any grouping keeps the invariants, since every cell keeps its corner at the vertex.
NodeId separate_node(World& world, NodeId node, unsigned moving_mask);

}  // namespace papertear
