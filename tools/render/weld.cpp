#include "tools/render/weld.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>

#include "kernels/parallel.hpp"

namespace papertear::render {

namespace {

using Vec3f = std::array<float, 3>;
using Loop = std::array<int, 4>;

constexpr std::size_t kFaceChunk = 1024;

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

// A corner of a drawn face: the face's cell and the corner's place in its face_loop.
struct Corner {
  std::uint32_t cell;
  int at;
};

// The corners that share one vertex, in ascending cell order (the order of open_faces).
struct Ring {
  std::array<Corner, 4> corner;
  int count = 0;
  void add(const Corner& c) {  // keeps the cells in ascending order
    std::size_t i = std::size_t(count++);
    for (; i > 0 && corner[i - 1].cell > c.cell; --i) corner[i] = corner[i - 1];
    corner[i] = c;
  }
};

// Finds rings. A corner's ring is the corner itself and the corners of the drawn faces of
// the same orientation that hold the same node at the same lattice vertex. Such faces lie in
// the face's plane around the vertex: those of the cell itself and of its neighbours one
// step across the vertex along either in-plane axis, or both. Face loops, their inverses and
// the lattice strides are tables here, as every corner of the mesh asks twice.
class Rings {
 public:
  Rings(const World& w, const std::vector<std::uint8_t>& open) : w_(w), open_(open) {
    const LatticeDims& d = w.topo.dims;
    size_ = {d.nx, d.ny, d.nl};
    stride_ = {1, std::int64_t(d.nx), std::int64_t(d.nx) * d.ny};
    for (int f = 0; f < kFacesPerCell; ++f) {
      loop_[std::size_t(f)] = face_loop(f);
      for (int at = 0; at < 4; ++at) place_[std::size_t(f)][std::size_t(loop_[std::size_t(f)][std::size_t(at)])] = at;
    }
  }

  const Loop& loop(int face) const { return loop_[std::size_t(face)]; }

  // The ring of corner `at` of the drawn face `face` of `cell`, which lies at `ijk`.
  Ring operator()(std::uint32_t cell, const std::array<int, 3>& ijk, int face, int at) const {
    const std::uint32_t node = w_.topo.node(cell, loop(face)[std::size_t(at)]);
    Ring ring;
    ring.add({cell, at});
    for_each_neighbour(cell, ijk, face, at, [&](std::uint32_t c, int q) {
      if (holds(c, face, q, node)) ring.add({c, place_[std::size_t(face)][std::size_t(q)]});
      return true;
    });
    return ring;
  }

  // Whether that corner creates its vertex, i.e. its ring has no corner in a lower cell:
  // only the lower neighbours need a look.
  bool creates(std::uint32_t cell, const std::array<int, 3>& ijk, int face, int at) const {
    const std::uint32_t node = w_.topo.node(cell, loop(face)[std::size_t(at)]);
    return for_each_neighbour(cell, ijk, face, at,
                              [&](std::uint32_t c, int q) { return c > cell || !holds(c, face, q, node); });
  }

 private:
  // Whether cell c draws face `face` and has `node` at its corner q.
  bool holds(std::uint32_t c, int face, int q, std::uint32_t node) const {
    return (open_[c] >> face & 1) && w_.topo.node(c, q) == node;
  }

  // Calls visit(c, q) for each neighbour c of `cell` one step across the vertex of corner
  // `at` along either in-plane axis or both, q being that vertex as a corner of c, until
  // visit returns false; returns whether it never did.
  template <class Visit>
  bool for_each_neighbour(std::uint32_t cell, const std::array<int, 3>& ijk, int face, int at,
                          const Visit& visit) const {
    const int q = loop(face)[std::size_t(at)];
    const int axis = face >> 1;
    const std::array<int, 2> plane = {axis == 0 ? 1 : 0, axis == 2 ? 1 : 2};
    for (int steps = 1; steps < 4; ++steps) {  // bit s: one step along plane[s]
      std::int64_t c = cell;
      int qc = q;
      bool inside = true;
      for (std::size_t s = 0; s < 2; ++s) {
        if (!(steps >> s & 1)) continue;
        const auto a = std::size_t(plane[s]);
        const int dir = (q >> a & 1) ? 1 : -1;  // towards the vertex
        inside = inside && ijk[a] + dir >= 0 && ijk[a] + dir < size_[a];
        c += dir * stride_[a];
        qc ^= 1 << a;
      }
      if (inside && !visit(std::uint32_t(c), qc)) return false;
    }
    return true;
  }

