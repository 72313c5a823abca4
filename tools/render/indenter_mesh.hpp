// The pierce scene's indenter (core/contact.hpp) as display geometry, so a frame shows what
// is pushing through the sheet.
#pragma once
#include "core/world.hpp"
#include "tools/render/surface.hpp"

namespace papertear::render {

// Appends the indenter of a pierce scene, where it is at the world's time, to `mesh`:
// a grey body of revolution (the tip ball, then the cone or the rod), a cone three radii tall,
// a rod up to three radii above the sheet. Does nothing for other loads. Its triangles are opaque Paper with a dark shade
// and no cell (kNoCell); its vertices belong to no node (kNoNode).
void append_indenter(const World& world, SurfaceMesh& mesh);

inline constexpr std::uint32_t kNoCell = 0xffffffffu;
inline constexpr std::uint32_t kNoNode = 0xffffffffu;

}  // namespace papertear::render
