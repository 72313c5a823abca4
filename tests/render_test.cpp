// The renderer (tools/render/): surface extraction, frayed torn faces, peeled skins, frames.
// Worlds are built here by hand: an intact lattice from build_lattice, a tear made the way
// fracture makes one (cells on one side get new copies of the nodes on the cut plane).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <thread>

#include <oneapi/tbb/task_arena.h>
#include <toml++/toml.h>

#include "core/lattice_builder.hpp"
#include "core/scene.hpp"
#include "core/contact.hpp"
#include "tools/render/indenter_mesh.hpp"
#include "tools/render/render.hpp"
#include "tools/render/peel.hpp"
#include "tools/render/quads.hpp"

using namespace papertear;
using namespace papertear::render;

namespace {

World make_sheet(int nx, int ny, int nl) {
  Scene scene;
  scene.sheet.cells = {nx, ny, nl};
  scene.sheet.cell_size = {1.0, 1.0, 1.0};  // cubes: the checks below count in whole cells
  World w;
  build_lattice(scene, w);
  return w;
}

// Appends a copy of node n (same position, velocity and lattice vertex) and returns its id.
std::uint32_t copy_node(World& w, std::uint32_t n) {
  const std::size_t id = w.nodes.count;
  NodeStore& s = w.nodes;
  s.resize(id + 1);
  s.px[id] = s.px[n]; s.py[id] = s.py[n]; s.pz[id] = s.pz[n];
  s.vx[id] = s.vx[n]; s.vy[id] = s.vy[n]; s.vz[id] = s.vz[n];
  s.vertex[id] = s.vertex[n];
  s.mass[id] = s.mass[n];
  s.inv_mass[id] = s.inv_mass[n];
  return std::uint32_t(id);
}

// Gives every cell accepted by `side(i, j, k)` new copies of the nodes it shares with cells
// that are not accepted, as a run of splits would; returns the new nodes.
template <class Side>
std::vector<std::uint32_t> split_off(World& w, Side side) {
  const LatticeDims& d = w.topo.dims;
  std::vector<char> inside_use(w.nodes.count, 0), outside_use(w.nodes.count, 0);
  for (std::uint32_t c = 0; c < d.cells(); ++c) {
    const auto ijk = d.cell_ijk(c);
    auto& use = side(ijk[0], ijk[1], ijk[2]) ? inside_use : outside_use;
    for (int q = 0; q < 8; ++q) use[w.topo.node(c, q)] = 1;
  }
  std::vector<std::uint32_t> copy(w.nodes.count, std::numeric_limits<std::uint32_t>::max());
  std::vector<std::uint32_t> added;
  const std::size_t old_count = w.nodes.count;
  for (std::uint32_t n = 0; n < old_count; ++n)
    if (inside_use[n] && outside_use[n]) added.push_back(copy[n] = copy_node(w, n));
  for (std::uint32_t c = 0; c < d.cells(); ++c) {
    const auto ijk = d.cell_ijk(c);
    if (!side(ijk[0], ijk[1], ijk[2])) continue;
    for (int q = 0; q < 8; ++q) {
      std::uint32_t& n = w.topo.cell_nodes[std::size_t(c) * 8 + std::size_t(q)];
      if (copy[n] != std::numeric_limits<std::uint32_t>::max()) n = copy[n];
    }
  }
  return added;
}

// Tears the sheet across x = nx/2 and moves the right half `gap` cells further right.
World torn_sheet(int nx, int ny, int nl, float gap) {
  World w = make_sheet(nx, ny, nl);
  const int cut = nx / 2;
  split_off(w, [&](int i, int, int) { return i >= cut; });
  std::set<std::uint32_t> right;
  for (std::uint32_t c = 0; c < w.topo.dims.cells(); ++c)
    if (w.topo.dims.cell_ijk(c)[0] >= cut)
      for (int q = 0; q < 8; ++q) right.insert(w.topo.node(c, q));
  for (std::uint32_t n : right) w.nodes.px[n] += gap;
  return w;
}

std::size_t count_kind(const std::vector<OpenFace>& faces, FaceKind kind) {
  return std::size_t(std::count_if(faces.begin(), faces.end(), [&](const OpenFace& f) { return f.kind == kind; }));
}

RenderSettings small_frame(int w, int h) {
  RenderSettings s;
  s.width = w;
  s.height = h;
  s.samples = 2;
  return s;
}

}  // namespace

TEST_CASE("an intact sheet's surface is exactly its outer faces", "[render]") {
  const int nx = 7, ny = 5, nl = 3;
  const World w = make_sheet(nx, ny, nl);
  const auto faces = open_faces(w);
  CHECK(faces.size() == std::size_t(2 * (nx * ny + ny * nl + nx * nl)));
  CHECK(count_kind(faces, FaceKind::Print) == std::size_t(nx * ny));
  CHECK(count_kind(faces, FaceKind::Torn) == 0);
  CHECK(count_kind(faces, FaceKind::Separated) == 0);
  for (const OpenFace& f : faces)
    if (f.kind == FaceKind::Print) CHECK(w.topo.dims.cell_ijk(f.cell)[2] == nl - 1);

  const SurfaceMesh mesh = build_surface_mesh(w);
  CHECK(mesh.triangle_count() == 2 * faces.size());
  // One vertex per node and face orientation: each side of the box is a welded grid.
  const std::size_t grid_vertices =
      std::size_t(2 * ((nx + 1) * (ny + 1) + (ny + 1) * (nl + 1) + (nx + 1) * (nl + 1)));
  CHECK(mesh.vertex_count() == grid_vertices);
}

