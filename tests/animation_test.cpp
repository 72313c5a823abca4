// The animated .glb of a run (tools/render/animation.hpp), read back with TinyGLTF and
// played frame by frame against the per-frame .glb exports of the same run.
#include <catch2/catch.hpp>

#include <tiny_gltf.h>
#include <toml++/toml.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <vector>

#include "core/simulation.hpp"
#include "tools/render/frame_sinks.hpp"
#include "tools/render/gltf_frame.hpp"
#include "tools/run_frames.hpp"
#include "tests/gltf_files.hpp"
#include "tests/test_files.hpp"

using namespace papertear;
namespace fs = std::filesystem;
using papertear::testing::load_glb;
using papertear::testing::read_floats;

namespace {

using Point = std::array<double, 3>;

// Vertices of the mesh "sheet" (not the fibres, which are a mesh of their own) by their
// original node, with their positions, and the frame node ids.
struct SheetVertices {
  std::multimap<std::uint32_t, Point> by_original;
  std::set<std::uint32_t> nodes;
};

SheetVertices sheet_vertices(const tinygltf::Model& m, const std::vector<float>& pos) {
  const auto& prim0 = m.meshes.at(0).primitives.at(0);
  const std::vector<float> original = read_floats(m, prim0.attributes.at("_ORIGINAL_NODE"));
  const std::vector<float> node = read_floats(m, prim0.attributes.at("_NODE"));
  std::set<std::uint32_t> used;
  for (const auto& p : m.meshes[0].primitives) {
    const tinygltf::Accessor& a = m.accessors[std::size_t(p.indices)];
    const tinygltf::BufferView& v = m.bufferViews[std::size_t(a.bufferView)];
    const auto* idx = reinterpret_cast<const std::uint32_t*>(m.buffers[0].data.data() + v.byteOffset);
    used.insert(idx, idx + a.count);
  }
  SheetVertices out;
  for (std::uint32_t v : used) {
    out.by_original.emplace(std::uint32_t(original[v]), Point{pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]});
    out.nodes.insert(std::uint32_t(node[v]));
  }
  return out;
}

// True when some vertex of `b` at original node `o` lies within `tol` of `p`.
bool has_match(const SheetVertices& b, std::uint32_t o, const Point& p, double tol) {
  const auto [lo, hi] = b.by_original.equal_range(o);
  for (auto it = lo; it != hi; ++it)
    if (std::abs(it->second[0] - p[0]) <= tol && std::abs(it->second[1] - p[1]) <= tol &&
        std::abs(it->second[2] - p[2]) <= tol)
      return true;
  return false;
}

// Every vertex of `a` has a counterpart at the same original node in `b`; the count of those
// that do not.
std::size_t unmatched(const SheetVertices& a, const SheetVertices& b, double tol) {
  std::size_t missing = 0;
  for (const auto& [o, p] : a.by_original) missing += has_match(b, o, p, tol) ? 0 : 1;
  return missing;
}

// Every node of every frame in glTF's frame, by its lattice vertex (= original node id): the
// nodes inside the sheet too, which a frame's surface mesh does not show.
struct NodeRecorder final : io::FrameSink {
  std::vector<SheetVertices> frames;
  void on_frame(const Simulation& sim, int, int, const Metrics&) override {
    const World& w = sim.world();
    SheetVertices f;
    for (std::size_t n = 0; n < w.nodes.count; ++n) {
      const auto g = render::to_gltf_position({w.nodes.px[n], w.nodes.py[n], w.nodes.pz[n]});
      f.by_original.emplace(w.nodes.vertex[n], Point{g[0], g[1], g[2]});
      f.nodes.insert(std::uint32_t(n));
    }
    frames.push_back(std::move(f));
  }
};

// Positions at frame k of the animated model: base + target k - 1 (one-hot weights).
std::vector<float> animated_positions(const tinygltf::Model& m, std::size_t k) {
  const auto& prim = m.meshes[0].primitives[0];
  std::vector<float> pos = read_floats(m, prim.attributes.at("POSITION"));
  if (k == 0) return pos;
  const std::vector<float> delta = read_floats(m, prim.targets.at(k - 1).at("POSITION"));
  for (std::size_t i = 0; i < pos.size(); ++i) pos[i] += delta[i];
  return pos;
}

}  // namespace

