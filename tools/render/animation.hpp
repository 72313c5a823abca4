// The animated .glb of a whole run (DIR/animation.glb): one mesh with the run's final
// topology whose positions follow the sheet frame by frame, as morph targets.
//
// Node splitting only ever divides the cells around a node between it and a new node, so
// the final topology holds every node the run made, and every one of them descends from the
// node that its cells shared in an earlier frame. A vertex of the final mesh (at final node
// m) is placed in frame f at the node that m's cells used at that frame: a node that has not
// split off yet sits exactly on its parent, and the faces of a crack that has not opened are
// closed (coincident, so invisible) until it does. At every frame the sheet's vertices are
// where that frame's own mesh export puts them (both in glTF's frame, gltf_frame.hpp).
//
// The file: the base mesh is frame 0; morph target k - 1 holds frame k's displacements of
// POSITION and NORMAL; one animation sets the weights at time k / fps to the one-hot vector
// of frame k, interpolated linearly in between (so it plays exactly the frames at their
// times, and smoothly at a display's higher rate). Target names ("frame_0001", ...) are in
// the mesh's extras.targetNames, which Blender and three.js read. Print UVs, materials and
// the per-vertex node ids (_NODE: the node in the final frame; _ORIGINAL_NODE) are as in the
// per-frame export (mesh_export.hpp). Left out: the frayed fibres, whose count changes from
// frame to frame (they are in the per-frame export), and the translucency of peeled skins.
#pragma once
#include <cstdint>
#include <filesystem>
#include <memory>
#include <vector>

#include "core/world.hpp"
#include "tools/render/mesh_export.hpp"
#include "tools/render/surface.hpp"

namespace papertear::render {

// Frames are kept in memory until the end of the run: 12 bytes per node per frame, plus the
// cell table (32 bytes per cell) for each frame whose topology changed. The default run
// peaks at 212 MB resident with it, 210 MB without (output.animation = false).
class TearRecording {
 public:
  // Keeps this frame's node positions, and its cell-corner to node table unless it is the
  // same as the previous frame's (topology changes only when a node splits).
  void add_frame(const World& world, const FrameInfo& info);
  std::size_t frame_count() const { return frames_.size(); }
  std::size_t bytes() const;  // memory held

  // Writes the animation of the recorded frames on the topology of `final_world` (the
  // world after the last recorded frame, or later). RenderError with no frames recorded.
  void write_glb(const World& final_world, const ExportOptions& options, const std::filesystem::path& path) const;

 private:
  struct Frame {
    FrameInfo info;
    std::vector<float> xyz;  // node positions, simulation frame
    std::shared_ptr<const std::vector<std::uint32_t>> cell_nodes;
  };
  std::vector<Frame> frames_;
};

}  // namespace papertear::render