TEST_CASE("triangles face outwards and normals agree with them", "[render]") {
  const World w = make_sheet(4, 3, 2);
  const SurfaceMesh mesh = build_surface_mesh(w);
  const float centre[3] = {2.0f, 1.5f, 1.0f};
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const auto& v = mesh.triangles[t];
    const auto& a = mesh.position[v[0]];
    const auto& b = mesh.position[v[1]];
    const auto& c = mesh.position[v[2]];
    const float e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const float e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const float n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    const float out[3] = {a[0] - centre[0], a[1] - centre[1], a[2] - centre[2]};
    INFO("triangle " << t);
    CHECK(n[0] * out[0] + n[1] * out[1] + n[2] * out[2] > 0.0f);
    const auto& vn = mesh.normal[v[0]];
    CHECK(vn[0] * n[0] + vn[1] * n[1] + vn[2] * n[2] > 0.0f);
  }
}

TEST_CASE("a sheet torn in two has matching torn faces on both sides", "[render]") {
  const int nx = 8, ny = 5, nl = 3;
  const World w = torn_sheet(nx, ny, nl, 2.0f);
  const auto faces = open_faces(w);
  std::size_t left = 0, right = 0;
  for (const OpenFace& f : faces) {
    if (f.kind != FaceKind::Torn) continue;
    const int i = w.topo.dims.cell_ijk(f.cell)[0];
    if (f.face == 1 && i == nx / 2 - 1) ++left;
    else if (f.face == 0 && i == nx / 2) ++right;
    else FAIL("torn face away from the cut: cell " << f.cell << " face " << int(f.face));
  }
  CHECK(left == std::size_t(ny * nl));
  CHECK(right == left);
  CHECK(count_kind(faces, FaceKind::Print) == std::size_t(nx * ny));
  CHECK(faces.size() == std::size_t(2 * (nx * ny + ny * nl + nx * nl) + 2 * ny * nl));
}

TEST_CASE("vertices remember their node and the print position where it was", "[render]") {
  const int nx = 8, ny = 5, nl = 2;
  const World w = torn_sheet(nx, ny, nl, 1.5f);
  const SurfaceMesh mesh = build_surface_mesh(w, {.fray = false});
  bool saw_copy = false;
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    const std::uint32_t n = mesh.node[v];
    REQUIRE(n < w.nodes.count);
    CHECK(mesh.original_node[v] == w.nodes.vertex[n]);
    saw_copy |= n != mesh.original_node[v];
    const auto ijk = w.topo.dims.vertex_ijk(mesh.original_node[v]);
    CHECK(mesh.uv[v][0] == Approx(float(ijk[0]) / float(nx)));
    CHECK(mesh.uv[v][1] == Approx(1.0f - float(ijk[1]) / float(ny)));
  }
  CHECK(saw_copy);  // the right half's cut nodes are copies, yet keep their original vertex
}

TEST_CASE("frayed fibres stick out of torn faces only, the same way every time", "[render]") {
  const int nx = 8, ny = 6, nl = 3;
  const World w = torn_sheet(nx, ny, nl, 3.0f);
  const MeshOptions options{.fray = true, .fray_length = 0.5f, .layer_opacity = 0.5f};
  const SurfaceMesh a = build_surface_mesh(w, options);
  const SurfaceMesh b = build_surface_mesh(w, options);
  CHECK(a.position == b.position);
  CHECK(a.triangles == b.triangles);

  const SurfaceMesh plain = build_surface_mesh(w, {.fray = false});
  REQUIRE(a.triangle_count() > plain.triangle_count());
  // Fibres of the left half stand on x = cut and reach into the gap, never past it.
  const float cut = float(nx / 2);
  float reach = 0.0f;
  std::set<float> tip_lengths;
  for (std::size_t t = plain.triangle_count(); t < a.triangle_count(); ++t) {
    CHECK(a.kind[t] == FaceKind::Torn);
    CHECK(a.material[t] == Material::Fibre);
    for (std::uint32_t v : a.triangles[t]) {
      const float x = a.position[v][0];
      if (x < cut + 1.5f) {  // left half's fibres
        CHECK(x >= cut - 0.2f);
        CHECK(x <= cut + 0.5f * 1.5f + 1e-4f);
        reach = std::max(reach, x - cut);
        tip_lengths.insert(x - cut);
      }
    }
  }
  CHECK(reach > 0.2f);
  CHECK(tip_lengths.size() > 10);  // fibres differ from face to face

  // A crack that has split but not opened grows no fibres; a narrow one grows short ones.
  const SurfaceMesh closed = build_surface_mesh(torn_sheet(nx, ny, nl, 0.0f), options);
  CHECK(closed.triangle_count() == plain.triangle_count());
  // A hairline crack whose fringe would be under a tenth of fray_length grows none either.
  const SurfaceMesh hairline = build_surface_mesh(torn_sheet(nx, ny, nl, 0.09f), options);
  CHECK(hairline.triangle_count() == plain.triangle_count());
  const SurfaceMesh narrow = build_surface_mesh(torn_sheet(nx, ny, nl, 0.2f), options);
  REQUIRE(narrow.triangle_count() > plain.triangle_count());
  for (std::size_t t = plain.triangle_count(); t < narrow.triangle_count(); ++t)
    for (std::uint32_t v : narrow.triangles[t])
      if (narrow.position[v][0] < cut + 0.1f) CHECK(narrow.position[v][0] <= cut + 0.1f * 1.5f + 1e-4f);
}

