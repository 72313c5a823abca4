#include "tools/render/surface.hpp"

#include <bit>
#include <cmath>
#include <limits>

#include "fracture/connectivity.hpp"
#include "kernels/parallel.hpp"
#include "tools/render/fray.hpp"
#include "tools/render/peel.hpp"

namespace papertear::render {

std::uint32_t SurfaceMesh::add_vertex(const std::array<float, 3>& p, const std::array<float, 3>& n,
                                      const std::array<float, 2>& t, std::uint32_t node_id,
                                      std::uint32_t original) {
  position.push_back(p);
  normal.push_back(n);
  uv.push_back(t);
  node.push_back(node_id);
  original_node.push_back(original);
  return std::uint32_t(position.size() - 1);
}

void SurfaceMesh::add_triangle(std::array<std::uint32_t, 3> v, Material m, FaceKind k, std::uint32_t cell_id,
                               float alpha, float brightness) {
  triangles.push_back(v);
  material.push_back(m);
  kind.push_back(k);
  cell.push_back(cell_id);
  opacity.push_back(alpha);
  shade.push_back(brightness);
}

void SurfaceMesh::resize(std::size_t vertices, std::size_t triangle_slots) {
  position.resize(vertices);
  normal.resize(vertices);
  uv.resize(vertices);
  node.resize(vertices);
  original_node.resize(vertices);
  triangles.resize(triangle_slots);
  material.resize(triangle_slots);
  kind.resize(triangle_slots);
  cell.resize(triangle_slots);
  opacity.resize(triangle_slots);
  shade.resize(triangle_slots);
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
  std::vector<std::size_t> first(chunk_count(open.size(), kCellChunk) + 1, 0);
  parallel_chunks(open.size(), kCellChunk, [&](std::size_t begin, std::size_t end, std::size_t chunk) {
    for (std::size_t c = begin; c < end; ++c) first[chunk + 1] += std::size_t(std::popcount(open[c]));
  });
  for (std::size_t c = 1; c < first.size(); ++c) first[c] += first[c - 1];
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

namespace {

using Vec3f = std::array<float, 3>;

Vec3f node_position(const World& w, std::uint32_t n) { return {w.nodes.px[n], w.nodes.py[n], w.nodes.pz[n]}; }

Vec3f sub(const Vec3f& a, const Vec3f& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3f cross(const Vec3f& a, const Vec3f& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

Material material_of(FaceKind kind) {
  switch (kind) {
    case FaceKind::Print: return Material::Print;
    case FaceKind::Torn: return Material::Fibre;
    default: return Material::Paper;
  }
}

// The surface faces as welded quads: one vertex per (node, face orientation).
class QuadBuilder {
 public:
  QuadBuilder(const World& w, SurfaceMesh& mesh)
      : w_(w), mesh_(mesh), slot_(w.nodes.count * kFacesPerCell, std::numeric_limits<std::uint32_t>::max()) {}

  void add(const OpenFace& f, float opacity) {
    std::array<std::uint32_t, 4> v{};
    const auto loop = face_loop(f.face);
    for (std::size_t c = 0; c < 4; ++c) v[c] = vertex(w_.topo.node(f.cell, loop[c]), f.face);
    const Material m = material_of(f.kind);
    const float shade = f.kind == FaceKind::Torn ? 0.9f : 1.0f;
    add_triangle({v[0], v[1], v[2]}, m, f, opacity, shade);
    add_triangle({v[0], v[2], v[3]}, m, f, opacity, shade);
  }

  // Area-weighted vertex normals; a vertex whose faces all collapsed keeps the direction of
  // its face in the rest state.
  void finish_normals() {
    for (std::size_t v = 0; v < mesh_.normal.size(); ++v) {
      auto& n = mesh_.normal[v];
      const float len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      if (len > 1e-20f) {
        for (float& x : n) x /= len;
      } else {
        n = {0.0f, 0.0f, 0.0f};
        const int f = rest_face_[v];
        n[std::size_t(f >> 1)] = (f & 1) ? 1.0f : -1.0f;
      }
    }
  }

 private:
  std::uint32_t vertex(std::uint32_t node, int face) {
    std::uint32_t& s = slot_[std::size_t(node) * kFacesPerCell + std::size_t(face)];
    if (s == std::numeric_limits<std::uint32_t>::max()) {
      const LatticeDims& d = w_.topo.dims;
      const std::uint32_t original = w_.nodes.vertex[node];
      const auto ijk = d.vertex_ijk(original);
      const std::array<float, 2> uv = {float(ijk[0]) / float(d.nx), 1.0f - float(ijk[1]) / float(d.ny)};
      s = mesh_.add_vertex(node_position(w_, node), {0.0f, 0.0f, 0.0f}, uv, node, original);
      rest_face_.push_back(face);
    }
    return s;
  }

  void add_triangle(std::array<std::uint32_t, 3> v, Material m, const OpenFace& f, float opacity, float shade) {
    const Vec3f n = cross(sub(mesh_.position[v[1]], mesh_.position[v[0]]),
                          sub(mesh_.position[v[2]], mesh_.position[v[0]]));
    for (std::uint32_t i : v)
      for (std::size_t c = 0; c < 3; ++c) mesh_.normal[i][c] += n[c];
    mesh_.add_triangle(v, m, f.kind, f.cell, opacity, shade);
  }

  const World& w_;
  SurfaceMesh& mesh_;
  std::vector<std::uint32_t> slot_;
  std::vector<int> rest_face_;
};

}  // namespace

SurfaceMesh build_surface_mesh(const World& world, const MeshOptions& options) {
  const std::vector<OpenFace> faces = open_faces(world, open_face_masks(world));
  const std::vector<float> opacity = cell_opacity(world, options.layer_opacity);
  SurfaceMesh mesh;
  mesh.triangles.reserve(faces.size() * 2);
  QuadBuilder quads(world, mesh);
  for (const OpenFace& f : faces) quads.add(f, opacity[f.cell]);
  quads.finish_normals();
  if (options.fray) append_frayed_faces(world, faces, options.fray_length, opacity, mesh);
  return mesh;
}

}  // namespace papertear::render
