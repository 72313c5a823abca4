#include "tools/render/surface.hpp"

#include <bit>

#include "fracture/connectivity.hpp"
#include "kernels/parallel.hpp"
#include "tools/render/fray.hpp"
#include "tools/render/peel.hpp"
#include "tools/render/weld.hpp"

namespace papertear::render {

namespace {

// resize() of one array without copying its entries when it grows: every entry is rewritten.
// Room for a few more (tears only grow) spares the next frames a reallocation, and at least
// one spare element lets the ray tracer hand the positions to Embree as they are (it loads
// 16 bytes at a vertex).
template <class T>
void resize_for_overwrite(MeshArray<T>& a, std::size_t n) {
  if (n >= a.capacity()) {
    a.clear();
    a.reserve(n + n / 16 + 1);
  }
  a.resize(n);
}

}  // namespace

void SurfaceMesh::resize(std::size_t vertices, std::size_t triangle_slots) {
  resize_for_overwrite(position, vertices);
  resize_for_overwrite(normal, vertices);
  resize_for_overwrite(uv, vertices);
  resize_for_overwrite(node, vertices);
  resize_for_overwrite(original_node, vertices);
  resize_for_overwrite(triangles, triangle_slots);
  resize_for_overwrite(material, triangle_slots);
  resize_for_overwrite(kind, triangle_slots);
  resize_for_overwrite(cell, triangle_slots);
  resize_for_overwrite(opacity, triangle_slots);
  resize_for_overwrite(shade, triangle_slots);
}

void SurfaceMesh::set_vertex(std::uint32_t i, const std::array<float, 3>& p, const std::array<float, 3>& n,
                             const std::array<float, 2>& t, std::uint32_t node_id, std::uint32_t original) {
  position[i] = p;
  normal[i] = n;
  uv[i] = t;
  node[i] = node_id;
  original_node[i] = original;
}

void SurfaceMesh::set_triangle(std::size_t i, std::array<std::uint32_t, 3> v, Material m, FaceKind k,
                               std::uint32_t cell_id, float alpha, float brightness) {
  triangles[i] = v;
  material[i] = m;
  kind[i] = k;
  cell[i] = cell_id;
  opacity[i] = alpha;
  shade[i] = brightness;
}

std::array<int, 4> face_loop(int face) {
  const int axis = face >> 1, side = face & 1;
  const int a1 = axis == 0 ? 1 : 0, a2 = axis == 2 ? 1 : 2;
  // (0,0) (1,0) (1,1) (0,1) in the bits of (a1, a2) turns counter-clockwise about
  // e_a1 x e_a2, which is +e_axis for axes x and z and -e_axis for y.
  const int bits[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  std::array<int, 4> loop{};
  for (int c = 0; c < 4; ++c) loop[std::size_t(c)] = (side << axis) | (bits[c][0] << a1) | (bits[c][1] << a2);
  const bool turns_outward = (axis == 1) != (side == 1);
  if (!turns_outward) std::swap(loop[1], loop[3]);
  return loop;
}

namespace {

// Cells are taken in fixed chunks: the list comes out the same on any number of threads.
constexpr std::size_t kCellChunk = 1024;

// The kind of open face f of the cell at ijk.
FaceKind kind_of(const LatticeDims& d, const std::array<int, 3>& ijk, int f) {
  const bool outside = d.neighbour(ijk[0], ijk[1], ijk[2], f) < 0;
  if (outside) return (f == 5 && ijk[2] == d.nl - 1) ? FaceKind::Print : FaceKind::Outer;
  return (f >> 1) == 2 ? FaceKind::Separated : FaceKind::Torn;
}

}  // namespace

std::vector<std::uint8_t> open_face_masks(const World& world) {
  const std::size_t cells = std::size_t(world.topo.dims.cells());
  std::vector<std::uint8_t> open(cells);
  parallel_chunks(cells, kCellChunk, [&](std::size_t begin, std::size_t end, std::size_t) {
    for (std::size_t c = begin; c < end; ++c) {
      std::uint8_t bits = 0;
      for (int f = 0; f < kFacesPerCell; ++f)
        if (!faces_connected(world, std::uint32_t(c), f)) bits |= std::uint8_t(1u << f);
      open[c] = bits;
    }
  });
  return open;
}

std::vector<OpenFace> open_faces(const World& world, const std::vector<std::uint8_t>& open) {
  // Two passes over the same chunks: count each chunk's faces, then write them at their place.
  const LatticeDims& d = world.topo.dims;
  const std::vector<std::size_t> first = chunk_offsets(open.size(), kCellChunk, [&](std::size_t begin, std::size_t end) {
    std::size_t faces = 0;
    for (std::size_t c = begin; c < end; ++c) faces += std::size_t(std::popcount(open[c]));
    return faces;
  });
  std::vector<OpenFace> out(first.back());
  parallel_chunks(open.size(), kCellChunk, [&](std::size_t begin, std::size_t end, std::size_t chunk) {
    std::size_t next = first[chunk];
    for (std::size_t c = begin; c < end; ++c) {
      const auto ijk = d.cell_ijk(std::uint32_t(c));
      for (int f = 0; f < kFacesPerCell; ++f)
        if (open[c] >> f & 1) out[next++] = {std::uint32_t(c), std::uint8_t(f), kind_of(d, ijk, f)};
    }
  });
  return out;
}

std::vector<OpenFace> open_faces(const World& world) { return open_faces(world, open_face_masks(world)); }

SurfaceMesh build_surface_mesh(const World& world, const MeshOptions& options) {
  SurfaceMesh mesh;
  build_surface_mesh(world, options, mesh);
  return mesh;
}

void build_surface_mesh(const World& world, const MeshOptions& options, SurfaceMesh& mesh) {
  const std::vector<std::uint8_t> open = open_face_masks(world);
  const std::vector<OpenFace> faces = open_faces(world, open);
  const std::vector<float> opacity = cell_opacity(world, options.layer_opacity);
  const WeldedQuads quads(world, faces, open);
  const FibrePlan fibres = options.fray ? plan_fibres(world, faces, options.fray_length) : FibrePlan{};
  // Everything is counted before anything is written, so the mesh is sized once: no copies
  // of grown arrays. The fibres come after the quads' triangles and vertices.
  mesh.resize(quads.vertex_count() + 3 * fibres.triangle_count(), quads.triangle_count() + fibres.triangle_count());
  quads.write(opacity, mesh);
  mesh.sheet_vertices = quads.vertex_count();
  mesh.sheet_triangles = quads.triangle_count();
  if (options.fray)
    write_fibres(world, faces, options.fray_length, opacity, fibres, {quads.triangle_count(), quads.vertex_count()},
                 mesh);
}

}  // namespace papertear::render