void check_same_mesh(const SurfaceMesh& m, const SurfaceMesh& one) {
  CHECK(m.position == one.position);
  CHECK(m.normal == one.normal);
  CHECK(m.uv == one.uv);
  CHECK(m.node == one.node);
  CHECK(m.original_node == one.original_node);
  CHECK(m.triangles == one.triangles);
  CHECK(m.material == one.material);
  CHECK(m.kind == one.kind);
  CHECK(m.cell == one.cell);
  CHECK(m.opacity == one.opacity);
  CHECK(m.shade == one.shade);
}

TEST_CASE("a surface mesh built into a used one is the same as a fresh one", "[render]") {
  World big = torn_sheet(40, 30, 3, 1.0f);
  split_off(big, [](int i, int j, int k) { return k == 2 && i < 10 && j < 20; });
  const World small = torn_sheet(12, 8, 2, 0.5f);
  const World intact = make_sheet(20, 16, 3);
  const MeshOptions options{.fray = true, .fray_length = 0.45f, .layer_opacity = 0.7f};
  const SurfaceMesh fresh_big = build_surface_mesh(big, options);
  const SurfaceMesh fresh_small = build_surface_mesh(small, options);
  REQUIRE(fresh_big.triangle_count() > 2 * fresh_small.triangle_count());
  // Shrinking, growing past the capacity, and a mesh with no fibres in between.
  SurfaceMesh used;
  for (const World* w : std::initializer_list<const World*>{&small, &big, &intact, &small, &big}) {
    build_surface_mesh(*w, options, used);
    if (w == &intact) continue;
    INFO((w == &big ? "big" : "small"));
    check_same_mesh(used, w == &big ? fresh_big : fresh_small);
  }
}

TEST_CASE("the surface mesh has the same bytes on any number of threads", "[render]") {
  // Two tears, so that fibres come from several of the fixed chunks of faces, and a peeled
  // skin (separated faces, translucent cells).
  World w = torn_sheet(40, 30, 3, 1.0f);
  split_off(w, [](int, int j, int) { return j >= 20; });
  split_off(w, [](int i, int j, int k) { return k == 2 && i < 10 && j < 20; });
  const MeshOptions options{.fray = true, .fray_length = 0.45f, .layer_opacity = 0.7f};
  SurfaceMesh one;
  tbb::task_arena(1).execute([&] { one = build_surface_mesh(w, options); });
  REQUIRE(open_faces(w).size() > 3 * 1024);
  REQUIRE(count_kind(open_faces(w), FaceKind::Separated) > 0);
  REQUIRE(std::any_of(one.opacity.begin(), one.opacity.end(), [](float a) { return a < 1.0f; }));
  for (int threads : {2, 3, 16}) {
    SurfaceMesh m;
    tbb::task_arena(threads).execute([&] { m = build_surface_mesh(w, options); });
    INFO(threads << " threads");
    check_same_mesh(m, one);
  }
  // Each fibre triangle has three vertices of its own, in order after the faces'.
  const SurfaceMesh plain = build_surface_mesh(w, {.fray = false});
  REQUIRE(one.triangle_count() > plain.triangle_count() + 1000);
  for (std::size_t t = plain.triangle_count(); t < one.triangle_count(); ++t) {
    const auto first = std::uint32_t(plain.vertex_count() + 3 * (t - plain.triangle_count()));
    CHECK(one.triangles[t] == std::array<std::uint32_t, 3>{first, first + 1, first + 2});
  }
}

