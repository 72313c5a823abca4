// The .glb writers' shared parts (mesh_export.hpp, animation.hpp): the frame record in
// asset.extras, the materials and a builder that packs arrays into one buffer.
#pragma once
#include <array>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <tiny_gltf.h>

#include "tools/render/gltf_frame.hpp"
#include "tools/render/image.hpp"
#include "tools/render/settings.hpp"
#include "tools/render/surface.hpp"

namespace papertear::render {

// The print image (embedded as PNG) and the paper colour of the three materials.
struct MaterialOptions {
  const Image* print = nullptr;
  Vec3d paper_color{0.93, 0.91, 0.86};  // sRGB
};

class GltfBuilder {
 public:
  GltfBuilder();

  template <class T>
  int view(const std::vector<T>& data, int target) {
    return view_bytes(data.data(), data.size() * sizeof(T), target);
  }
  int view_bytes(const void* data, std::size_t bytes, int target);
  int accessor(int view, int component, int type, std::size_t count);
  // A FLOAT VEC3 accessor with the min and max glTF requires of POSITION.
  int vec3_accessor(const std::vector<float>& xyz, bool with_bounds);
  // Materials "print", "paper", "fibre" (indices 0, 1, 2), the print as texture 0.
  void add_materials(const MaterialOptions& options);
  // asset.extras: units and frame, and what else the writer adds.
  void set_extras(tinygltf::Value::Object extras);
  // One node per mesh, named as the mesh, all in the default scene.
  void add_mesh_nodes();
  tinygltf::Model& model() { return model_; }
  // Encodes the model as .glb and writes it atomically (io::OutputError, RenderError).
  void write(const std::filesystem::path& path);

 private:
  tinygltf::Model model_;
};

tinygltf::Value::Object frame_extras(const FrameInfo& info);

// The mesh's triangle indices grouped by material (print, paper, fibre), each in mesh order.
std::array<std::vector<std::uint32_t>, 3> indices_by_material(const SurfaceMesh& mesh);
// TEXCOORD_0, _NODE and _ORIGINAL_NODE, and with `ids_uv` TEXCOORD_1 = (_NODE,
// _ORIGINAL_NODE) (ids as SCALAR FLOAT: glTF allows 32-bit integers
// only for indices, and floats hold ids exactly below 2^24; RenderError for larger ids).
std::map<std::string, int> print_and_node_attributes(GltfBuilder& g, const SurfaceMesh& mesh, bool ids_uv = true);
// A mesh named `name`: one primitive per material that has triangles, all with `attributes`.
tinygltf::Mesh primitives_by_material(GltfBuilder& g, const SurfaceMesh& mesh,
                                      const std::map<std::string, int>& attributes, const std::string& name);

// The mesh cut in two: the sheet's faces, and the frayed fibres after them (surface.hpp),
// each with its own vertices (fibre vertices are never shared with the sheet). The fibres'
// vertices are shared where they agree in all but the normal: the file gives the fibres
// no normals, so viewers shade them flat, as glTF asks of a mesh without NORMAL.
struct SheetAndFibres {
  SurfaceMesh sheet, fibres;
};
SheetAndFibres split_fibres(const SurfaceMesh& mesh);

}  // namespace papertear::render
