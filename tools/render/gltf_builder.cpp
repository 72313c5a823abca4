#include "tools/render/gltf_builder.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <unordered_map>
#include <map>
#include <sstream>

#include "tools/output_files.hpp"
#include "tools/render/surface.hpp"
#include "tools/summary.hpp"

namespace papertear::render {

namespace {

constexpr std::array<const char*, 3> kMaterialNames = {"print", "paper", "fibre"};
constexpr std::uint32_t kExactFloatIds = 1u << 24;

std::size_t index_of(Material m) { return m == Material::Print ? 0 : m == Material::Paper ? 1 : 2; }

double srgb_to_linear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }

}  // namespace

GltfBuilder::GltfBuilder() {
  model_.asset.version = "2.0";
  model_.asset.generator = "papertear";
  model_.buffers.emplace_back();
}

int GltfBuilder::view_bytes(const void* data, std::size_t bytes, int target) {
  auto& buf = model_.buffers[0].data;
  while (buf.size() % 4) buf.push_back(0);  // accessors need aligned offsets
  tinygltf::BufferView bv;
  bv.buffer = 0;
  bv.byteOffset = buf.size();
  bv.byteLength = bytes;
  bv.target = target;
  const auto* p = static_cast<const unsigned char*>(data);
  buf.insert(buf.end(), p, p + bytes);
  model_.bufferViews.push_back(bv);
  return int(model_.bufferViews.size() - 1);
}

int GltfBuilder::accessor(int view, int component, int type, std::size_t count) {
  tinygltf::Accessor a;
  a.bufferView = view;
  a.componentType = component;
  a.type = type;
  a.count = count;
  model_.accessors.push_back(a);
  return int(model_.accessors.size() - 1);
}

int GltfBuilder::vec3_accessor(const std::vector<float>& xyz, bool with_bounds) {
  const std::size_t n = xyz.size() / 3;
  const int a = accessor(view(xyz, TINYGLTF_TARGET_ARRAY_BUFFER), TINYGLTF_COMPONENT_TYPE_FLOAT,
                         TINYGLTF_TYPE_VEC3, n);
  if (!with_bounds) return a;
  std::vector<double> lo(3, 0.0), hi(3, 0.0);
  for (std::size_t c = 0; c < 3 && n > 0; ++c) {
    lo[c] = hi[c] = xyz[c];
    for (std::size_t v = 0; v < n; ++v) {
      lo[c] = std::min(lo[c], double(xyz[3 * v + c]));
      hi[c] = std::max(hi[c], double(xyz[3 * v + c]));
    }
  }
  model_.accessors[std::size_t(a)].minValues = lo;
  model_.accessors[std::size_t(a)].maxValues = hi;
  return a;
}

void GltfBuilder::add_materials(const MaterialOptions& o) {
  const std::vector<double> paper = {srgb_to_linear(o.paper_color[0]), srgb_to_linear(o.paper_color[1]),
                                     srgb_to_linear(o.paper_color[2]), 1.0};
  for (std::size_t i = 0; i < kMaterialNames.size(); ++i) {
    tinygltf::Material mat;
    mat.name = kMaterialNames[i];
    mat.pbrMetallicRoughness.baseColorFactor = i == 0 && o.print ? std::vector<double>{1.0, 1.0, 1.0, 1.0} : paper;
    mat.pbrMetallicRoughness.metallicFactor = 0.0;
    mat.pbrMetallicRoughness.roughnessFactor = 1.0;
    model_.materials.push_back(mat);
  }
  if (!o.print) return;
  const std::vector<std::uint8_t> png = encode_png(*o.print);
  tinygltf::Image image;
  image.name = "print";
  image.mimeType = "image/png";
  image.bufferView = view(png, 0);
  model_.images.push_back(image);
  tinygltf::Sampler sampler;
  sampler.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
  sampler.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;
  sampler.wrapS = sampler.wrapT = TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
  model_.samplers.push_back(sampler);
  tinygltf::Texture tex;
  tex.source = 0;
  tex.sampler = 0;
  model_.textures.push_back(tex);
  model_.materials[0].pbrMetallicRoughness.baseColorTexture.index = 0;
}