namespace {

using Vec3f = std::array<float, 3>;

// The welded quads as the serial definition has them (surface.hpp): faces in order, corners
// in face_loop order, a new vertex for every (node, face orientation) not met before; each
// triangle's cross product added to its three vertices in triangle order, then normalised.
SurfaceMesh weld_serially(const World& w) {
  SurfaceMesh r;
  std::map<std::pair<std::uint32_t, int>, std::uint32_t> id;
  std::vector<int> rest_face;
  auto sub = [](const Vec3f& a, const Vec3f& b) { return Vec3f{a[0] - b[0], a[1] - b[1], a[2] - b[2]}; };
  auto cross = [](const Vec3f& a, const Vec3f& b) {
    return Vec3f{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
  };
  for (const OpenFace& f : open_faces(w)) {
    const auto loop = face_loop(f.face);
    std::array<std::uint32_t, 4> v{};
    for (std::size_t c = 0; c < 4; ++c) {
      const std::uint32_t n = w.topo.node(f.cell, loop[c]);
      const auto [at, fresh] = id.try_emplace({n, int(f.face)}, std::uint32_t(r.position.size()));
      if (fresh) {
        r.position.push_back({w.nodes.px[n], w.nodes.py[n], w.nodes.pz[n]});
        r.normal.push_back({0.0f, 0.0f, 0.0f});
        r.node.push_back(n);
        rest_face.push_back(f.face);
      }
      v[c] = at->second;
    }
    for (const std::array<std::uint32_t, 3> t : {std::array{v[0], v[1], v[2]}, std::array{v[0], v[2], v[3]}}) {
      const Vec3f n = cross(sub(r.position[t[1]], r.position[t[0]]), sub(r.position[t[2]], r.position[t[0]]));
      for (std::uint32_t i : t)
        for (std::size_t c = 0; c < 3; ++c) r.normal[i][c] += n[c];
      r.triangles.push_back(t);
    }
  }
  for (std::size_t v = 0; v < r.normal.size(); ++v) {
    Vec3f& n = r.normal[v];
    const float len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (len > 1e-20f) {
      for (float& x : n) x /= len;
    } else {
      n = {0.0f, 0.0f, 0.0f};
      n[std::size_t(rest_face[v] >> 1)] = (rest_face[v] & 1) ? 1.0f : -1.0f;
    }
  }
  return r;
}

}  // namespace

TEST_CASE("surface vertices are numbered as the faces first meet them, normals summed in triangle order", "[render]") {
  World w = torn_sheet(12, 9, 3, 1.0f);
  split_off(w, [](int i, int j, int k) { return k == 2 && i < 4 && j < 5; });
  split_off(w, [](int, int j, int) { return j >= 6; });
  // Jitter every node, so that normals are sums of many different terms and a change in the
  // order of the additions would show in the last bits.
  std::uint32_t state = 12345;
  auto jitter = [&] {
    state = state * 1664525u + 1013904223u;
    return float(state >> 8) / float(1u << 24) * 0.2f - 0.1f;
  };
  for (std::size_t n = 0; n < w.nodes.count; ++n) {
    w.nodes.px[n] += jitter();
    w.nodes.py[n] += jitter();
    w.nodes.pz[n] += jitter();
  }
  const SurfaceMesh expected = weld_serially(w);
  for (int threads : {1, 2, 3}) {
    SurfaceMesh m;
    tbb::task_arena(threads).execute([&] { m = build_surface_mesh(w, {.fray = false}); });
    INFO(threads << " threads");
    CHECK(m.position == expected.position);
    CHECK(m.normal == expected.normal);
    CHECK(m.node == expected.node);
    CHECK(m.triangles == expected.triangles);
  }
}

TEST_CASE("the ray tracer's quads are the mesh's triangles in pairs, hits mapped back", "[render]") {
  const SurfaceMesh mesh = build_surface_mesh(torn_sheet(8, 6, 3, 1.0f), {.fray = true});
  std::vector<std::uint32_t> tris(mesh.triangle_count());
  for (std::uint32_t t = 0; t < tris.size(); ++t) tris[t] = t;
  tris.push_back(0);  // an odd one out at the end stays a single triangle
  const std::vector<TracedQuad> quads = pair_triangles(mesh, tris);
  CHECK(quads.size() == (tris.size() + 1) / 2);  // faces and fibre teeth all pair up
  std::vector<int> seen(mesh.triangle_count(), 0);
  auto point = [&](std::uint32_t v) { return mesh.position[v]; };
  for (const TracedQuad& q : quads) {
    seen[q.triangle[0]]++;
    if (q.pairing != TracedQuad::Pairing::single) seen[q.triangle[1]]++;
    // Embree's quad coordinates: (q0 q1 q3) below the diagonal u + v = 1, (q2 q3 q1) above.
    for (const auto [u, v] : {std::array<float, 2>{0.2f, 0.3f}, {0.7f, 0.1f}, {0.6f, 0.8f}, {0.9f, 0.5f}}) {
      if (q.pairing == TracedQuad::Pairing::single && u + v > 1.0f) continue;
      std::array<float, 3> expected{}, got{};
      const TrianglePoint h = on_triangle(q, u, v);
      const auto& t = mesh.triangles[h.triangle];
      for (std::size_t c = 0; c < 3; ++c) {
        expected[c] = u + v <= 1.0f
                          ? (1 - u - v) * point(q.vertex[0])[c] + u * point(q.vertex[1])[c] + v * point(q.vertex[3])[c]
                          : (u + v - 1) * point(q.vertex[2])[c] + (1 - u) * point(q.vertex[3])[c] + (1 - v) * point(q.vertex[1])[c];
        got[c] = (1 - h.u - h.v) * point(t[0])[c] + h.u * point(t[1])[c] + h.v * point(t[2])[c];
        CHECK(got[c] == Approx(expected[c]).margin(1e-5));
      }
      CHECK(h.triangle == q.triangle[u + v <= 1.0f ? 0 : 1]);
    }
  }
  seen[0]--;  // listed twice
  CHECK(std::all_of(seen.begin(), seen.end(), [](int n) { return n == 1; }));
  for (const auto kind : {TracedQuad::Pairing::single, TracedQuad::Pairing::shared_ends, TracedQuad::Pairing::shared_first})
    CHECK(std::any_of(quads.begin(), quads.end(), [&](const TracedQuad& q) { return q.pairing == kind; }));
}

TEST_CASE("a peeled skin is translucent by its thickness", "[render]") {
  const int nx = 6, ny = 4, nl = 4;
  World w = make_sheet(nx, ny, nl);
  // Lift the top layer off the sheet over i < 2, and the top two layers over i >= 4.
  split_off(w, [&](int i, int, int k) { return (i < 2 && k == nl - 1) || (i >= 4 && k >= nl - 2); });
  const float a = 0.6f;
  const std::vector<float> opacity = cell_opacity(w, a);
  for (std::uint32_t c = 0; c < w.topo.dims.cells(); ++c) {
    const auto ijk = w.topo.dims.cell_ijk(c);
    const int i = ijk[0], k = ijk[2];
    float expected = 1.0f;
    if (i < 2 && k == nl - 1) expected = a;
    if (i >= 4 && k >= nl - 2) expected = 1.0f - (1.0f - a) * (1.0f - a);
    INFO("cell " << i << "," << ijk[1] << "," << k);
    CHECK(opacity[c] == Approx(expected));
  }
  const auto faces = open_faces(w);
  CHECK(count_kind(faces, FaceKind::Separated) == std::size_t(2 * (2 * ny + 2 * ny)));
  const SurfaceMesh mesh = build_surface_mesh(w, {.fray = false, .fray_length = 0.0f, .layer_opacity = a});
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) CHECK(mesh.opacity[t] == opacity[mesh.cell[t]]);
}

