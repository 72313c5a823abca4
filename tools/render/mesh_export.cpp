#include "tools/render/mesh_export.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <map>
#include <sstream>
#include <vector>

#include "tools/output_files.hpp"
#include "tools/render/gltf_builder.hpp"
#include "tools/summary.hpp"

namespace papertear::render {

namespace {

constexpr std::array<const char*, 3> kMaterialNames = {"print", "paper", "fibre"};

// Positions or normals (`to_gltf`: to_gltf_position or to_gltf_direction) in glTF's frame
// (gltf_frame.hpp), flattened.
template <class Convert>
std::vector<float> in_gltf_frame(const MeshArray<std::array<float, 3>>& v, Convert to_gltf) {
  std::vector<float> out;
  out.reserve(v.size() * 3);
  for (const auto& a : v) {
    const std::array<float, 3> g = to_gltf(a);
    out.insert(out.end(), g.begin(), g.end());
  }
  return out;
}

// The sheet's attributes, or the fibres' (flat-shaded: no normals, and no ids UV map: a
// fibre's node is that of the face it grows on).
std::map<std::string, int> vertex_attributes(GltfBuilder& g, const SurfaceMesh& mesh, bool fibres) {
  std::map<std::string, int> attr = print_and_node_attributes(g, mesh, !fibres);
  attr["POSITION"] = g.vec3_accessor(in_gltf_frame(mesh.position, to_gltf_position), true);
  if (!fibres) attr["NORMAL"] = g.vec3_accessor(in_gltf_frame(mesh.normal, to_gltf_direction), false);
  return attr;
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
  for (std::size_t i = 0; i < kMaterialNames.size(); ++i) {
    t << "newmtl " << kMaterialNames[i] << "\n";
    const bool textured = i == 0 && !o.print_file.empty();
    for (int c = 0; c < 3; ++c) t << (c ? " " : "Kd ") << (textured ? 1.0f : float(o.paper_color[std::size_t(c)]));
    t << "\nKa 0 0 0\nKs 0 0 0\nd 1\nillum 1\n";
    if (textured) t << "map_Kd " << o.print_file << "\n";
  }
  return t.str();
}

}  // namespace

void export_glb(const SurfaceMesh& mesh, const std::filesystem::path& path, const ExportOptions& options) {
  GltfBuilder g;
  g.add_materials({.print = options.print, .paper_color = options.paper_color});
  // The fibres in a mesh (and node) of their own, so that a user can hide or drop them.
  const SheetAndFibres parts = split_fibres(mesh);
  g.model().meshes.push_back(primitives_by_material(g, parts.sheet, vertex_attributes(g, parts.sheet, false), "sheet"));
  if (parts.fibres.triangle_count() > 0)
    g.model().meshes.push_back(
        primitives_by_material(g, parts.fibres, vertex_attributes(g, parts.fibres, true), "fibres"));
  g.add_mesh_nodes();
  g.set_extras(options.frame ? frame_extras(*options.frame) : tinygltf::Value::Object{});
  g.write(path);
}

void export_obj(const SurfaceMesh& mesh, const std::filesystem::path& path, const ExportOptions& options) {
  std::filesystem::path mtl = path;
  mtl.replace_extension(".mtl");
  ObjText t;
  t << "# papertear display mesh: " << mesh.vertex_count() << " vertices, " << mesh.triangle_count()
    << " triangles\n# Each 'v' line is followed by '#node <original node> <node>': the id of the node at the\n"
    << "# same lattice vertex in the intact sheet, and the node's id in this frame.\n";
  t << "# Units: metres, y up: simulation (x, y, z) mm is written as (x, z, -y) * 0.001.\n";
  if (options.frame) {
    const FrameInfo& f = *options.frame;
    t << "# frame " << std::size_t(f.frame) << " step " << std::size_t(f.step) << " time_us " << float(f.time)
      << " fps " << std::size_t(f.fps) << " digest " << io::digest_hex(f.digest) << "\n";
  }
  t << "mtllib " << mtl.filename().string() << "\n";
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    const auto p = to_gltf_position(mesh.position[v]);
    t << "v " << p[0] << " " << p[1] << " " << p[2] << "\n#node " << mesh.original_node[v] << " " << mesh.node[v] << "\n";
  }
  for (const auto& uv : mesh.uv) t << "vt " << uv[0] << " " << (1.0f - uv[1]) << "\n";
  for (const auto& normal : mesh.normal) {
    const auto n = to_gltf_direction(normal);
    t << "vn " << n[0] << " " << n[1] << " " << n[2] << "\n";
  }
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
