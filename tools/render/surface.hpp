// The sheet's visible surface, extracted from the topology (MODEL.md §6, paper §4).
//
// A cell face is part of the surface when no lattice neighbour is joined to the cell across
// it (fracture/connectivity.hpp: joined = all four face nodes shared). Such faces are:
//   Print      the top face of the top layer (carries the printed image),
//   Outer      any other face on the outside of the lattice (edges, underside),
//   Torn       an in-plane face whose neighbour exists but has been split off,
//   Separated  a face between two layers that have come apart (peeling).
// Geometry is taken at the nodes' current positions; texture coordinates come from the
// nodes' rest positions, so the print tears and stretches with the paper.
//
// Vertices are shared between faces of the same orientation that meet at one node, which
// makes a bent sheet shade smoothly while the cell edges stay crisp. Every vertex records
// its node (ids are stable from frame to frame) and that node's original id, i.e. the node
// at the same lattice vertex in the intact sheet, so points can be followed across frames
// and across tears.
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/world.hpp"

namespace papertear::render {

enum class FaceKind : std::uint8_t { Print, Outer, Torn, Separated };
enum class Material : std::uint8_t { Print, Paper, Fibre };

struct OpenFace {
  std::uint32_t cell;
  std::uint8_t face;  // 2 * axis + side (core/lattice.hpp)
  FaceKind kind;
};

// Every surface face, in ascending (cell, face) order.
std::vector<OpenFace> open_faces(const World& world);
// The same in two steps: per cell, bit f set when face f is a surface face; then the list.
std::vector<std::uint8_t> open_face_masks(const World& world);
std::vector<OpenFace> open_faces(const World& world, const std::vector<std::uint8_t>& open);

// An allocator whose resize() leaves new elements default-initialised, which for the mesh's
// plain types means not written at all. build_surface_mesh sizes the mesh once and then its
// parallel passes write every entry, so each page is first touched (and faulted in) by the
// thread that fills it, rather than zeroed beforehand by one thread.
template <class T>
struct UninitialisedAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = UninitialisedAllocator<U>;
  };
  UninitialisedAllocator() = default;
  template <class U>
  UninitialisedAllocator(const UninitialisedAllocator<U>&) noexcept {}
  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};
template <class T>
using MeshArray = std::vector<T, UninitialisedAllocator<T>>;

struct SurfaceMesh {
  // Per vertex.
  MeshArray<std::array<float, 3>> position;
  MeshArray<std::array<float, 3>> normal;
  MeshArray<std::array<float, 2>> uv;         // print coordinates, (0, 0) = the image's top left
  MeshArray<std::uint32_t> node;              // node id in this frame
  MeshArray<std::uint32_t> original_node;     // node id in the intact sheet (= lattice vertex)
  // Per triangle (counter-clockwise seen from outside).
  MeshArray<std::array<std::uint32_t, 3>> triangles;
  MeshArray<Material> material;
  MeshArray<FaceKind> kind;
  MeshArray<std::uint32_t> cell;
  MeshArray<float> opacity;  // 1, or less for a peeled skin (peel.hpp)
  MeshArray<float> shade;    // albedo factor: fibres vary a little in brightness
  // Vertices and triangles [0, sheet_*) are the sheet's faces (welded quads, weld.hpp); the
  // frayed fibres (and, when drawn, the indenter) come after them.
  std::size_t sheet_vertices = 0, sheet_triangles = 0;

  std::size_t vertex_count() const { return position.size(); }
  std::size_t triangle_count() const { return triangles.size(); }
  // Sets every per-vertex and per-triangle array to these sizes; new entries are left
  // uninitialised for set_vertex and set_triangle to fill in (several threads may fill
  // disjoint ones), and all of them must be. Arrays keep their capacity, and one that must
  // grow is not copied (its old entries are to be overwritten anyway).
  void resize(std::size_t vertices, std::size_t triangle_slots);
  void set_vertex(std::uint32_t i, const std::array<float, 3>& p, const std::array<float, 3>& n,
                  const std::array<float, 2>& t, std::uint32_t node_id, std::uint32_t original);
  void set_triangle(std::size_t i, std::array<std::uint32_t, 3> v, Material m, FaceKind k, std::uint32_t cell_id,
                    float alpha, float brightness);
};

struct MeshOptions {
  bool fray = true;            // torn faces grow jagged fibres (fray.hpp)
  float fray_length = 0.45f;   // how far fibres stick out, in cell sizes
  float layer_opacity = 0.7f;  // opacity of a peeled skin one layer thick (peel.hpp)
};

// The display mesh of a world: its surface faces as triangles, plus frayed fibres on torn
// faces. Reads the world only.
SurfaceMesh build_surface_mesh(const World& world, const MeshOptions& options = {});
// The same, written into `mesh` (whatever it held before is replaced). For a frame loop:
// passing the same mesh back every frame keeps its ~40 MB (a torn 90 x 90 x 5 sheet) mapped,
// instead of faulting in fresh pages and unmapping them again each frame.
void build_surface_mesh(const World& world, const MeshOptions& options, SurfaceMesh& mesh);

// The corners of face f in counter-clockwise order seen from outside the cell.
std::array<int, 4> face_loop(int face);

}  // namespace papertear::render
