// The checks that must hold between any two steps (see core/world.hpp). Tests run them after
// every fracture pass; they are too slow for every step of a production run.
#pragma once
#include <string>
#include <vector>

#include "core/world.hpp"

namespace papertear {

// Returns a description of each violated invariant (empty: all hold). Stops after `limit`.
std::vector<std::string> check_invariants(const World& world, std::size_t limit = 20);

}  // namespace papertear
