// A 64-bit hash of the raw bits of the state: node count, positions, velocities and the
// cell→corner→node table, in a fixed order. Two runs agree on the digest exactly when they
// agree on every bit of that state, which is what the determinism tests compare.
#pragma once
#include <cstdint>

#include "core/world.hpp"

namespace papertear {

std::uint64_t state_digest(const World& world);

}  // namespace papertear
