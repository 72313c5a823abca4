// The cells that use a node. A node always sits at one lattice vertex (core/world.hpp), so
// its cells are among the (up to) 8 cells around that vertex: no adjacency list is stored.
#pragma once
#include <array>
#include <cstdint>

#include "core/world.hpp"

namespace papertear {

struct CellCorner {
  std::uint32_t cell;
  std::uint8_t corner;  // the node's corner in that cell
};

struct NodeCells {
  std::array<CellCorner, 8> items{};
  int count = 0;
  const CellCorner* begin() const { return items.data(); }
  const CellCorner* end() const { return items.data() + count; }
};

// The cells using `node`, in ascending cell order.
inline NodeCells cells_of_node(const World& w, std::uint32_t node) {
  const LatticeDims& d = w.topo.dims;
  const auto v = d.vertex_ijk(w.nodes.vertex[node]);
  NodeCells out;
  for (int dk = 1; dk >= 0; --dk)
    for (int dj = 1; dj >= 0; --dj)
      for (int di = 1; di >= 0; --di) {
        const int i = v[0] - di, j = v[1] - dj, k = v[2] - dk;
        if (i < 0 || j < 0 || k < 0 || i >= d.nx || j >= d.ny || k >= d.nl) continue;
        const std::uint32_t c = d.cell_index(i, j, k);
        const int q = corner_of(di, dj, dk);
        if (w.topo.node(c, q) == node) out.items[std::size_t(out.count++)] = {c, std::uint8_t(q)};
      }
  return out;
}

}  // namespace papertear
