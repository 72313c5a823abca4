// Energies for metrics and physics tests, in double precision. Range functions: the caller
// sums the per-range results in a fixed order (kernels/parallel.hpp, deterministic_sum).
#pragma once
#include <cstddef>

#include "core/world.hpp"

namespace papertear {

// Σ ½ m |v|² over nodes [begin, end).
double kinetic_energy(std::size_t begin, std::size_t end, const NodeStore& nodes);
// Σ ½ k (L - L0)² over the 28 springs of cells [begin, end).
double cell_elastic_energy(std::size_t begin, std::size_t end, const World& world);
// Σ ½ k (L - L0)² over block-lattice springs [begin, end).
double coarse_elastic_energy(std::size_t begin, std::size_t end, const World& world);

}  // namespace papertear