TEST_CASE("the built-in print looks like printed matter", "[render]") {
  const Image print = default_print(256);
  REQUIRE(print.width == 256);
  std::set<std::uint32_t> colours;
  std::size_t dark = 0;
  for (int y = 0; y < print.height; ++y)
    for (int x = 0; x < print.width; ++x) {
      const std::uint8_t* p = print.pixel(x, y);
      colours.insert(std::uint32_t(p[0]) << 16 | std::uint32_t(p[1]) << 8 | p[2]);
      dark += p[0] < 80 && p[1] < 80 && p[2] < 80;
    }
  CHECK(colours.size() > 8);  // several inks
  CHECK(dark > 1000);         // lines of text-like marks
  CHECK(default_print(256).rgb == print.rgb);
}

TEST_CASE("a frame has the requested size and shows the sheet over the background", "[render]") {
  const World w = make_sheet(20, 12, 3);
  Renderer renderer(small_frame(160, 96));
  const Image frame = renderer.draw(w, renderer.camera_for(w));
  const std::vector<std::uint8_t> png = encode_png(frame);
  const Image back = decode_png(png);
  CHECK(back.width == 160);
  CHECK(back.height == 96);
  CHECK(back.rgb == frame.rgb);
  std::set<std::uint32_t> colours;
  for (int i = 0; i < frame.width * frame.height; ++i) {
    const std::uint8_t* p = frame.rgb.data() + 3 * i;
    colours.insert(std::uint32_t(p[0]) << 16 | std::uint32_t(p[1]) << 8 | p[2]);
  }
  CHECK(colours.size() > 50);
  // The default view frames the sheet with a margin: the corners are background, and the
  // sheet covers a good part of the frame.
  const auto& bg = renderer.settings().background;
  auto is_bg = [&](const std::uint8_t* p) {
    for (int c = 0; c < 3; ++c)
      if (std::abs(int(p[c]) - int(std::lround(255 * bg[std::size_t(c)]))) > 2) return false;
    return true;
  };
  CHECK(is_bg(frame.pixel(0, 0)));
  CHECK(is_bg(frame.pixel(159, 95)));
  int sheet_pixels = 0;
  for (int y = 0; y < frame.height; ++y)
    for (int x = 0; x < frame.width; ++x) sheet_pixels += !is_bg(frame.pixel(x, y));
  CHECK(sheet_pixels > frame.width * frame.height / 5);
}

// The ray tracer leaves rays whose pixels cannot see the sheet's bounding box out of its
// query; a lane left out must read as a miss whatever Embree wrote into it (it once drew a
// phantom line of paper along the culled rectangle's edge).
TEST_CASE("nothing is drawn outside the sheet's image", "[render]") {
  const World w = make_sheet(40, 24, 3);
  RenderSettings s = small_frame(320, 192);
  s.samples = 1;
  s.fray = false;
  Renderer renderer(s);
  const Camera camera = renderer.camera_for(w);
  const Image frame = renderer.draw(w, camera);
  // The image of the sheet's box (the nodes' extent and half a cell more), in pixels.
  std::array<float, 3> lo, hi;
  lo.fill(std::numeric_limits<float>::max());
  hi.fill(-std::numeric_limits<float>::max());
  for (std::size_t n = 0; n < w.nodes.count; ++n) {
    const std::array<float, 3> p{w.nodes.px[n], w.nodes.py[n], w.nodes.pz[n]};
    for (std::size_t k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k] - 0.5f), hi[k] = std::max(hi[k], p[k] + 0.5f);
  }
  const auto dot = [](const std::array<float, 3>& a, const std::array<float, 3>& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  };
  float left = 1e9f, right = -1e9f, top = 1e9f, bottom = -1e9f;
  for (int c = 0; c < 8; ++c) {
    const std::array<float, 3> d{(c & 1 ? hi[0] : lo[0]) - camera.position[0], (c & 2 ? hi[1] : lo[1]) - camera.position[1],
                                 (c & 4 ? hi[2] : lo[2]) - camera.position[2]};
    const float depth = dot(d, camera.forward);
    const float x = 0.5f * float(s.width) * (dot(d, camera.right) / (depth * camera.tan_half_fov_y * camera.aspect) + 1.0f);
    const float y = 0.5f * float(s.height) * (1.0f - dot(d, camera.up) / (depth * camera.tan_half_fov_y));
    left = std::min(left, x), right = std::max(right, x), top = std::min(top, y), bottom = std::max(bottom, y);
  }
  const auto& bg = renderer.settings().background;
  int drawn_outside = 0, drawn_inside = 0;
  for (int y = 0; y < frame.height; ++y)
    for (int x = 0; x < frame.width; ++x) {
      const std::uint8_t* p = frame.pixel(x, y);
      bool background = true;
      for (int c = 0; c < 3; ++c)
        background = background && std::abs(int(p[c]) - int(std::lround(255 * bg[std::size_t(c)]))) <= 2;
      const bool outside = x < left - 1 || x > right + 1 || y < top - 1 || y > bottom + 1;
      (outside ? drawn_outside : drawn_inside) += !background;
    }
  CHECK(drawn_inside > frame.width * frame.height / 5);
  CHECK(drawn_outside == 0);
}