void GltfBuilder::set_extras(tinygltf::Value::Object extras) {
  extras["unit"] = tinygltf::Value(std::string("m"));
  extras["metres_per_unit"] = tinygltf::Value(kMetresPerUnit);
  extras["frame_convention"] = tinygltf::Value(std::string("y up; simulation (x, y, z) mm -> glTF (x, z, -y) m"));
  model_.asset.extras = tinygltf::Value(std::move(extras));
}

void GltfBuilder::add_mesh_nodes() {
  tinygltf::Scene scene;
  for (std::size_t i = 0; i < model_.meshes.size(); ++i) {
    tinygltf::Node node;
    node.mesh = int(i);
    node.name = model_.meshes[i].name;
    model_.nodes.push_back(node);
    scene.nodes.push_back(int(i));
  }
  model_.scenes.push_back(scene);
  model_.defaultScene = 0;
}

void GltfBuilder::write(const std::filesystem::path& path) {
  std::ostringstream out;
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&model_, out, false, true))
    throw RenderError("cannot encode '" + path.string() + "' as glTF");
  io::write_file_atomically(path, out.str());
}

std::array<std::vector<std::uint32_t>, 3> indices_by_material(const SurfaceMesh& mesh) {
  std::array<std::vector<std::uint32_t>, 3> out;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    auto& list = out[index_of(mesh.material[t])];
    list.insert(list.end(), mesh.triangles[t].begin(), mesh.triangles[t].end());
  }
  return out;
}

std::map<std::string, int> print_and_node_attributes(GltfBuilder& g, const SurfaceMesh& mesh, bool ids_uv) {
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
    if (mesh.node[v] >= kExactFloatIds || mesh.original_node[v] >= kExactFloatIds)
      throw RenderError("glTF export: node ids of 2^24 and above cannot be stored exactly as floats");
  const std::size_t n = mesh.vertex_count();
  std::map<std::string, int> attr;
  std::vector<float> uv;
  uv.reserve(2 * n);
  for (const auto& t : mesh.uv) uv.insert(uv.end(), t.begin(), t.end());
  attr["TEXCOORD_0"] = g.accessor(g.view(uv, TINYGLTF_TARGET_ARRAY_BUFFER), TINYGLTF_COMPONENT_TYPE_FLOAT,
                                  TINYGLTF_TYPE_VEC2, n);
  const std::vector<float> node(mesh.node.begin(), mesh.node.end());
  const std::vector<float> original(mesh.original_node.begin(), mesh.original_node.end());
  attr["_NODE"] = g.accessor(g.view(node, TINYGLTF_TARGET_ARRAY_BUFFER), TINYGLTF_COMPONENT_TYPE_FLOAT,
                             TINYGLTF_TYPE_SCALAR, n);
  attr["_ORIGINAL_NODE"] = g.accessor(g.view(original, TINYGLTF_TARGET_ARRAY_BUFFER),
                                      TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_SCALAR, n);
  if (!ids_uv) return attr;
  // The same ids again as a second UV map (node, original node): importers that drop
  // attributes of their own (Blender's) keep UV maps, and tools/blender/ turns it back.
  std::vector<float> ids(2 * n);
  for (std::size_t v = 0; v < n; ++v) ids[2 * v] = node[v], ids[2 * v + 1] = original[v];
  attr["TEXCOORD_1"] = g.accessor(g.view(ids, TINYGLTF_TARGET_ARRAY_BUFFER), TINYGLTF_COMPONENT_TYPE_FLOAT,
                                  TINYGLTF_TYPE_VEC2, n);
  return attr;
}

tinygltf::Mesh primitives_by_material(GltfBuilder& g, const SurfaceMesh& mesh,
                                      const std::map<std::string, int>& attributes, const std::string& name) {
  tinygltf::Mesh gm;
  gm.name = name;
  const auto groups = indices_by_material(mesh);
  for (std::size_t i = 0; i < groups.size(); ++i) {
    if (groups[i].empty()) continue;
    tinygltf::Primitive p;
    p.attributes = attributes;
    p.indices = g.accessor(g.view(groups[i], TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER),
                           TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, groups[i].size());
    p.material = int(i);
    p.mode = TINYGLTF_MODE_TRIANGLES;
    gm.primitives.push_back(p);
  }
  return gm;
}

