#include "tools/render/camera.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "tools/render/image.hpp"

namespace papertear::render {

namespace {

using Vec3 = Eigen::Vector3d;

Vec3 to_vec(const Vec3d& a) { return {a[0], a[1], a[2]}; }
Vec3f to_f(const Vec3& v) { return {float(v.x()), float(v.y()), float(v.z())}; }

// The default viewing direction: from the front (low y), a little to the left, looking
// down at 50 degrees, so the print reads upright and its tears show their depth.
Vec3 default_view_direction() {
  const double elevation = 50.0 * M_PI / 180.0, azimuth = 15.0 * M_PI / 180.0;
  return Vec3(std::sin(azimuth) * std::cos(elevation), std::cos(azimuth) * std::cos(elevation),
              -std::sin(elevation));
}

// The distance along -forward from the target at which every corner of the box lies within
// `fill` of the frame.
double fitting_distance(const Bounds& b, const Vec3& target, const Vec3& forward, const Vec3& right,
                        const Vec3& up, double tan_x, double tan_y) {
  const double fill = 0.9;
  double d = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const Vec3 p(corner & 1 ? b.hi[0] : b.lo[0], corner & 2 ? b.hi[1] : b.lo[1], corner & 4 ? b.hi[2] : b.lo[2]);
    const Vec3 r = p - target;
    const double depth = r.dot(forward);
    d = std::max(d, std::abs(r.dot(right)) / (tan_x * fill) - depth);
    d = std::max(d, std::abs(r.dot(up)) / (tan_y * fill) - depth);
  }
  const double size = (to_vec({b.hi[0], b.hi[1], b.hi[2]}) - to_vec({b.lo[0], b.lo[1], b.lo[2]})).norm();
  return std::max(d, 0.1 * size + 1e-3);
}

}  // namespace

Bounds rest_bounds(const World& w) {
  const LatticeDims& d = w.topo.dims;
  Bounds b;
  b.lo = {0.0f, 0.0f, 0.0f};
  const auto hi = d.vertex_position(d.nx, d.ny, d.nl);
  b.hi = {float(hi[0]), float(hi[1]), float(hi[2])};
  return b;
}

Bounds sheet_bounds(const World& w) {
  Bounds b;
  b.lo = {std::numeric_limits<float>::max(), std::numeric_limits<float>::max(), std::numeric_limits<float>::max()};
  b.hi = {-b.lo[0], -b.lo[1], -b.lo[2]};
  for (std::uint32_t n : w.topo.cell_nodes) {
    const float p[3] = {w.nodes.px[n], w.nodes.py[n], w.nodes.pz[n]};
    for (std::size_t a = 0; a < 3; ++a) {
      b.lo[a] = std::min(b.lo[a], p[a]);
      b.hi[a] = std::max(b.hi[a], p[a]);
    }
  }
  if (w.topo.cell_nodes.size() == 0) b.lo = b.hi = {0, 0, 0};
  return b;
}

Camera make_camera(const CameraSettings& s, const Bounds& b, int width, int height) {
  Camera cam;
  cam.aspect = float(width) / float(height);
  const double tan_y = std::tan(0.5 * s.fov * M_PI / 180.0);
  const double tan_x = tan_y * cam.aspect;
  const Vec3 centre = 0.5 * (to_vec({b.lo[0], b.lo[1], b.lo[2]}) + to_vec({b.hi[0], b.hi[1], b.hi[2]}));
  const Vec3 target = s.target ? to_vec(*s.target) : centre;
  const Vec3 forward = s.position ? (target - to_vec(*s.position)).normalized() : default_view_direction();
  const Vec3 right_raw = forward.cross(to_vec(s.up));
  if (!(right_raw.norm() > 1e-9)) throw RenderError("camera.up: parallel to the viewing direction");
  const Vec3 right = right_raw.normalized();
  const Vec3 up = right.cross(forward);
  const Vec3 position =
      s.position ? to_vec(*s.position) : target - forward * fitting_distance(b, target, forward, right, up, tan_x, tan_y);
  cam.position = to_f(position);
  cam.forward = to_f(forward);
  cam.right = to_f(right);
  cam.up = to_f(up);
  cam.tan_half_fov_y = float(tan_y);
  return cam;
}

}  // namespace papertear::render