TEST_CASE("the gap of a torn sheet shows the background", "[render]") {
  const int nx = 20, ny = 10, nl = 3;
  const float gap = 3.0f;
  const World w = torn_sheet(nx, ny, nl, gap);
  RenderSettings s = small_frame(120, 80);
  s.samples = 1;
  s.background = {0.2, 0.6, 0.3};
  // Straight down onto the middle of the gap; the image's up is the sheet's +y.
  const double gap_centre = nx / 2 + gap / 2;
  s.camera.position = Vec3d{gap_centre, ny / 2.0, 60.0};
  s.camera.target = Vec3d{gap_centre, ny / 2.0, 0.0};
  s.camera.up = {0.0, 1.0, 0.0};
  s.camera.fov = 20.0;
  Renderer renderer(s);
  const Image frame = renderer.draw(w, renderer.camera_for(w));
  auto near_bg = [&](const std::uint8_t* p) {
    return std::abs(int(p[0]) - 51) <= 2 && std::abs(int(p[1]) - 153) <= 2 && std::abs(int(p[2]) - 77) <= 2;
  };
  // The fibres reach at most fray_length * 1.5 + lean into a gap three cells wide: the
  // middle column of the image is background from top to bottom of the sheet.
  // (3.8 pixels per cell: rows 25..55 lie over y = 1..9.)
  for (int y = 25; y <= 55; y += 5) {
    INFO("row " << y);
    CHECK(near_bg(frame.pixel(60, y)));
  }
  // About 8 cells to each side of the gap's middle is paper.
  CHECK_FALSE(near_bg(frame.pixel(30, 40)));
  CHECK_FALSE(near_bg(frame.pixel(90, 40)));
}

TEST_CASE("frayed fibres are drawn whichever side the camera looks from", "[render]") {
  // The ray tracer leaves fibre sides turned away from both the eye and the light out of
  // its scenes: from below the sheet other sides must show. A gap one cell wide, seen
  // straight down and straight up: the fibres reaching into it cover background pixels.
  const int nx = 20, ny = 10, nl = 3;
  const float gap = 1.0f;
  const World w = torn_sheet(nx, ny, nl, gap);
  const double gap_centre = nx / 2 + gap / 2;
  auto background_pixels = [&](bool fray, double z) {
    RenderSettings s = small_frame(160, 96);
    s.samples = 1;
    s.fray = fray;
    s.background = {0.2, 0.6, 0.3};
    s.camera.position = Vec3d{gap_centre, ny / 2.0, z};
    s.camera.target = Vec3d{gap_centre, ny / 2.0, nl / 2.0};
    s.camera.up = {0.0, 1.0, 0.0};
    s.camera.fov = 12.0;
    Renderer renderer(s);
    const Image frame = renderer.draw(w, renderer.camera_for(w));
    int count = 0;
    for (int y = 0; y < frame.height; ++y)
      for (int x = 0; x < frame.width; ++x) {
        const std::uint8_t* p = frame.pixel(x, y);
        count += std::abs(int(p[0]) - 51) <= 2 && std::abs(int(p[1]) - 153) <= 2 && std::abs(int(p[2]) - 77) <= 2;
      }
    return count;
  };
  for (double z : {60.0, -57.0}) {
    INFO("camera at z = " << z);
    const int bare = background_pixels(false, z), frayed = background_pixels(true, z);
    CHECK(bare > 0);
    CHECK(frayed < bare - 100);
  }
}

namespace {

// A torn sheet with a corner of its top layer split off and lifted, so that translucency
// and shadows are exercised too.
World torn_sheet_with_lifted_corner() {
  World w = torn_sheet(16, 10, 3, 1.0f);
  split_off(w, [&](int i, int j, int k) { return i < 4 && j < 4 && k == 2; });
  for (std::uint32_t c = 0; c < w.topo.dims.cells(); ++c) {
    const auto ijk = w.topo.dims.cell_ijk(c);
    if (ijk[0] < 4 && ijk[1] < 4 && ijk[2] == 2)
      for (int q = 0; q < 8; ++q) w.nodes.pz[w.topo.node(c, q)] = float(ijk[2] + (q >> 2)) + 0.8f;
  }
  return w;
}

}  // namespace