namespace {

// Vertices [v0, v1) and triangles [t0, t1) of `mesh` (whose triangles use only those
// vertices) as a mesh of their own.
SurfaceMesh slice(const SurfaceMesh& mesh, std::size_t v0, std::size_t v1, std::size_t t0, std::size_t t1) {
  SurfaceMesh out;
  out.resize(v1 - v0, t1 - t0);
  for (std::size_t v = v0; v < v1; ++v)
    out.set_vertex(std::uint32_t(v - v0), mesh.position[v], mesh.normal[v], mesh.uv[v], mesh.node[v],
                   mesh.original_node[v]);
  for (std::size_t t = t0; t < t1; ++t) {
    std::array<std::uint32_t, 3> tri = mesh.triangles[t];
    for (auto& i : tri) i -= std::uint32_t(v0);
    out.set_triangle(t - t0, tri, mesh.material[t], mesh.kind[t], mesh.cell[t], mesh.opacity[t], mesh.shade[t]);
  }
  out.sheet_vertices = out.vertex_count();
  out.sheet_triangles = out.triangle_count();
  return out;
}

// The same triangles with vertices that agree in position, texture coordinates and ids made
// one (normals are not compared: the fibres' file leaves them out).
SurfaceMesh share_vertices(const SurfaceMesh& mesh) {
  using Key = std::array<std::uint32_t, 7>;
  struct KeyHash {
    std::size_t operator()(const Key& k) const {
      std::size_t h = 0;
      for (std::uint32_t x : k) h = h * 0x9E3779B97F4A7C15ull + x;
      return h;
    }
  };
  std::unordered_map<Key, std::uint32_t, KeyHash> index;
  std::vector<std::uint32_t> remap(mesh.vertex_count()), first;
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    Key k;
    std::memcpy(k.data(), mesh.position[v].data(), 12);
    std::memcpy(k.data() + 3, mesh.uv[v].data(), 8);
    k[5] = mesh.node[v];
    k[6] = mesh.original_node[v];
    const auto [it, added] = index.emplace(k, std::uint32_t(first.size()));
    if (added) first.push_back(std::uint32_t(v));
    remap[v] = it->second;
  }
  SurfaceMesh out;
  out.resize(first.size(), mesh.triangle_count());
  for (std::size_t i = 0; i < first.size(); ++i) {
    const std::uint32_t v = first[i];
    out.set_vertex(std::uint32_t(i), mesh.position[v], mesh.normal[v], mesh.uv[v], mesh.node[v], mesh.original_node[v]);
  }
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const auto& tri = mesh.triangles[t];
    out.set_triangle(t, {remap[tri[0]], remap[tri[1]], remap[tri[2]]}, mesh.material[t], mesh.kind[t],
                     mesh.cell[t], mesh.opacity[t], mesh.shade[t]);
  }
  out.sheet_vertices = out.vertex_count();
  out.sheet_triangles = out.triangle_count();
  return out;
}

}  // namespace

SheetAndFibres split_fibres(const SurfaceMesh& mesh) {
  return {slice(mesh, 0, mesh.sheet_vertices, 0, mesh.sheet_triangles),
          share_vertices(
              slice(mesh, mesh.sheet_vertices, mesh.vertex_count(), mesh.sheet_triangles, mesh.triangle_count()))};
}

tinygltf::Value::Object frame_extras(const FrameInfo& info) {
  tinygltf::Value::Object o;
  o["frame"] = tinygltf::Value(info.frame);
  // A step count fits a double exactly far beyond any run's length.
  o["step"] = tinygltf::Value(double(info.step));
  o["time_us"] = tinygltf::Value(info.time);
  o["fps"] = tinygltf::Value(info.fps);
  o["digest"] = tinygltf::Value(io::digest_hex(info.digest));
  return o;
}

}  // namespace papertear::render
