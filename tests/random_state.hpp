// Random initial states for the physics and reference tests: a resting lattice has zero force
// everywhere, so these tests start from a perturbed one.
#pragma once
#include <cstdint>
#include <random>

#include "core/world.hpp"

namespace papertear::testing {

// Random displacements (up to dp) and velocities (up to dv) on every node, from `seed`, so
// that every spring is stretched or compressed and has a relative velocity.
inline void perturb(World& w, std::uint32_t seed, float dp, float dv) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  NodeStore& n = w.nodes;
  for (std::size_t i = 0; i < n.count; ++i) {
    n.px[i] += dp * unit(rng); n.py[i] += dp * unit(rng); n.pz[i] += dp * unit(rng);
    n.vx[i] = dv * unit(rng); n.vy[i] = dv * unit(rng); n.vz[i] = dv * unit(rng);
  }
}

}  // namespace papertear::testing