TEST_CASE("the same state renders to the same bytes", "[render]") {
  const World w = torn_sheet_with_lifted_corner();
  Renderer renderer(small_frame(128, 80));
  const Camera cam = renderer.camera_for(w);
  const std::vector<std::uint8_t> a = encode_png(renderer.draw(w, cam));
  const std::vector<std::uint8_t> b = encode_png(renderer.draw(w, cam));
  CHECK(a == b);
  Renderer again(small_frame(128, 80));
  CHECK(encode_png(again.draw(w, cam)) == a);
  // Tiles are shared out differently on other thread counts; the pixels are not.
  for (int threads : {1, 2, 3}) {
    std::vector<std::uint8_t> c;
    tbb::task_arena(threads).execute([&] { c = encode_png(renderer.draw(w, cam)); });
    INFO(threads << " threads");
    CHECK(c == a);
  }
}

TEST_CASE("a renderer's buffers kept from frame to frame do not change a frame", "[render]") {
  // A renderer keeps its mesh, scenes and pass buffers for the next draw(): frames of other
  // states in between (more and fewer triangles, no skins, nothing torn) leave A's bytes as a
  // fresh renderer draws them, on any number of threads.
  const World a = torn_sheet_with_lifted_corner();
  const World b = torn_sheet(24, 14, 3, 0.6f);
  const World plain = make_sheet(10, 8, 2);
  Renderer fresh(small_frame(128, 80));
  const Camera cam = fresh.camera_for(a);
  const std::vector<std::uint8_t> a_fresh = encode_png(fresh.draw(a, cam));
  const std::vector<std::uint8_t> b_fresh = encode_png(Renderer(small_frame(128, 80)).draw(b, cam));
  Renderer kept(small_frame(128, 80));
  CHECK(encode_png(kept.draw(b, cam)) == b_fresh);
  CHECK(encode_png(kept.draw(a, cam)) == a_fresh);
  CHECK(encode_png(kept.draw(plain, cam)) == encode_png(Renderer(small_frame(128, 80)).draw(plain, cam)));
  CHECK(encode_png(kept.draw(b, cam)) == b_fresh);
  CHECK(encode_png(kept.draw(build_surface_mesh(a, kept.mesh_options()), cam)) == a_fresh);
  // Embree reads the mesh's positions in place when a spare element follows them, else a
  // padded copy: the same frame either way.
  SurfaceMesh tight = build_surface_mesh(a, kept.mesh_options());
  REQUIRE(tight.position.capacity() > tight.position.size());
  tight.position.shrink_to_fit();
  if (tight.position.capacity() == tight.position.size()) CHECK(encode_png(kept.draw(tight, cam)) == a_fresh);
  for (int threads : {1, 2, 3, 16}) {
    std::vector<std::uint8_t> c, d;
    tbb::task_arena(threads).execute([&] {
      c = encode_png(kept.draw(a, cam));
      d = encode_png(kept.draw(b, cam));
    });
    INFO(threads << " threads");
    CHECK(c == a_fresh);
    CHECK(d == b_fresh);
  }
}

TEST_CASE("one renderer draws from several threads at once", "[render]") {
  // The calls that find the kept buffers in use draw with their own: the same bytes.
  const World a = torn_sheet(16, 10, 3, 1.0f);
  Renderer renderer(small_frame(96, 64));
  const Camera cam = renderer.camera_for(a);
  const std::vector<std::uint8_t> once = encode_png(renderer.draw(a, cam));
  std::vector<std::vector<std::uint8_t>> frames(4);
  std::vector<std::thread> threads;
  for (auto& f : frames) threads.emplace_back([&] { f = encode_png(renderer.draw(a, cam)); });
  for (auto& t : threads) t.join();
  for (const auto& f : frames) CHECK(f == once);
}

TEST_CASE("the default camera keeps the whole sheet in the frame", "[render]") {
  const World w = make_sheet(30, 20, 5);
  const Bounds b = sheet_bounds(w);
  CHECK(b.hi[0] == 30.0f);
  CHECK(b.hi[2] == 5.0f);
  const Camera cam = make_camera(CameraSettings{}, b, 1280, 720);
  for (int corner = 0; corner < 8; ++corner) {
    const float p[3] = {corner & 1 ? b.hi[0] : b.lo[0], corner & 2 ? b.hi[1] : b.lo[1], corner & 4 ? b.hi[2] : b.lo[2]};
    float r[3];
    for (int c = 0; c < 3; ++c) r[c] = p[c] - cam.position[std::size_t(c)];
    auto dot = [&](const Vec3f& a) { return r[0] * a[0] + r[1] * a[1] + r[2] * a[2]; };
    const float depth = dot(cam.forward);
    REQUIRE(depth > 0.0f);
    CHECK(std::abs(dot(cam.right) / depth) <= cam.tan_half_fov_y * cam.aspect);
    CHECK(std::abs(dot(cam.up) / depth) <= cam.tan_half_fov_y);
  }
  CHECK(cam.position[2] > b.hi[2]);  // from above
}

TEST_CASE("render settings are read from the scene's tables", "[render]") {
  const toml::table doc = toml::parse(R"(
    [render]
    width = 640
    height = 360
    background = "#102030"
    samples = 3
    [camera]
    fov = 50
    target = [1, 2, 3]
    [light]
    direction = [0, 0, -1]
    [print]
    image = "art/poster.png"
  )");
  const RenderSettings s = parse_render_settings(doc, "/scenes");
  CHECK(s.width == 640);
  CHECK(s.height == 360);
  CHECK(s.samples == 3);
  CHECK(s.background[0] == Approx(16.0 / 255.0));
  CHECK(s.camera.fov == 50.0);
  CHECK_FALSE(s.camera.position.has_value());
  CHECK((*s.camera.target)[2] == 3.0);
  CHECK(s.print.image == std::filesystem::path("/scenes/art/poster.png"));
}

