// Ray-traced frames of the display mesh (Embree 3).
//
// One frame: the world's surface mesh (surface.hpp: print, paper, fibres, peeled skins) goes
// into three Embree scenes, opaque surfaces, peeled skins facing the eye and skins for
// shadow rays (each without the triangles its rays cannot need: raytracer.cpp), their
// triangles paired into quads (quads.hpp). The renderer keeps the mesh, the scenes and the
// passes' buffers for the next frame, which rebuilds them in place: a frame loop does not
// fault in and unmap them every frame (the mesh alone is ~40 MB for a torn 90 x 90 x 5
// sheet). The image is cut into 32 x 32 pixel tiles that are traced in parallel
// (kernels/parallel.hpp: TBB, fixed chunks). Within a tile, rays go to Embree as
// packets of 16 (4 x 4 pixel blocks): one query finds their nearest opaque surfaces, one
// gathers the skins in front of them, and the shadow rays of all surfaces seen go out 16 at
// a time. Which rays share a packet depends only on the tile, and every "random" number
// (sub-pixel position, point on the light) is hashed from (pixel, sample), so a frame has
// the same bytes on any number of threads.
//
// Adaptive sampling: one sample per pixel first; the remaining samples are traced where a
// pixel's colour differs from a neighbour's and so does its shading with the print left
// blank (edges, silhouettes, shadows, fibres); where only the print differs, they look the
// print up on the same flat surface instead.
//
// Shading: a directional key light with soft shadows (shadow rays towards a jittered point
// of the light's disc; the cosine term takes its centre), a sky term brighter from above, Lambert surfaces in linear light,
// output in sRGB. A peeled skin of opacity a adds a times its own colour and passes 1 - a
// of what lies behind it; light shining through a thin skin lights its far side too.
#pragma once
#include <memory>

#include "core/world.hpp"
#include "tools/render/camera.hpp"
#include "tools/render/image.hpp"
#include "tools/render/settings.hpp"
#include "tools/render/surface.hpp"

namespace papertear::render {

class Renderer {
 public:
  // Loads the print (RenderError when its PNG cannot be read) and opens an Embree device.
  explicit Renderer(const RenderSettings& settings);
  ~Renderer();
  Renderer(Renderer&&) noexcept;
  Renderer& operator=(Renderer&&) noexcept;
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  const RenderSettings& settings() const;
  const Image& print() const;  // the image on the top face (sRGB)
  MeshOptions mesh_options() const;

  // The settings' camera, or the default view fitted to this world's sheet. For an
  // animation, take it once from the first frame and pass it to every draw().
  Camera camera_for(const World& world) const;

  // A frame of the world (with the pierce scene's indenter, indenter_mesh.hpp), or of a mesh
  // already built. Safe to call from several threads at once: a call that finds the kept
  // buffers in use by another allocates its own.
  Image draw(const World& world, const Camera& camera) const;
  Image draw(const SurfaceMesh& mesh, const Camera& camera) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace papertear::render
