// Mesh export of the display mesh (surface.hpp): glTF binary (.glb) and Wavefront OBJ.
//
// Both carry positions, normals, the print's texture coordinates and, per vertex, the node
// it belongs to, so that downstream tools can follow a point of the sheet across frames:
//   node           the node's id in this frame (ids never change once given out), and
//   original node  the id of the node at the same lattice vertex in the intact sheet; all
//                  pieces a node was split into share it.
// glTF: vertex attributes "_NODE" and "_ORIGINAL_NODE", SCALAR FLOAT (glTF allows 32-bit
// unsigned integers only for indices; floats hold ids exactly below 2^24, and export
// refuses a mesh with larger ids), and again as the UV map TEXCOORD_1 for importers that
// drop custom attributes. Two meshes, each with its node: "sheet", one primitive per
// material ("print", "paper", "fibre" for torn faces) sharing the vertex data, and
// "fibres", the frayed fibres, with shared vertices and no normals (flat-shaded), so that
// a user can hide or drop them. The print image, if given, is embedded as a PNG.
// OBJ: every "v" line is followed by a comment line "#node <original node> <node>".
// Texture coordinates are written with OBJ's origin at the image's bottom left; a .mtl file
// of the same name holds the three materials, and refers to the print image by file name.
// Both are in glTF's frame, y up and in metres (gltf_builder.hpp): a simulation point
// (x, y, z) mm is written as (x, z, -y) * 0.001, normals likewise rotated.
// Fibres and translucency of peeled skins are display detail: in the OBJ the fibres are
// ordinary triangles of group "fibre"; translucency is not exported.
#pragma once
#include <filesystem>
#include <string>

#include <optional>

#include "tools/render/gltf_frame.hpp"
#include "tools/render/image.hpp"
#include "tools/render/settings.hpp"
#include "tools/render/surface.hpp"

namespace papertear::render {

struct ExportOptions {
  const Image* print = nullptr;  // glb: embedded as the print material's texture
  std::string print_file;        // obj: the texture's file name for map_Kd (not written here)
  Vec3d paper_color{0.93, 0.91, 0.86};  // sRGB
  std::optional<FrameInfo> frame;       // glb: asset.extras; obj: a header comment
};

// Both written atomically (tools/output_files.hpp: io::OutputError when a file cannot be
// written); RenderError for a mesh that cannot be encoded.
void export_glb(const SurfaceMesh& mesh, const std::filesystem::path& path, const ExportOptions& options = {});
// Writes `path` (.obj) and the .mtl beside it (same stem).
void export_obj(const SurfaceMesh& mesh, const std::filesystem::path& path, const ExportOptions& options = {});

}  // namespace papertear::render
