// Peeled layers (paper §4, MODEL.md §6): where the layers of a column of cells have come
// apart, everything above a separation is a skin lifted off the sheet and is drawn
// translucent by its thickness. A skin of n layers lets through (1 - a)^n of the light,
// where a is the opacity of one layer (Beer–Lambert for a uniform stack). Cells in the
// bottom part of each column, resting on nothing, stay opaque, and so does a skin thick enough to let through
// less than 5 % (with the default layer opacity 0.7: three layers or more).
#pragma once
#include <vector>

#include "core/world.hpp"

namespace papertear::render {

// Opacity per cell (1 for cells that are not part of a peeled skin).
std::vector<float> cell_opacity(const World& world, float layer_opacity);

}  // namespace papertear::render
