// Frayed fibres on torn faces (paper §4, figure 6; MODEL.md §6). The lattice cell is the
// smallest unit of a tear, so a torn face alone looks like a staircase. Each torn face
// therefore grows a row of "teeth": thin pyramids standing on the face and leaning out of
// it, some broad (clumps of fibres), some needle-like (single loose fibres). Their number,
// widths, lengths and tips are a pure function of (cell, face), so a tear keeps the same
// fringe from frame to frame, and the physics never sees them. They grow with the opening
// of the tear (at most half way across the gap from each side) and never rise above the
// face, so a fresh crack does not sprout fibres through the print. A face whose fringe would
// be shorter than a tenth of `length` grows none (it would lie flat on the face).
#pragma once
#include <cstdint>
#include <vector>

#include "core/world.hpp"
#include "tools/render/surface.hpp"

namespace papertear::render {

// Appends the fibres of every torn face of `faces` (in their order) to `mesh`: flat-shaded
// triangles with three vertices each. `length` is the longest fibre, in cell sizes;
// `opacity` is per cell (peel.hpp). The work is shared out in fixed chunks to the threads of
// the current arena; the mesh has the same bytes on any number of threads.
void append_frayed_faces(const World& world, const std::vector<OpenFace>& faces, float length,
                         const std::vector<float>& opacity, SurfaceMesh& mesh);

}  // namespace papertear::render
