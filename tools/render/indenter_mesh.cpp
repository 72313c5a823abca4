#include "tools/render/indenter_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/contact.hpp"

namespace papertear::render {

namespace {

constexpr int kSegments = 48;       // around the axis
constexpr int kCapRings = 12;       // from the bottom of the tip ball to where the side begins
constexpr float kShade = 0.45f;     // a steel grey against the paper
constexpr float kHeightRadii = 3.0f;  // how far above the tip ball's centre the body is drawn

// One point of the profile: radius and height relative to the tip ball's centre, with the
// outward normal in (r, z).
struct ProfilePoint {
  float r, z, nr, nz;
};

// The profile from the bottom of the ball up: the ball's cap to where the cone (half-angle
// a) or the rod (a = 0) is tangent to it, then the side.
std::vector<ProfilePoint> profile(const Indenter& ind, float cz) {
  std::vector<ProfilePoint> p;
  const float radius = ind.radius, sin_a = ind.sin_a, cos_a = ind.cos_a;
  // The side's outward normal is (cos a, -sin a); the ball meets it at polar angle 90° - a.
  const float theta_end = std::atan2(cos_a, sin_a);
  for (int i = 0; i <= kCapRings; ++i) {
    const float theta = theta_end * float(i) / float(kCapRings);
    p.push_back({radius * std::sin(theta), -radius * std::cos(theta), std::sin(theta), -std::cos(theta)});
  }
  // A cone is drawn kHeightRadii tall (wider would hide the hole); a rod reaches at least
  // kHeightRadii radii above the sheet's top (the ball's centre at t = 0, less one radius).
  const float above_sheet = float(ind.tip_z0) - cz + (kHeightRadii - 1.0f) * radius;
  const float top = sin_a > 0.0f ? kHeightRadii * radius : std::max(kHeightRadii * radius, above_sheet);
  const ProfilePoint& joint = p.back();
  const float tan_a = sin_a / cos_a;
  p.push_back({joint.r + (top - joint.z) * tan_a, top, cos_a, -sin_a});
  return p;
}

}  // namespace

void append_indenter(const World& world, SurfaceMesh& mesh) {
  const std::optional<Indenter> ind = make_indenter(world);
  if (!ind) return;
  const IndenterPose pose = indenter_pose(*ind, world.time);
  const std::vector<ProfilePoint> prof = profile(*ind, pose.cz);
  const auto first = std::uint32_t(mesh.vertex_count());
  const auto vertex = [&](std::size_t ring, int segment) {
    return first + std::uint32_t(ring) * kSegments + std::uint32_t(segment % kSegments);
  };
  for (const ProfilePoint& q : prof)
    for (int s = 0; s < kSegments; ++s) {
      const float phi = 2.0f * float(M_PI) * float(s) / float(kSegments);
      const float c = std::cos(phi), sn = std::sin(phi);
      mesh.position.push_back({pose.cx + q.r * c, pose.cy + q.r * sn, pose.cz + q.z});
      mesh.normal.push_back({q.nr * c, q.nr * sn, q.nz});
      mesh.uv.push_back({0.0f, 0.0f});
      mesh.node.push_back(kNoNode);
      mesh.original_node.push_back(kNoNode);
    }
  // Quads between rings, counter-clockwise seen from outside: going up the profile and
  // around the axis by +phi, (lower s, lower s+1, upper s+1, upper s) faces outward.
  const auto triangle = [&](std::array<std::uint32_t, 3> v) {
    mesh.triangles.push_back(v);
    mesh.material.push_back(Material::Paper);
    mesh.kind.push_back(FaceKind::Outer);
    mesh.cell.push_back(kNoCell);
    mesh.opacity.push_back(1.0f);
    mesh.shade.push_back(kShade);
  };
  for (std::size_t ring = 0; ring + 1 < prof.size(); ++ring)
    for (int s = 0; s < kSegments; ++s) {
      const std::uint32_t a = vertex(ring, s), b = vertex(ring, s + 1), c = vertex(ring + 1, s + 1),
                          d = vertex(ring + 1, s);
      if (prof[ring].r > 0.0f) triangle({a, b, c});  // not at the ball's bottom pole, a point
      triangle({a, c, d});
    }
  // A flat top, its own vertices with the normal +z: the body is cut off, not open.
  const ProfilePoint& top = prof.back();
  const auto centre = std::uint32_t(mesh.vertex_count());
  const auto add_top_vertex = [&](float x, float y) {
    mesh.position.push_back({x, y, pose.cz + top.z});
    mesh.normal.push_back({0.0f, 0.0f, 1.0f});
    mesh.uv.push_back({0.0f, 0.0f});
    mesh.node.push_back(kNoNode);
    mesh.original_node.push_back(kNoNode);
  };
  add_top_vertex(pose.cx, pose.cy);
  for (int s = 0; s < kSegments; ++s) {
    const float phi = 2.0f * float(M_PI) * float(s) / float(kSegments);
    add_top_vertex(pose.cx + top.r * std::cos(phi), pose.cy + top.r * std::sin(phi));
  }
  for (int s = 0; s < kSegments; ++s)
    triangle({centre, centre + 1 + std::uint32_t(s), centre + 1 + std::uint32_t((s + 1) % kSegments)});
}

}  // namespace papertear::render
