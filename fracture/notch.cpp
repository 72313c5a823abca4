#include "fracture/notch.hpp"

#include "fracture/fracture_pass.hpp"
#include "fracture/node_cells.hpp"

namespace papertear {

void cut_notch(World& w) {
  const LoadParams& load = w.scene.load;
  if ((load.kind != "pull" && load.kind != "tear") || load.notch <= 0) return;
  const LatticeDims& d = w.topo.dims;
  const int axis = load.axis == 'y' ? 1 : 0, across = 1 - axis;
  const int mid = (axis == 0 ? d.nx : d.ny) / 2;
  // Splitting the vertices at depth 0..notch-1 opens the faces of the first notch-1 cells
  // fully and the next one at its lower corners: a cut that ends in a sharp tip.
  for (int depth = 0; depth < load.notch; ++depth)
    for (int k = 0; k <= d.nl; ++k) {
      int v[3] = {0, 0, k};
      v[axis] = mid;
      v[across] = depth;
      const std::uint32_t vertex = d.vertex_index(v[0], v[1], v[2]);
      // Before any split the node at a vertex has the vertex's id (core/lattice_builder.cpp).
      split_node(w, NodeId(vertex), axis, 1);
    }
}

}  // namespace papertear
