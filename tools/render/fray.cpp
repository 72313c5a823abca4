#include "tools/render/fray.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "kernels/parallel.hpp"
#include "tools/render/hash.hpp"

namespace papertear::render {

namespace {

using Vec3 = Eigen::Vector3f;

constexpr float kShortestFringe = 0.1f;  // of the longest fibre: shorter fringes are not drawn
constexpr std::size_t kFaceChunk = 1024;  // faces per chunk of plan_fibres and write_fibres

bool torn(const OpenFace& f) { return f.kind == FaceKind::Torn; }

// The torn face as a bilinear patch P(u, w): u runs along the face in the sheet's plane,
// w up through the thickness.
struct FacePatch {
  Vec3 p[2][2];                 // p[u][w]
  std::uint32_t node[2][2];
  std::array<float, 2> uv[2][2];
  Vec3 outward;                 // unit normal, pointing out of the cell

  Vec3 at(float u, float w) const {
    return (1 - u) * ((1 - w) * p[0][0] + w * p[0][1]) + u * ((1 - w) * p[1][0] + w * p[1][1]);
  }
  std::array<float, 2> uv_at(float u, float w) const {
    std::array<float, 2> out{};
    for (std::size_t c = 0; c < 2; ++c)
      out[c] = (1 - u) * ((1 - w) * uv[0][0][c] + w * uv[0][1][c]) + u * ((1 - w) * uv[1][0][c] + w * uv[1][1][c]);
    return out;
  }
  std::uint32_t nearest_node(float u, float w) const { return node[u < 0.5f ? 0 : 1][w < 0.5f ? 0 : 1]; }
};

// Returns false for a face squashed to nothing (no direction to grow fibres in).
bool make_patch(const World& world, std::uint32_t cell, int face, FacePatch& out) {
  const LatticeDims& d = world.topo.dims;
  const int axis = face >> 1, side = face & 1;
  const int tangent = 1 - axis;  // torn faces are in-plane faces: axis 0 or 1
  for (int bu = 0; bu < 2; ++bu)
    for (int bw = 0; bw < 2; ++bw) {
      const int q = (side << axis) | (bu << tangent) | (bw << 2);
      const std::uint32_t n = world.topo.node(cell, q);
      out.p[bu][bw] = Vec3(world.nodes.px[n], world.nodes.py[n], world.nodes.pz[n]);
      out.node[bu][bw] = n;
      const auto ijk = d.vertex_ijk(world.nodes.vertex[n]);
      out.uv[bu][bw] = {float(ijk[0]) / float(d.nx), 1.0f - float(ijk[1]) / float(d.ny)};
    }
  const Vec3 du = out.p[1][0] + out.p[1][1] - out.p[0][0] - out.p[0][1];
  const Vec3 dw = out.p[0][1] + out.p[1][1] - out.p[0][0] - out.p[1][0];
  Vec3 n = du.cross(dw);
  if (!(n.norm() > 1e-12f)) return false;
  // e_tangent x e_z is +x for tangent y and -y for tangent x; the outward normal is
  // +e_axis on a high face and -e_axis on a low one.
  const float cross_sign = tangent == 1 ? 1.0f : -1.0f;
  const float outward_sign = side ? 1.0f : -1.0f;
  out.outward = n.normalized() * (cross_sign * outward_sign);
  return true;
}

// How far the torn face has moved away from the face it was joined to: the mean distance
// between the four pairs of nodes that were one node before the tear.
float opening(const World& world, std::uint32_t cell, int face) {
  const LatticeDims& d = world.topo.dims;
  const auto ijk = d.cell_ijk(cell);
  const std::int64_t other = d.neighbour(ijk[0], ijk[1], ijk[2], face);
  if (other < 0) return 0.0f;
  const int axis = face >> 1;
  float sum = 0.0f;
  for (int q : face_corners(face)) {
    const std::uint32_t a = world.topo.node(cell, q), b = world.topo.node(std::uint32_t(other), q ^ (1 << axis));
    const Vec3 pa(world.nodes.px[a], world.nodes.py[a], world.nodes.pz[a]);
    const Vec3 pb(world.nodes.px[b], world.nodes.py[b], world.nodes.pz[b]);
    sum += (pb - pa).norm();
  }
  return 0.25f * sum;
}

struct Tooth {
  float u0, u1, w0, w1;   // base rectangle on the face
  float tip_u, tip_w;     // where the tip stands over the face
  float length;           // how far it sticks out, in cell sizes
  float lean;             // sideways lean of the tip, in cell sizes
  float lift;             // up/down curl of the tip, in cell sizes
  float shade;
};

// The teeth of one face: 3 to 5 clumps across it, a third of them thin single fibres.
// Fixed capacity: a frame has tens of thousands of torn faces, and no allocation per face.
constexpr int kMostTeeth = 5;
struct Teeth {
  std::array<Tooth, kMostTeeth> at;
  int count = 0;
  const Tooth* begin() const { return at.data(); }
  const Tooth* end() const { return at.data() + count; }
};

Teeth make_teeth(std::uint32_t cell, int face, float length) {
  HashStream rng(hash_key(cell, std::uint64_t(face), 0x6672617945ull));
  const int count = 3 + rng.below(kMostTeeth - 2);
  std::array<float, kMostTeeth + 1> edge{};
  for (int t = 0; t < count; ++t) edge[std::size_t(t) + 1] = edge[std::size_t(t)] + rng.uniform(0.6f, 1.6f);
  for (int t = 0; t <= count; ++t) edge[std::size_t(t)] /= edge[std::size_t(count)];
  Teeth teeth;
  for (int t = 0; t < count; ++t) {
    Tooth th{};
    const float a = edge[std::size_t(t)], b = edge[std::size_t(t) + 1];
    th.tip_u = a + (b - a) * rng.uniform(0.25f, 0.75f);
    const bool fibre = rng.uniform() < 0.35f;
    if (fibre) {  // a single loose fibre: narrow base, long
      const float half_u = std::min(0.08f, 0.5f * (b - a));
      th.tip_w = rng.uniform(0.35f, 0.95f);
      th.u0 = std::max(0.0f, th.tip_u - half_u);
      th.u1 = std::min(1.0f, th.tip_u + half_u);
      th.w0 = std::max(0.0f, th.tip_w - 0.15f);
      th.w1 = std::min(1.0f, th.tip_w + 0.15f);
      th.length = length * rng.uniform(0.9f, 1.5f);
    } else {      // a clump: the whole height of its stretch of face
      th.tip_w = rng.uniform(0.45f, 1.0f);
      th.u0 = a;
      th.u1 = b;
      th.w0 = 0.0f;
      th.w1 = 1.0f;
      th.length = length * rng.uniform(0.3f, 0.9f);
    }
    th.lean = rng.uniform(-0.15f, 0.15f);
    th.lift = rng.uniform(-0.12f, 0.0f);  // never above the face: the print stays clean
    th.shade = rng.uniform(0.88f, 1.0f);
    teeth.at[std::size_t(teeth.count++)] = th;
  }
  return teeth;
}

// Calls fibre(f, p, uw, n, shade) for every fibre triangle of torn face `face` of `cell`:
// its corners p at face coordinates uw (u, w) of face patch f, its unit normal n. Both passes
// (plan_fibres, write_fibres) see the same triangles.
template <class Fibre>
void for_each_fibre(const World& world, std::uint32_t cell, int face, float length, const Fibre& fibre) {
  FacePatch f;
  const LatticeDims& d = world.topo.dims;
  const float cell_size = float((face >> 1) == 0 ? d.hx : d.hy);
  // Fibres grow as the tear opens: from each side they reach at most half way across the
  // gap, so a crack that has only just split shows none, and none poke into the cell
  // they were torn from.
  const float longest = length;
  length = std::min(length, 0.5f * opening(world, cell, face) / cell_size);
  // A fringe shorter than a tenth of the longest lies nearly flat on its face, which is
  // drawn fibre-white anyway; in a damage zone of hairline cracks such fringes would be
  // half of a frame's triangles, and every triangle costs the ray tracer's BVH build.
  if (length < kShortestFringe * longest || length <= 1e-3f || !make_patch(world, cell, face, f)) return;
  // The in-plane tangent and the sheet's up direction at this face, for lean and lift.
  const Vec3 along = (f.p[1][0] + f.p[1][1] - f.p[0][0] - f.p[0][1]).normalized();
  const Vec3 up = (f.p[0][1] + f.p[1][1] - f.p[0][0] - f.p[1][0]).normalized();
  // The base loop (u0,w0) (u1,w0) (u1,w1) (u0,w1) turns counter-clockwise about
  // du x dw; the side triangles face outwards when it turns about the outward normal.
  const Vec3 du_x_dw = (f.p[1][0] - f.p[0][0]).cross(f.p[0][1] - f.p[0][0]);
  const bool reverse = du_x_dw.dot(f.outward) < 0.0f;
  for (const Tooth& t : make_teeth(cell, face, length)) {
    float loop[4][2] = {{t.u0, t.w0}, {t.u1, t.w0}, {t.u1, t.w1}, {t.u0, t.w1}};
    if (reverse) {
      std::swap(loop[1][0], loop[3][0]);
      std::swap(loop[1][1], loop[3][1]);
    }
    const Vec3 tip = f.at(t.tip_u, t.tip_w) +
                     cell_size * (t.length * f.outward + t.lean * along + t.lift * up);
    Vec3 base[4];  // each corner of the base is in two sides
    for (int e = 0; e < 4; ++e) base[e] = f.at(loop[e][0], loop[e][1]);
    for (int e = 0; e < 4; ++e) {
      const float* a = loop[e];
      const float* b = loop[(e + 1) % 4];
      const Vec3 p[3] = {base[e], base[(e + 1) % 4], tip};
      const float uw[3][2] = {{a[0], a[1]}, {b[0], b[1]}, {t.tip_u, t.tip_w}};
      Vec3 n = (p[1] - p[0]).cross(p[2] - p[0]);
      if (!(n.norm() > 1e-20f)) continue;
      n.normalize();
      fibre(f, p, uw, n, t.shade);
    }
  }
}

// Writes fibre triangles from triangle `next` on into a mesh already grown to hold them:
// fibre triangle t owns the three vertices from first_vertex + 3 (t - first_triangle) on.
class FibreWriter {
 public:
  FibreWriter(const World& world, const FibreRegion& region, std::size_t next, SurfaceMesh& mesh)
      : world_(world), region_(region), next_(next), mesh_(mesh) {}

