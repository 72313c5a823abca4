// Forces of the block-lattice ("coarse") springs, MODEL.md §4.
//
// Data flow: pass 1 (parallel over springs) reads stage positions/velocities and writes one
// force vector per spring into per-spring columns; pass 2 (serial, ascending spring id) adds
// them into the node force columns. No two threads write the same place, and each node's
// sum is taken in spring order, so the result does not depend on the thread count. Springs
// of blocks a crack has entered have stiffness and damping 0 and add nothing.
#pragma once
#include <cstddef>
#include <vector>

#include "core/world.hpp"
#include "kernels/cell_forces.hpp"

namespace papertear {

struct CoarseForceScratch {
  std::vector<float> fx, fy, fz;
};

void coarse_spring_forces(std::size_t begin, std::size_t end, const CoarseSprings& springs,
                          const Topology& topo, const CellForceInputs& in, CoarseForceScratch& out);
void scatter_coarse_forces(const CoarseSprings& springs, const Topology& topo,
                           const CoarseForceScratch& forces, const ForceOutputs& out);

}  // namespace papertear
