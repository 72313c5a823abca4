#include "tools/render/animation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include "core/lattice.hpp"
#include "tools/render/gltf_builder.hpp"

namespace papertear::render {

namespace {

using Vec3f = std::array<float, 3>;

// For every node of the final topology one (cell, corner) slot that uses it: the slot
// through which each frame's table names the node's ancestor.
std::vector<std::uint32_t> slot_of_node(const World& w) {
  std::vector<std::uint32_t> slot(w.nodes.count, UINT32_MAX);
  for (std::size_t s = w.topo.cell_nodes.size(); s-- > 0;) slot[w.topo.cell_nodes[s]] = std::uint32_t(s);
  return slot;
}

// Area-weighted vertex normals of the fixed topology at one frame's positions (in glTF's
// frame, which is a rotation and uniform scale of the simulation's, so the same normals).
std::vector<Vec3f> vertex_normals(const SurfaceMesh& mesh, const std::vector<Vec3f>& p) {
  std::vector<Vec3f> n(p.size(), Vec3f{0, 0, 0});
  for (const auto& t : mesh.triangles) {
    const Vec3f &a = p[t[0]], &b = p[t[1]], &c = p[t[2]];
    const float ux = b[0] - a[0], uy = b[1] - a[1], uz = b[2] - a[2];
    const float vx = c[0] - a[0], vy = c[1] - a[1], vz = c[2] - a[2];
    const Vec3f cr{uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx};
    for (std::uint32_t v : t)
      for (int k = 0; k < 3; ++k) n[v][std::size_t(k)] += cr[std::size_t(k)];
  }
  for (Vec3f& v : n) {
    const float len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    // A vertex whose faces have no area yet (a closed crack seen edge on) gets any unit
    // normal: it is hidden, and glTF requires unit normals.
    v = len > 0 ? Vec3f{v[0] / len, v[1] / len, v[2] / len} : Vec3f{0, 1, 0};
  }
  return n;
}

std::vector<float> flat(const std::vector<Vec3f>& v) {
  std::vector<float> out;
  out.reserve(3 * v.size());
  for (const Vec3f& a : v) out.insert(out.end(), a.begin(), a.end());
  return out;
}

std::vector<float> difference(const std::vector<Vec3f>& a, const std::vector<Vec3f>& base) {
  std::vector<float> out;
  out.reserve(3 * a.size());
  for (std::size_t i = 0; i < a.size(); ++i)
    for (int k = 0; k < 3; ++k) out.push_back(a[i][std::size_t(k)] - base[i][std::size_t(k)]);
  return out;
}

tinygltf::Value::Object animation_extras(const std::vector<FrameInfo>& frames) {
  tinygltf::Value::Object extras = frame_extras(frames.back());  // the last frame's record
  tinygltf::Value::Array list;
  for (const FrameInfo& f : frames) list.emplace_back(frame_extras(f));
  extras["frames"] = tinygltf::Value(std::move(list));
  extras["frame_count"] = tinygltf::Value(int(frames.size()));
  return extras;
}

}  // namespace

void TearRecording::add_frame(const World& world, const FrameInfo& info) {
  Frame f;
  f.info = info;
  const std::size_t n = world.nodes.count;
  f.xyz.resize(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    f.xyz[3 * i] = world.nodes.px[i];
    f.xyz[3 * i + 1] = world.nodes.py[i];
    f.xyz[3 * i + 2] = world.nodes.pz[i];
  }
  const auto& table = world.topo.cell_nodes;
  if (!frames_.empty() && frames_.back().cell_nodes->size() == table.size() &&
      std::equal(table.begin(), table.end(), frames_.back().cell_nodes->begin()))
    f.cell_nodes = frames_.back().cell_nodes;
  else
    f.cell_nodes = std::make_shared<const std::vector<std::uint32_t>>(table.begin(), table.end());
  frames_.push_back(std::move(f));
}

std::size_t TearRecording::bytes() const {
  std::size_t total = 0;
  const std::vector<std::uint32_t>* last = nullptr;
  for (const Frame& f : frames_) {
    total += f.xyz.size() * sizeof(float);
    if (f.cell_nodes.get() != last) total += f.cell_nodes->size() * sizeof(std::uint32_t);
    last = f.cell_nodes.get();
  }
  return total;
}

namespace {

// The final mesh's vertices placed at one frame (glTF's frame): each at the node that its
// final node's cell corner used then.
std::vector<Vec3f> frame_positions(const SurfaceMesh& mesh, const std::vector<std::uint32_t>& slot,
                                   const std::vector<float>& xyz, const std::vector<std::uint32_t>& cell_nodes) {
  std::vector<Vec3f> p(mesh.vertex_count());
  for (std::size_t v = 0; v < p.size(); ++v) {
    const std::size_t node = cell_nodes[slot[mesh.node[v]]];
    p[v] = to_gltf_position({xyz[3 * node], xyz[3 * node + 1], xyz[3 * node + 2]});
  }
  return p;
}

// Keyframe k at k / fps; its weights the one-hot vector of frame k (frame 0: all zero).
void add_weights_animation(GltfBuilder& g, std::size_t frames, int fps) {
  const std::size_t targets = frames - 1;
  std::vector<float> times(frames), weights(frames * targets, 0.0f);
  for (std::size_t k = 0; k < frames; ++k) {
    times[k] = float(double(k) / fps);
    if (k > 0) weights[k * targets + (k - 1)] = 1.0f;
  }
  const int input = g.accessor(g.view(times, 0), TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_SCALAR, frames);
  g.model().accessors[std::size_t(input)].minValues = {double(times.front())};
  g.model().accessors[std::size_t(input)].maxValues = {double(times.back())};
  const int output = g.accessor(g.view(weights, 0), TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_SCALAR,
                                weights.size());
  tinygltf::Animation anim;
  anim.name = "tear";
  tinygltf::AnimationSampler sampler;
  sampler.input = input;
  sampler.output = output;
  sampler.interpolation = "LINEAR";
  anim.samplers.push_back(sampler);
  tinygltf::AnimationChannel channel;
  channel.sampler = 0;
  channel.target_node = 0;
  channel.target_path = "weights";
  anim.channels.push_back(channel);
  g.model().animations.push_back(anim);
}

}  // namespace

void TearRecording::write_glb(const World& final_world, const ExportOptions& options,
                              const std::filesystem::path& path) const {
  if (frames_.empty()) throw RenderError("no frames recorded for '" + path.string() + "'");
  // The sheet alone: fibres change in number from frame to frame (animation.hpp).
  const SurfaceMesh mesh = build_surface_mesh(final_world, {.fray = false});
  const std::vector<std::uint32_t> slot = slot_of_node(final_world);
  GltfBuilder g;
  std::map<std::string, int> attributes = print_and_node_attributes(g, mesh);
  const std::vector<Vec3f> base = frame_positions(mesh, slot, frames_[0].xyz, *frames_[0].cell_nodes);
  const std::vector<Vec3f> base_normal = vertex_normals(mesh, base);
  attributes["POSITION"] = g.vec3_accessor(flat(base), true);
  attributes["NORMAL"] = g.vec3_accessor(flat(base_normal), false);
  std::vector<std::map<std::string, int>> targets;
  tinygltf::Value::Array names;
  for (std::size_t k = 1; k < frames_.size(); ++k) {
    const std::vector<Vec3f> p = frame_positions(mesh, slot, frames_[k].xyz, *frames_[k].cell_nodes);
    targets.push_back({{"POSITION", g.vec3_accessor(difference(p, base), true)},
                       {"NORMAL", g.vec3_accessor(difference(vertex_normals(mesh, p), base_normal), false)}});
    char name[24];
    std::snprintf(name, sizeof name, "frame_%04d", frames_[k].info.frame);
    names.emplace_back(std::string(name));
  }
  g.add_materials({.print = options.print, .paper_color = options.paper_color});
  tinygltf::Mesh gm = primitives_by_material(g, mesh, attributes, "sheet");
  for (tinygltf::Primitive& p : gm.primitives) p.targets = targets;
  gm.weights.assign(targets.size(), 0.0);
  if (!targets.empty()) gm.extras = tinygltf::Value(tinygltf::Value::Object{{"targetNames", tinygltf::Value(names)}});
  g.model().meshes.push_back(gm);
  g.add_mesh_nodes();
  std::vector<FrameInfo> infos;
  for (const Frame& f : frames_) infos.push_back(f.info);
  if (frames_.size() > 1) add_weights_animation(g, frames_.size(), infos.back().fps);
  g.set_extras(animation_extras(infos));
  g.write(path);
}

}  // namespace papertear::render
