#include "tools/render/mesh_export.hpp"

#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <map>
#include <sstream>
#include <vector>

#include "tools/output_files.hpp"

namespace papertear::render {

namespace {

constexpr std::array<Material, 3> kMaterials = {Material::Print, Material::Paper, Material::Fibre};
constexpr std::array<const char*, 3> kMaterialNames = {"print", "paper", "fibre"};
constexpr std::uint32_t kExactFloatIds = 1u << 24;

std::size_t index_of(Material m) { return m == Material::Print ? 0 : m == Material::Paper ? 1 : 2; }

double srgb_to_linear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }

// Triangle indices grouped by material, each group in mesh order.
std::array<std::vector<std::uint32_t>, 3> indices_by_material(const SurfaceMesh& mesh) {
  std::array<std::vector<std::uint32_t>, 3> out;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    auto& list = out[index_of(mesh.material[t])];
    list.insert(list.end(), mesh.triangles[t].begin(), mesh.triangles[t].end());
  }
  return out;
}

void check_ids(const SurfaceMesh& mesh) {
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
    if (mesh.node[v] >= kExactFloatIds || mesh.original_node[v] >= kExactFloatIds)
      throw RenderError("glTF export: node ids of 2^24 and above cannot be stored exactly as floats");
}

// Builds the glTF model: one buffer holding every array, one view and accessor per array.
class GltfBuilder {
 public:
  GltfBuilder() {
    model_.asset.version = "2.0";
    model_.asset.generator = "papertear";
    model_.buffers.emplace_back();
  }

  template <class T>
  int view(const std::vector<T>& data, int target) {
    return view_bytes(data.data(), data.size() * sizeof(T), target);
  }
  int view_bytes(const void* data, std::size_t bytes, int target) {
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
  int accessor(int view, int component, int type, std::size_t count) {
    tinygltf::Accessor a;
    a.bufferView = view;
    a.componentType = component;
    a.type = type;
    a.count = count;
    model_.accessors.push_back(a);
    return int(model_.accessors.size() - 1);
  }
  tinygltf::Model& model() { return model_; }

 private:
  tinygltf::Model model_;
};

std::vector<float> flatten3(const MeshArray<std::array<float, 3>>& v) {
  std::vector<float> out;
  out.reserve(v.size() * 3);
  for (const auto& a : v) out.insert(out.end(), a.begin(), a.end());
  return out;
}

std::map<std::string, int> vertex_attributes(GltfBuilder& g, const SurfaceMesh& mesh) {
  const std::size_t n = mesh.vertex_count();
  std::map<std::string, int> attr;
  const int pos = g.accessor(g.view(flatten3(mesh.position), TINYGLTF_TARGET_ARRAY_BUFFER),
                             TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, n);
  std::vector<double> lo(3, 0.0), hi(3, 0.0);
  for (std::size_t c = 0; c < 3 && n > 0; ++c) {
    lo[c] = hi[c] = mesh.position[0][c];
    for (const auto& p : mesh.position) {
      lo[c] = std::min(lo[c], double(p[c]));
      hi[c] = std::max(hi[c], double(p[c]));
    }
  }
  g.model().accessors[std::size_t(pos)].minValues = lo;
  g.model().accessors[std::size_t(pos)].maxValues = hi;
  attr["POSITION"] = pos;
  attr["NORMAL"] = g.accessor(g.view(flatten3(mesh.normal), TINYGLTF_TARGET_ARRAY_BUFFER),
                              TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, n);
  std::vector<float> uv;
  for (const auto& t : mesh.uv) uv.insert(uv.end(), t.begin(), t.end());
  attr["TEXCOORD_0"] = g.accessor(g.view(uv, TINYGLTF_TARGET_ARRAY_BUFFER), TINYGLTF_COMPONENT_TYPE_FLOAT,
                                  TINYGLTF_TYPE_VEC2, n);
  const std::vector<float> node(mesh.node.begin(), mesh.node.end());
  const std::vector<float> original(mesh.original_node.begin(), mesh.original_node.end());
  attr["_NODE"] = g.accessor(g.view(node, TINYGLTF_TARGET_ARRAY_BUFFER), TINYGLTF_COMPONENT_TYPE_FLOAT,
                             TINYGLTF_TYPE_SCALAR, n);
  attr["_ORIGINAL_NODE"] = g.accessor(g.view(original, TINYGLTF_TARGET_ARRAY_BUFFER),
                                      TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_SCALAR, n);
  return attr;
}

void add_materials(GltfBuilder& g, const ExportOptions& o) {
  tinygltf::Model& m = g.model();
  const std::vector<double> paper = {srgb_to_linear(o.paper_color[0]), srgb_to_linear(o.paper_color[1]),
                                     srgb_to_linear(o.paper_color[2]), 1.0};
  for (std::size_t i = 0; i < kMaterials.size(); ++i) {
    tinygltf::Material mat;
    mat.name = kMaterialNames[i];
    mat.pbrMetallicRoughness.baseColorFactor = kMaterials[i] == Material::Print && o.print
                                                   ? std::vector<double>{1.0, 1.0, 1.0, 1.0}
                                                   : paper;
    mat.pbrMetallicRoughness.metallicFactor = 0.0;
    mat.pbrMetallicRoughness.roughnessFactor = 1.0;
    m.materials.push_back(mat);
  }
  if (!o.print) return;
  const std::vector<std::uint8_t> png = encode_png(*o.print);
  tinygltf::Image image;
  image.name = "print";
  image.mimeType = "image/png";
  image.bufferView = g.view(png, 0);
  m.images.push_back(image);
  tinygltf::Sampler sampler;
  sampler.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
  sampler.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;
  sampler.wrapS = sampler.wrapT = TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
  m.samplers.push_back(sampler);
  tinygltf::Texture tex;
  tex.source = 0;
  tex.sampler = 0;
  m.textures.push_back(tex);
  m.materials[0].pbrMetallicRoughness.baseColorTexture.index = 0;
}

// OBJ text, written with std::to_chars (shortest round-trip form, locale-independent).
class ObjText {
 public:
  ObjText& operator<<(std::string_view s) {
    text_.append(s);
    return *this;
  }
  ObjText& operator<<(float v) { return number(v); }
  ObjText& operator<<(std::uint32_t v) { return number(v); }
  ObjText& operator<<(std::size_t v) { return number(v); }
  const std::string& str() const { return text_; }

