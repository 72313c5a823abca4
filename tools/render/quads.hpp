// Consecutive triangles of the display mesh paired into quads for the ray tracer.
//
// Embree builds its BVH over primitives, and a quad (two triangles sharing an edge) is one
// primitive: half as many primitives build in about half the time and trace as fast. The
// mesh's triangles come in such pairs: a surface face is (v0 v1 v2) (v0 v2 v3), and the side
// triangles of a fibre tooth (a b tip) (b c tip) meet along b–tip (they have their own
// vertices, equal in position). Embree splits quad (q0 q1 q2 q3) along q1–q3 into
// (q0 q1 q3) and (q2 q3 q1); the pairs below are ordered so that these are exactly the two
// triangles, and a hit's quad coordinates convert back to the triangle's barycentrics.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "tools/render/surface.hpp"

namespace papertear::render {

struct TracedQuad {
  enum class Pairing : std::uint8_t {
    single,       // one triangle (a b c) as (a b c c)
    shared_ends,  // (a b c) (b' e c'), b' and c' at b and c: (a b e c)
    shared_first  // (a b c) (a c f): (b c f a)
  };
  std::array<std::uint32_t, 4> vertex;
  std::array<std::uint32_t, 2> triangle;  // the mesh's triangles (the second unused if single)
  Pairing pairing;
};

// A point on a mesh triangle: barycentric u of its vertex 1 and v of its vertex 2.
struct TrianglePoint {
  std::uint32_t triangle;
  float u, v;
};

// The triangles `tris` (ids into mesh.triangles) as quads, consecutive pairs joined where
// they share the diagonal; the quads keep the triangles' order. Runs in parallel in fixed
// chunks: the result does not depend on the thread count.
std::vector<TracedQuad> pair_triangles(const SurfaceMesh& mesh, const std::vector<std::uint32_t>& tris);
// The same into `quads`, which keeps its capacity (a frame loop reuses one list).
void pair_triangles(const SurfaceMesh& mesh, const std::vector<std::uint32_t>& tris, std::vector<TracedQuad>& quads);

// The mesh triangle and its barycentrics at quad coordinates (u, v) of an Embree hit.
TrianglePoint on_triangle(const TracedQuad& quad, float u, float v);

}  // namespace papertear::render
