// A pinhole camera, and the default view: from above the sheet at an angle, fitted so that
// the whole bounding box of the sheet fills most of the frame.
#pragma once
#include <array>

#include "core/world.hpp"
#include "tools/render/settings.hpp"

namespace papertear::render {

using Vec3f = std::array<float, 3>;

struct Bounds {
  Vec3f lo{0, 0, 0}, hi{0, 0, 0};
};

// The bounding box of the nodes that cells use.
Bounds sheet_bounds(const World& world);
// The sheet's bounds at rest (before any step): what a run frames its camera on, so that a
// run resumed from a checkpoint looks at the sheet exactly as the uninterrupted run did.
Bounds rest_bounds(const World& world);

struct Camera {
  Vec3f position{};
  Vec3f forward{}, right{}, up{};  // orthonormal; right x up = -forward
  float tan_half_fov_y = 0.0f;
  float aspect = 1.0f;             // width / height
};

// From explicit position/target when the settings give them; otherwise target = the box's
// centre and the position fitted to the box. Throws RenderError when `up` is parallel to
// the view direction.
Camera make_camera(const CameraSettings& settings, const Bounds& bounds, int width, int height);

}  // namespace papertear::render
