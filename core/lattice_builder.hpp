// Builds the intact lattice of a scene: nodes at every vertex, the cell→corner→node table,
// the colour lists, the spring table, node masses and the grips. Fibre blocks and bond
// strengths are laid by fracture/blocks.hpp on top of it.
#pragma once
#include "core/world.hpp"

namespace papertear {

void build_lattice(const Scene& scene, World& out);
// The 28 slots' rest length, stiffness and damping for a material on a lattice.
// Fitted to the material's moduli (core/elasticity.hpp), the edges less the block lattice's share.
SpringTable make_spring_table(const MaterialParams& material, const LatticeDims& dims);
// The largest edge-spring stiffness of a table: the scale of a penalty contact.
double stiffest_edge(const SpringTable& table);
// Recomputes node masses from the cells that use each node (after splits: total mass is
// unchanged because every cell always hands 1/8 of its mass to each of its 8 corners).
void recompute_masses(World& world);
// Sizes the RK4 scratch to the nodes and sets the stage state to the state (p, v), as it is
// between steps (kernels/rk4.hpp).
void reset_stage_state(World& world);
// Tear (load.kind = "tear"): two fingers pinch the sheet at its low edge (coordinate 0 of
// the in-plane axis across load.axis), one each side of the tear line at the middle of
// load.axis, and move apart out of plane (mode III): the first up, the second down, each at
// load.speed, with an in-plane spread of kTearSpread · speed that opens the tear a little.
// Each grip holds grip_cells × grip_cells cells through the thickness, grip_margin cells
// from the tear line: the paper between the fingers is what tears.
struct TearGrips {
  std::array<int, 2> left, right;  // vertex ranges [first, last] along load.axis
  int depth;                       // vertices 0..depth across it
};
TearGrips tear_grips(const LoadParams& load, const LatticeDims& dims);
inline constexpr double kTearSpread = 0.25;

// Grip velocity at time t: full speed after the ramp, linear before it.
float grip_ramp(const LoadParams& load, double t);
// How far a load point moving at `speed`, ramped up linearly over `ramp_time` as grip_ramp
// does, has travelled by time t (grip_ramp's integral): the grips' and the indenter's travel.
double ramped_travel(double speed, double ramp_time, double t);

}  // namespace papertear
