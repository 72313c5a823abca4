// The surface faces as welded quads (surface.hpp), built in parallel with the bytes of the
// serial definition: faces in (cell, face) order, each face's corners in face_loop order, a
// new vertex for every (node, face orientation) not met before; each face's two triangles
// (v0 v1 v2) (v0 v2 v3), whose cross products are added to their three vertices in triangle
// order; then every normal normalised.
//
// Without a table filled in that order, each corner works out its place from the lattice:
// a node sits at one lattice vertex (core/invariants.hpp checks it), so the faces of one
// orientation that hold it all lie around that vertex in the face's plane, i.e. they are
// faces of the corner's own cell and of at most three of its neighbours (the corner's
// "ring"). From the cells' open-face masks a corner lists its ring in ascending cell order,
// which is the order in which open_faces lists those faces. The corner of the lowest cell
// creates the vertex, and sums its normal over the ring in that order: the same terms in the
// same order as the serial loop, so the same bits. Fixed chunks of faces count the vertices
// they create; the counts in chunk order number them.
#pragma once
#include <cstdint>
#include <vector>

#include "core/world.hpp"
#include "tools/render/surface.hpp"

namespace papertear::render {

class WeldedQuads {
 public:
  // Finds the corners that create vertices (in parallel). `open` holds each cell's bits of
  // open faces (open_face_masks) and `faces` the list made from them; the world, the faces
  // and the masks are read again by write(), so they must outlive this object.
  WeldedQuads(const World& world, const std::vector<OpenFace>& faces, const std::vector<std::uint8_t>& open);

  std::size_t vertex_count() const { return first_vertex_.back(); }
  std::size_t triangle_count() const { return 2 * faces_.size(); }

  // Writes vertices [0, vertex_count()) and triangles [0, triangle_count()) of a mesh
  // already sized to hold them; `opacity` is per cell (peel.hpp).
  void write(const std::vector<float>& opacity, SurfaceMesh& mesh) const;

 private:
  void write_vertices(SurfaceMesh& mesh, std::vector<std::uint32_t>& vertex_of) const;
  void write_triangles(const std::vector<float>& opacity, const std::vector<std::uint32_t>& vertex_of,
                       SurfaceMesh& mesh) const;

  const World& world_;
  const std::vector<OpenFace>& faces_;
  const std::vector<std::uint8_t>& open_;
  std::vector<std::uint8_t> creates_;      // per face: bit c set when corner c creates its vertex
  std::vector<std::size_t> first_vertex_;  // per chunk of faces its first vertex; last: the count
};

}  // namespace papertear::render