  const World& w_;
  const std::vector<std::uint8_t>& open_;
  std::array<int, 3> size_{};
  std::array<std::int64_t, 3> stride_{};
  std::array<Loop, kFacesPerCell> loop_{};
  std::array<std::array<int, 8>, kFacesPerCell> place_{};  // place_[f][q]: q's place in loop_[f]
};

// The cross products of a face's triangles (v0 v1 v2) and (v0 v2 v3).
std::array<Vec3f, 2> triangle_normals(const World& w, std::uint32_t cell, const Loop& loop) {
  std::array<Vec3f, 4> p{};
  for (std::size_t c = 0; c < 4; ++c) p[c] = node_position(w, w.topo.node(cell, loop[c]));
  return {cross(sub(p[1], p[0]), sub(p[2], p[0])), cross(sub(p[2], p[0]), sub(p[3], p[0]))};
}

// Area-weighted normal of the vertex of `ring`: the cross products of its triangles summed
// in triangle order (float addition is not associative: this order is the serial one); a
// vertex whose faces all collapsed keeps the direction of its face in the rest state.
Vec3f vertex_normal(const World& w, const Ring& ring, const Loop& loop, int face) {
  Vec3f n{0.0f, 0.0f, 0.0f};
  auto add = [&](const Vec3f& t) {
    for (std::size_t c = 0; c < 3; ++c) n[c] += t[c];
  };
  for (int r = 0; r < ring.count; ++r) {
    const Corner& corner = ring.corner[std::size_t(r)];
    const std::array<Vec3f, 2> t = triangle_normals(w, corner.cell, loop);
    if (corner.at != 3) add(t[0]);  // corners 0, 1, 2 are in the first triangle
    if (corner.at != 1) add(t[1]);  // corners 0, 2, 3 in the second
  }
  const float len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  if (len > 1e-20f) {
    for (float& x : n) x /= len;
  } else {
    n = {0.0f, 0.0f, 0.0f};
    n[std::size_t(face >> 1)] = (face & 1) ? 1.0f : -1.0f;
  }
  return n;
}

}  // namespace

WeldedQuads::WeldedQuads(const World& world, const std::vector<OpenFace>& faces, const std::vector<std::uint8_t>& open)
    : world_(world), faces_(faces), open_(open), creates_(faces.size()) {
  const Rings rings(world, open);
  first_vertex_ = chunk_offsets(faces.size(), kFaceChunk, [&](std::size_t begin, std::size_t end) {
    std::size_t created = 0;
    for (std::size_t i = begin; i < end; ++i) {
      const OpenFace& f = faces[i];
      const auto ijk = world.topo.dims.cell_ijk(f.cell);
      std::uint8_t bits = 0;
      for (int at = 0; at < 4; ++at)
        if (rings.creates(f.cell, ijk, f.face, at)) bits |= std::uint8_t(1u << at);
      creates_[i] = bits;
      created += std::size_t(std::popcount(bits));
    }
    return created;
  });
}

void WeldedQuads::write(const std::vector<float>& opacity, SurfaceMesh& mesh) const {
  // The vertex of each (node, face orientation), set by the corner that creates it and read
  // by all of its ring once every vertex is written.
  std::vector<std::uint32_t> vertex_of(world_.nodes.count * kFacesPerCell);
  write_vertices(mesh, vertex_of);
  write_triangles(opacity, vertex_of, mesh);
}

void WeldedQuads::write_vertices(SurfaceMesh& mesh, std::vector<std::uint32_t>& vertex_of) const {
  const LatticeDims& d = world_.topo.dims;
  const Rings rings(world_, open_);
  parallel_chunks(faces_.size(), kFaceChunk, [&](std::size_t begin, std::size_t end, std::size_t chunk) {
    auto next = std::uint32_t(first_vertex_[chunk]);
    for (std::size_t i = begin; i < end; ++i) {
      if (creates_[i] == 0) continue;
      const OpenFace& f = faces_[i];
      const Loop& loop = rings.loop(f.face);
      const auto ijk = d.cell_ijk(f.cell);
      for (int at = 0; at < 4; ++at) {
        if (!(creates_[i] >> at & 1)) continue;
        const std::uint32_t node = world_.topo.node(f.cell, loop[std::size_t(at)]);
        const std::uint32_t original = world_.nodes.vertex[node];
        const auto vertex = d.vertex_ijk(original);
        const std::array<float, 2> uv = {float(vertex[0]) / float(d.nx), 1.0f - float(vertex[1]) / float(d.ny)};
        const Vec3f n = vertex_normal(world_, rings(f.cell, ijk, f.face, at), loop, f.face);
        mesh.set_vertex(next, node_position(world_, node), n, uv, node, original);
        vertex_of[std::size_t(node) * kFacesPerCell + f.face] = next++;
      }
    }
  });
}

void WeldedQuads::write_triangles(const std::vector<float>& opacity, const std::vector<std::uint32_t>& vertex_of,
                                  SurfaceMesh& mesh) const {
  const Rings rings(world_, open_);
  parallel_chunks(faces_.size(), kFaceChunk, [&](std::size_t begin, std::size_t end, std::size_t) {
    for (std::size_t i = begin; i < end; ++i) {
      const OpenFace& f = faces_[i];
      std::array<std::uint32_t, 4> v{};
      for (std::size_t c = 0; c < 4; ++c)
        v[c] = vertex_of[std::size_t(world_.topo.node(f.cell, rings.loop(f.face)[c])) * kFacesPerCell + f.face];
      const Material m = material_of(f.kind);
      const float shade = f.kind == FaceKind::Torn ? 0.9f : 1.0f;
      mesh.set_triangle(2 * i, {v[0], v[1], v[2]}, m, f.kind, f.cell, opacity[f.cell], shade);
      mesh.set_triangle(2 * i + 1, {v[0], v[2], v[3]}, m, f.kind, f.cell, opacity[f.cell], shade);
    }
  });
}

}  // namespace papertear::render