TEST_CASE("animation.glb places the sheet at every frame where that frame's own .glb does", "[export][glb]") {
  Scene scene;  // the default pull, small: it tears in two during the run
  scene.sheet.cells = {30, 20, 3};
  scene.run.steps = 300;
  scene.run.frames = 6;
  Simulation sim(scene, {.threads = 2});
  const fs::path dir = testing::fresh_test_dir("animation", "frames");
  auto sinks = render::make_render_sinks(toml::parse("[output]\npng = false\nmesh = \"glb\"\nmesh_frames = \"all\"\n"
                                                     "video = false\nvideo_fps = 12\n"),
                                         {}, dir);
  NodeRecorder nodes;
  std::vector<io::FrameSink*> ptrs = {&nodes};
  for (auto& s : sinks) ptrs.push_back(s.get());
  io::run_frames(sim, ptrs, nullptr);

  const tinygltf::Model anim = load_glb(dir / "animation.glb");
  REQUIRE(anim.meshes.size() == 1);  // the sheet; the fibres are left out of the animation
  REQUIRE(anim.meshes[0].primitives[0].targets.size() == 5);
  REQUIRE(anim.animations.size() == 1);
  CHECK(anim.asset.extras.Get("fps").GetNumberAsInt() == 12);
  CHECK(anim.asset.extras.Get("frame_count").GetNumberAsInt() == 6);
  const std::vector<float> times = read_floats(anim, anim.animations[0].samplers[0].input);
  CHECK(times.back() == Approx(5.0 / 12));
  // A point is matched to a few float roundings (base + displacement); the sheet is 30 mm =
  // 0.03 m wide, and an opened crack's sides are thousands of times further apart.
  const double tol = 1e-8;
  std::set<std::uint32_t> first_nodes, animated_nodes;
  std::vector<float> previous_nodes;
  bool saw_steady_pair = false;
  for (std::size_t k = 0; k < 6; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%04zu.glb", k);
    const tinygltf::Model frame = load_glb(dir / "mesh" / name);
    const auto& prim = frame.meshes[0].primitives[0];
    const SheetVertices own = sheet_vertices(frame, read_floats(frame, prim.attributes.at("POSITION")));
    const SheetVertices played = sheet_vertices(anim, animated_positions(anim, k));
    INFO("frame " << k);
    CHECK(frame.asset.extras.Get("frame").GetNumberAsInt() == int(k));
    CHECK(unmatched(own, played, tol) == 0);  // the frame's whole surface is played
    // Each played vertex sits on a node of that frame at its lattice vertex (its ancestor):
    // on the frame's surface where that vertex is on it, else on a node inside the sheet
    // (a crack still closed), hidden.
    CHECK(unmatched(played, nodes.frames.at(k), tol) == 0);
    SheetVertices on_surface;
    for (const auto& [o, p] : played.by_original)
      if (own.by_original.count(o)) on_surface.by_original.emplace(o, p);
    CHECK(unmatched(on_surface, own, tol) == 0);
    CHECK(on_surface.by_original.size() > played.by_original.size() / 2);
    if (k == 0) first_nodes = own.nodes;
    // Between splits the sheet's vertex list stays as it was (the fibres are apart).
    const std::vector<float> node_list = read_floats(frame, prim.attributes.at("_NODE"));
    if (k > 0 && std::set<float>(node_list.begin(), node_list.end()) ==
                     std::set<float>(previous_nodes.begin(), previous_nodes.end())) {
      CHECK(node_list == previous_nodes);
      saw_steady_pair = true;
    }
    previous_nodes = node_list;
    if (k == 5) CHECK(own.nodes == played.nodes);  // the final topology, node for node
    animated_nodes = played.nodes;
  }
  CHECK(saw_steady_pair);
  // Nodes split during the run, so early frames place nodes that did not exist yet.
  CHECK(first_nodes.size() < animated_nodes.size());
}

TEST_CASE("output.animation = false writes no animation.glb", "[export][glb]") {
  Scene scene;
  scene.sheet.cells = {12, 8, 1};
  scene.run.steps = 4;
  scene.run.frames = 2;
  Simulation sim(scene, {.threads = 1});
  const fs::path dir = testing::fresh_test_dir("animation", "off");
  auto sinks = render::make_render_sinks(toml::parse("[output]\npng = false\nmesh = \"glb\"\nanimation = false\n"),
                                         {}, dir);
  std::vector<io::FrameSink*> ptrs;
  for (auto& s : sinks) ptrs.push_back(s.get());
  io::run_frames(sim, ptrs, nullptr);
  CHECK(fs::exists(dir / "mesh" / "frame_0001.glb"));
  CHECK_FALSE(fs::exists(dir / "animation.glb"));
}
