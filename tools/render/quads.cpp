#include "tools/render/quads.hpp"

#include "kernels/parallel.hpp"

namespace papertear::render {

namespace {

using Pairing = TracedQuad::Pairing;

bool same_place(const SurfaceMesh& mesh, std::uint32_t a, std::uint32_t b) { return mesh.position[a] == mesh.position[b]; }

// The quad of triangles s and t when they share the diagonal as one of the pairings does.
bool join(const SurfaceMesh& mesh, std::uint32_t s, std::uint32_t t, TracedQuad& out) {
  const auto& a = mesh.triangles[s];
  const auto& b = mesh.triangles[t];
  if (same_place(mesh, b[0], a[1]) && same_place(mesh, b[2], a[2])) {
    out = {{a[0], a[1], b[1], a[2]}, {s, t}, Pairing::shared_ends};
    return true;
  }
  if (b[0] == a[0] && b[1] == a[2]) {
    out = {{a[1], a[2], b[2], a[0]}, {s, t}, Pairing::shared_first};
    return true;
  }
  return false;
}

}  // namespace

std::vector<TracedQuad> pair_triangles(const SurfaceMesh& mesh, const std::vector<std::uint32_t>& tris) {
  std::vector<TracedQuad> quads;
  pair_triangles(mesh, tris, quads);
  return quads;
}

void pair_triangles(const SurfaceMesh& mesh, const std::vector<std::uint32_t>& tris, std::vector<TracedQuad>& quads) {
  // Pairs are formed greedily within fixed chunks (of an even size, so the mesh's pairs,
  // which start at even positions, are not cut), in parallel; chunk c's quads follow
  // chunk c - 1's.
  constexpr std::size_t kChunk = 8192;
  std::vector<std::vector<TracedQuad>> parts(chunk_count(tris.size(), kChunk));
  parallel_chunks(tris.size(), kChunk, [&](std::size_t begin, std::size_t end, std::size_t c) {
    std::vector<TracedQuad>& part = parts[c];
    part.reserve((end - begin) / 2 + 1);
    for (std::size_t i = begin; i < end;) {
      TracedQuad q;
      if (i + 1 < end && join(mesh, tris[i], tris[i + 1], q)) {
        part.push_back(q);
        i += 2;
      } else {
        const auto& a = mesh.triangles[tris[i]];
        part.push_back({{a[0], a[1], a[2], a[2]}, {tris[i], tris[i]}, Pairing::single});
        i += 1;
      }
    }
  });
  std::size_t count = 0;
  for (const auto& part : parts) count += part.size();
  quads.clear();
  quads.reserve(count);
  for (const auto& part : parts) quads.insert(quads.end(), part.begin(), part.end());
}

TrianglePoint on_triangle(const TracedQuad& quad, float u, float v) {
  // Embree's quad coordinates: (q0 q1 q3) with weights 1-u-v, u, v; (q2 q3 q1) with
  // weights u+v-1, 1-u, 1-v.
  const bool first = u + v <= 1.0f;
  switch (quad.pairing) {
    case Pairing::single: break;
    case Pairing::shared_ends:  // (a b c) = (q0 q1 q3), (b e c) = (q1 q2 q3)
      if (!first) return {quad.triangle[1], u + v - 1.0f, 1.0f - u};
      break;
    case Pairing::shared_first:  // (a b c) = (q3 q0 q1), (a c f) = (q3 q1 q2)
      if (first) return {quad.triangle[0], 1.0f - u - v, u};
      return {quad.triangle[1], 1.0f - v, u + v - 1.0f};
  }
  return {quad.triangle[0], u, v};
}

}  // namespace papertear::render
