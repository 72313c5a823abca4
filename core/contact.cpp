#include "core/contact.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "core/elasticity.hpp"
#include "core/lattice_builder.hpp"
#include "core/solver.hpp"
#include "kernels/parallel.hpp"

namespace papertear {

std::optional<Indenter> make_indenter(const World& w) {
  const LoadParams& l = w.scene.load;
  if (l.kind != "pierce") return std::nullopt;
  const LatticeDims& d = w.topo.dims;
  Indenter ind;
  ind.x = l.indenter_at[0] * d.nx * d.hx;
  ind.y = l.indenter_at[1] * d.ny * d.hy;
  ind.tip_z0 = d.nl * d.hz + l.indenter_radius;  // the ball's bottom touches the top face
  ind.radius = float(l.indenter_radius);
  if (l.indenter == "cone") {
    const double a = l.indenter_angle * std::numbers::pi / 180.0;
    ind.sin_a = float(std::sin(a));
    ind.cos_a = float(std::cos(a));
  }
  const double k = l.contact_stiffness * stiffest_edge(w.springs) / cell_mass(w.scene.material, d);
  ind.stiffness = float(k);
  ind.damping = float(k * w.scene.material.damping);
  ind.speed = l.speed;
  ind.ramp_time = l.ramp_time;
  return ind;
}

// The speed ramps up linearly over ramp_time, as the grips' does.
double indenter_travel(const Indenter& ind, double t) { return ramped_travel(ind.speed, ind.ramp_time, t); }

IndenterPose indenter_pose(const Indenter& ind, double t) {
  const double ramp = ind.ramp_time <= 0.0 ? 1.0 : std::min(1.0, std::max(0.0, t) / ind.ramp_time);
  return {float(ind.x), float(ind.y), float(ind.tip_z0 - indenter_travel(ind, t)), float(-ind.speed * ramp)};
}

namespace {

struct Contact {
  float depth = 0.0f;         // > 0 inside the body
  float nx = 0, ny = 0, nz = -1;  // outward normal
};

// Depth and normal of a point q relative to the tip centre. The body is the set of points
// within R of the sharp cone {ρ cos α ≤ h sin α}: in the (ρ, h) half-plane, points whose
// projection on the cone's side line (sin α, cos α) is negative are nearest the apex,
// the others nearest that side line, at signed distance ρ cos α − h sin α.
Contact contact_at(float qx, float qy, float qz, const Indenter& ind) {
  Contact c;
  const float rho = std::sqrt(qx * qx + qy * qy);
  float dist;
  if (rho * ind.sin_a + qz * ind.cos_a <= 0.0f) {
    dist = std::sqrt(rho * rho + qz * qz);
    if (dist > 0.0f) c.nx = qx / dist, c.ny = qy / dist, c.nz = qz / dist;
  } else {
    dist = rho * ind.cos_a - qz * ind.sin_a;
    // On the axis the side's normal is undefined: push the node off the tip, downwards.
    if (rho > 0.0f) c.nx = ind.cos_a * qx / rho, c.ny = ind.cos_a * qy / rho, c.nz = -ind.sin_a;
  }
  c.depth = ind.radius - dist;
  return c;
}

// The force on one node at (p, v): zero outside the body.
std::array<float, 3> node_contact_force(const Indenter& ind, const IndenterPose& pose, float px, float py, float pz,
                                        float vx, float vy, float vz, float mass) {
  const Contact c = contact_at(px - pose.cx, py - pose.cy, pz - pose.cz, ind);
  if (!(c.depth > 0.0f)) return {0.0f, 0.0f, 0.0f};
  const float vn = vx * c.nx + vy * c.ny + (vz - pose.vz) * c.nz;
  const float f = mass * (ind.stiffness * c.depth - ind.damping * vn);
  if (!(f > 0.0f)) return {0.0f, 0.0f, 0.0f};  // a penalty pushes, it never pulls
  return {f * c.nx, f * c.ny, f * c.nz};
}

}  // namespace

void add_contact_forces(std::size_t begin, std::size_t end, const Indenter& ind, const IndenterPose& pose,
                        const ContactInputs& in, float* fx, float* fy, float* fz) {
  for (std::size_t i = begin; i < end; ++i) {
    const std::array<float, 3> f =
        node_contact_force(ind, pose, in.sx[i], in.sy[i], in.sz[i], in.svx[i], in.svy[i], in.svz[i], in.mass[i]);
    fx[i] += f[0];
    fy[i] += f[1];
    fz[i] += f[2];
  }
}

void apply_contact(World& w, const Indenter& ind, double t) {
  const IndenterPose pose = indenter_pose(ind, t);
  IntegratorScratch& s = w.scratch;
  const ContactInputs in{s.sx.data(), s.sy.data(), s.sz.data(), s.svx.data(), s.svy.data(), s.svz.data(),
                         w.nodes.mass.data()};
  parallel_chunks(w.nodes.count, kNodeChunk, [&](std::size_t b, std::size_t e, std::size_t) {
    add_contact_forces(b, e, ind, pose, in, s.fx.data(), s.fy.data(), s.fz.data());
  });
}

double indenter_force(const World& w) {
  const std::optional<Indenter> ind = make_indenter(w);
  if (!ind) return 0.0;
  const NodeStore& n = w.nodes;
  const IndenterPose pose = indenter_pose(*ind, w.time);
  double total = 0.0;
  for (std::size_t i = 0; i < n.count; ++i) {
    if (n.free_mask[i] == 0.0f) continue;  // clamped nodes: the clamp takes their push
    // The node is pushed down (−z); the indenter is pushed back up.
    total -= node_contact_force(*ind, pose, n.px[i], n.py[i], n.pz[i], n.vx[i], n.vy[i], n.vz[i], n.mass[i])[2];
  }
  return total;
}

}  // namespace papertear
