// The initial flaw: a cut at the middle of the sheet's low edge, across the pull, through
// every layer. Made with the same node splits as a tear, so the cut faces are torn faces.
#pragma once
#include "core/world.hpp"

namespace papertear {

// Cuts load.notch cells deep at pull-axis coordinate n/2 (n: cells along the pull axis),
// from the edge at 0 of the other in-plane axis: for a tear, between the two grips. No
// effect for notch = 0 or under a load other than pull and tear.
void cut_notch(World& world);

}  // namespace papertear
