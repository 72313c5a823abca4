// Whether two lattice-neighbour cells are still joined across their shared face: they are
// exactly when they share all four of the face's nodes. Fracture, metrics and the surface
// extraction of the renderer all ask this one question.
#pragma once
#include "core/world.hpp"

namespace papertear {

// True when cell `c` has a lattice neighbour across face f (= 2*axis + side) and shares all
// four face nodes with it. False at the sheet's outside.
inline bool faces_connected(const World& w, std::uint32_t c, int face) {
  const LatticeDims& d = w.topo.dims;
  const auto ijk = d.cell_ijk(c);
  const std::int64_t n = d.neighbour(ijk[0], ijk[1], ijk[2], face);
  if (n < 0) return false;
  const int axis = face >> 1;
  for (int q : face_corners(face)) {
    const int q_other = q ^ (1 << axis);  // the same vertex seen from the neighbour
    if (w.topo.node(c, q) != w.topo.node(std::uint32_t(n), q_other)) return false;
  }
  return true;
}

}  // namespace papertear