TEST_CASE("bad render settings are named", "[render]") {
  auto error_of = [](const char* text) -> std::string {
    try {
      parse_render_settings(toml::parse(text));
    } catch (const SceneError& e) {
      return e.what();
    }
    return "";
  };
  CHECK_THAT(error_of("[render]\nwidht = 3"), Catch::Contains("render.widht") && Catch::Contains("render.width"));
  CHECK_THAT(error_of("[render]\nwidth = \"big\""), Catch::Contains("render.width"));
  CHECK_THAT(error_of("[render]\nbackground = \"blue\""), Catch::Contains("render.background"));
  CHECK_THAT(error_of("[render]\nsamples = 0"), Catch::Contains("render.samples"));
  CHECK_THAT(error_of("[camera]\nposition = [1, 2]"), Catch::Contains("camera.position"));
  CHECK_THAT(error_of("[light]\ndirection = [0, 0, 0]"), Catch::Contains("light.direction"));
  CHECK_THAT(error_of("[print]\nimage = 3"), Catch::Contains("print.image"));
  CHECK(error_of("[render]\nwidth = 10") == "");
}

TEST_CASE("a print image that cannot be read is reported by name", "[render]") {
  RenderSettings s = small_frame(8, 8);
  s.print.image = "/nonexistent/poster.png";
  CHECK_THROWS_WITH(Renderer(s), Catch::Contains("print.image") && Catch::Contains("/nonexistent/poster.png"));
}

TEST_CASE("the pierce scene's indenter is drawn where it is: closed and facing out", "[render]") {
  Scene scene;
  scene.sheet.cells = {20, 20, 3};
  World w;
  build_lattice(scene, w);
  SurfaceMesh sheet = build_surface_mesh(w);
  const std::size_t sheet_vertices = sheet.vertex_count(), sheet_triangles = sheet.triangle_count();
  append_indenter(w, sheet);  // a pull: nothing to draw
  CHECK(sheet.vertex_count() == sheet_vertices);
  CHECK(sheet.triangle_count() == sheet_triangles);

  for (const char* shape : {"cone", "sphere"}) {
    INFO(shape);
    scene.load.kind = "pierce";
    scene.load.indenter = shape;
    World p;
    build_lattice(scene, p);
    p.time = 40.0;
    SurfaceMesh mesh = build_surface_mesh(p);
    const std::size_t first_vertex = mesh.vertex_count(), first_triangle = mesh.triangle_count();
    append_indenter(p, mesh);
    REQUIRE(mesh.triangle_count() > first_triangle);
    const Indenter ind = *make_indenter(p);
    const IndenterPose pose = indenter_pose(ind, p.time);
    // The lowest point is the bottom of the tip ball.
    float lowest = std::numeric_limits<float>::max();
    for (std::size_t v = first_vertex; v < mesh.vertex_count(); ++v) lowest = std::min(lowest, mesh.position[v][2]);
    CHECK(lowest == Approx(pose.cz - ind.radius).margin(1e-4));
    // Closed: every edge (by position) is shared by two of its triangles, in opposite
    // directions; outward: each triangle faces away from the axis point at its height, or
    // from the ball's centre below it, or up on the flat top.
    std::map<std::array<float, 6>, int> edges;
    int inward = 0;
    for (std::size_t t = first_triangle; t < mesh.triangle_count(); ++t) {
      const auto& tri = mesh.triangles[t];
      std::array<std::array<float, 3>, 3> q{mesh.position[tri[0]], mesh.position[tri[1]], mesh.position[tri[2]]};
      for (int e = 0; e < 3; ++e) {
        const auto& a = q[std::size_t(e)];
        const auto& b = q[std::size_t((e + 1) % 3)];
        edges[{a[0], a[1], a[2], b[0], b[1], b[2]}] += 1;
        edges[{b[0], b[1], b[2], a[0], a[1], a[2]}] -= 1;
      }
      const std::array<float, 3> e1{q[1][0] - q[0][0], q[1][1] - q[0][1], q[1][2] - q[0][2]};
      const std::array<float, 3> e2{q[2][0] - q[0][0], q[2][1] - q[0][1], q[2][2] - q[0][2]};
      const std::array<float, 3> n{e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
      const float cz = (q[0][2] + q[1][2] + q[2][2]) / 3.0f;
      const std::array<float, 3> from{(q[0][0] + q[1][0] + q[2][0]) / 3.0f - pose.cx,
                                      (q[0][1] + q[1][1] + q[2][1]) / 3.0f - pose.cy, std::min(0.0f, cz - pose.cz)};
      const float facing = n[0] * from[0] + n[1] * from[1] + n[2] * from[2];
      const bool flat_top = n[0] == 0.0f && n[1] == 0.0f;
      inward += flat_top ? n[2] < 0.0f : facing < 0.0f;
    }
    CHECK(inward == 0);
    int open = 0;
    for (const auto& [edge, balance] : edges) open += balance != 0;
    CHECK(open == 0);
  }
}
