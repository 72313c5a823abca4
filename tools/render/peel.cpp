#include "tools/render/peel.hpp"

#include <cmath>

#include "fracture/connectivity.hpp"
#include "kernels/parallel.hpp"

namespace papertear::render {

namespace {
// A skin that lets through less than this is drawn opaque: the difference would hardly show,
// and every see-through surface costs the ray tracer a second look behind it.
constexpr float kOpaqueBelow = 0.05f;
// Sets the opacity of the skins of column (i, j); skin_start is scratch of one entry per layer.
void column_opacity(const World& world, int i, int j, float clear, std::vector<int>& skin_start,
                    std::vector<float>& opacity) {
  const LatticeDims& d = world.topo.dims;
  // Walk the column upwards; a new skin starts above every open layer boundary.
  int start = 0;
  for (int k = 0; k < d.nl; ++k) {
    if (k > 0 && !faces_connected(world, d.cell_index(i, j, k - 1), 5)) start = k;
    skin_start[std::size_t(k)] = start;
  }
  for (int k = d.nl - 1; k >= 0; --k) {
    const int start_k = skin_start[std::size_t(k)];
    if (start_k == 0) break;  // this and everything below rests on the base
    int end = k;              // last layer of this cell's skin
    while (end + 1 < d.nl && skin_start[std::size_t(end + 1)] == start_k) ++end;
    const int thickness = end - start_k + 1;
    const float through = std::pow(clear, float(thickness));
    opacity[d.cell_index(i, j, k)] = through < kOpaqueBelow ? 1.0f : 1.0f - through;
  }
}

}  // namespace

std::vector<float> cell_opacity(const World& world, float layer_opacity) {
  const LatticeDims& d = world.topo.dims;
  std::vector<float> opacity(std::size_t(d.cells()), 1.0f);
  // Each column writes only its own cells, so fixed chunks of columns may run in parallel.
  const std::size_t columns = std::size_t(d.nx) * std::size_t(d.ny);
  parallel_chunks(columns, 1024, [&](std::size_t begin, std::size_t end, std::size_t) {
    std::vector<int> skin_start(std::size_t(d.nl));
    for (std::size_t c = begin; c < end; ++c)
      column_opacity(world, int(c % std::size_t(d.nx)), int(c / std::size_t(d.nx)), 1.0f - layer_opacity, skin_start,
                     opacity);
  });
  return opacity;
}

}  // namespace papertear::render