  void face(std::uint32_t cell, float opacity) {
    cell_ = cell;
    opacity_ = opacity;
  }

  void operator()(const FacePatch& f, const Vec3 (&p)[3], const float (&uw)[3][2], const Vec3& n, float shade) {
    const auto first = std::uint32_t(region_.first_vertex + 3 * (next_ - region_.first_triangle));
    std::array<std::uint32_t, 3> v{};
    for (std::size_t c = 0; c < 3; ++c) {
      const std::uint32_t node = f.nearest_node(uw[c][0], uw[c][1]);
      v[c] = first + std::uint32_t(c);
      mesh_.set_vertex(v[c], {p[c].x(), p[c].y(), p[c].z()}, {n.x(), n.y(), n.z()}, f.uv_at(uw[c][0], uw[c][1]), node,
                       world_.nodes.vertex[node]);
    }
    mesh_.set_triangle(next_++, v, Material::Fibre, FaceKind::Torn, cell_, opacity_, shade);
  }

 private:
  const World& world_;
  FibreRegion region_;
  std::size_t next_;
  SurfaceMesh& mesh_;
  std::uint32_t cell_ = 0;
  float opacity_ = 1.0f;
};

}  // namespace

FibrePlan plan_fibres(const World& world, const std::vector<OpenFace>& faces, float length) {
  FibrePlan plan;
  plan.first = chunk_offsets(faces.size(), kFaceChunk, [&](std::size_t begin, std::size_t end) {
    std::size_t triangles = 0;
    for (std::size_t i = begin; i < end; ++i)
      if (torn(faces[i])) for_each_fibre(world, faces[i].cell, faces[i].face, length, [&](auto&&...) { ++triangles; });
    return triangles;
  });
  return plan;
}

void write_fibres(const World& world, const std::vector<OpenFace>& faces, float length,
                  const std::vector<float>& opacity, const FibrePlan& plan, const FibreRegion& region,
                  SurfaceMesh& mesh) {
  parallel_chunks(faces.size(), kFaceChunk, [&](std::size_t begin, std::size_t end, std::size_t c) {
    FibreWriter write(world, region, region.first_triangle + plan.first[c], mesh);
    for (std::size_t i = begin; i < end; ++i) {
      if (!torn(faces[i])) continue;
      write.face(faces[i].cell, opacity[faces[i].cell]);
      for_each_fibre(world, faces[i].cell, faces[i].face, length, std::ref(write));
    }
  });
}

}  // namespace papertear::render
