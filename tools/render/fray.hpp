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

// The fibres are made in two parallel passes over fixed chunks of faces, so that the mesh has
// the same bytes on any number of threads: plan_fibres counts each chunk's fibre triangles,
// running the whole fibre geometry (a tooth side whose normal is degenerate is left out, so
// nothing cheaper gives the exact count); write_fibres writes them at their place in face
// order into a mesh already sized to hold them.
struct FibrePlan {
  std::vector<std::size_t> first = {0};  // per chunk: fibre triangles before it; back(): all of them
  std::size_t triangle_count() const { return first.back(); }
};

// Where the fibres go in the mesh: fibre triangles from first_triangle on, each with three
// vertices of its own from first_vertex on (flat-shaded).
struct FibreRegion {
  std::size_t first_triangle = 0, first_vertex = 0;
};

// `length` is the longest fibre, in cell sizes.
FibrePlan plan_fibres(const World& world, const std::vector<OpenFace>& faces, float length);

// Writes the fibres of every torn face of `faces` (in their order); `opacity` is per cell
// (peel.hpp), `plan` what plan_fibres gave for the same world, faces and length.
void write_fibres(const World& world, const std::vector<OpenFace>& faces, float length,
                  const std::vector<float>& opacity, const FibrePlan& plan, const FibreRegion& region,
                  SurfaceMesh& mesh);

}  // namespace papertear::render