 private:
  template <class T>
  ObjText& number(T v) {
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    text_.append(buf, r.ptr);
    return *this;
  }
  std::string text_;
};

std::string mtl_text(const ExportOptions& o) {
  ObjText t;
  t << "# papertear materials\n";
  for (std::size_t i = 0; i < kMaterials.size(); ++i) {
    t << "newmtl " << kMaterialNames[i] << "\n";
    const bool textured = kMaterials[i] == Material::Print && !o.print_file.empty();
    for (int c = 0; c < 3; ++c) t << (c ? " " : "Kd ") << (textured ? 1.0f : float(o.paper_color[std::size_t(c)]));
    t << "\nKa 0 0 0\nKs 0 0 0\nd 1\nillum 1\n";
    if (textured) t << "map_Kd " << o.print_file << "\n";
  }
  return t.str();
}

}  // namespace

void export_glb(const SurfaceMesh& mesh, const std::filesystem::path& path, const ExportOptions& options) {
  check_ids(mesh);
  GltfBuilder g;
  const std::map<std::string, int> attributes = vertex_attributes(g, mesh);
  add_materials(g, options);
  tinygltf::Mesh gm;
  gm.name = "sheet";
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
  tinygltf::Model& m = g.model();
  m.meshes.push_back(gm);
  tinygltf::Node node;
  node.mesh = 0;
  node.name = "sheet";
  m.nodes.push_back(node);
  tinygltf::Scene scene;
  scene.nodes = {0};
  m.scenes.push_back(scene);
  m.defaultScene = 0;
  std::ostringstream out;
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&m, out, false, true))
    throw RenderError("cannot encode '" + path.string() + "' as glTF");
  io::write_file_atomically(path, out.str());
}

void export_obj(const SurfaceMesh& mesh, const std::filesystem::path& path, const ExportOptions& options) {
  std::filesystem::path mtl = path;
  mtl.replace_extension(".mtl");
  ObjText t;
  t << "# papertear display mesh: " << mesh.vertex_count() << " vertices, " << mesh.triangle_count()
    << " triangles\n# Each 'v' line is followed by '#node <original node> <node>': the id of the node at the\n"
    << "# same lattice vertex in the intact sheet, and the node's id in this frame.\n";
  t << "mtllib " << mtl.filename().string() << "\n";
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    const auto& p = mesh.position[v];
    t << "v " << p[0] << " " << p[1] << " " << p[2] << "\n#node " << mesh.original_node[v] << " " << mesh.node[v] << "\n";
  }
  for (const auto& uv : mesh.uv) t << "vt " << uv[0] << " " << (1.0f - uv[1]) << "\n";
  for (const auto& n : mesh.normal) t << "vn " << n[0] << " " << n[1] << " " << n[2] << "\n";
  const auto groups = indices_by_material(mesh);
  for (std::size_t i = 0; i < groups.size(); ++i) {
    if (groups[i].empty()) continue;
    t << "g " << kMaterialNames[i] << "\nusemtl " << kMaterialNames[i] << "\n";
    for (std::size_t k = 0; k < groups[i].size(); k += 3) {
      t << "f";
      for (std::size_t c = 0; c < 3; ++c) {
        const std::uint32_t v = groups[i][k + c] + 1;
        t << " " << v << "/" << v << "/" << v;
      }
      t << "\n";
    }
  }
  io::write_file_atomically(mtl, mtl_text(options));
  io::write_file_atomically(path, t.str());
}

}  // namespace papertear::render
