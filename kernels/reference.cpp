// The reference model (kernels/reference.hpp): deliberately the plainest code that computes
// the elastic model — one explicit spring list, a force loop over it, and textbook RK4 on
// whole-state vectors. Everything is double precision, so its rounding error is far below
// the float solver's and the tests can treat it as the exact answer of the same equations.
#include "kernels/reference.hpp"

#include <cmath>
#include <cstddef>

#include "core/lattice_builder.hpp"

namespace papertear {
namespace {

using Vec3 = std::array<double, 3>;

Vec3 axpy(const Vec3& y, double a, const Vec3& x) {
  return {y[0] + a * x[0], y[1] + a * x[1], y[2] + a * x[2]};
}

double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

Vec3 minus(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }

}  // namespace

ReferenceModel::ReferenceModel(const World& world)
    : load_(world.scene.load),
      gravity_(world.scene.world.gravity),
      drag_(world.scene.world.drag),
      dt_(world.dt),
      time_(world.time) {
  const NodeStore& n = world.nodes;
  nodes_.resize(n.count);
  for (std::size_t i = 0; i < n.count; ++i) {
    nodes_[i] = Node{{n.px[i], n.py[i], n.pz[i]}, {n.vx[i], n.vy[i], n.vz[i]}, n.mass[i],
                     n.grip[i] == 0, n.grip[i]};
  }
  for (const Grip& g : world.grips)
    grip_velocity_.push_back({g.velocity[0], g.velocity[1], g.velocity[2]});

  // Every cell's own 28 springs, scaled by the cell's factor (MODEL.md §4).
  const Topology& t = world.topo;
  const SpringTable& tab = world.springs;
  const std::size_t cells = std::size_t(t.dims.cells());
  for (std::size_t c = 0; c < cells; ++c) {
    const double scale = t.cell_scale[c];
    for (std::size_t s = 0; s < kSpringSlots.size(); ++s) {
      const SpringSlot& slot = kSpringSlots[s];
      add_spring(t.node(std::uint32_t(c), slot.a), t.node(std::uint32_t(c), slot.b), tab.rest[s],
                 scale * tab.stiffness[s], scale * tab.damping[s]);
    }
  }
  // Block-lattice springs; those of blocks a crack has entered are zeroed and skipped.
  const CoarseSprings& cs = world.coarse;
  for (std::size_t i = 0; i < cs.size(); ++i) {
    if (cs.stiffness[i] == 0.0f && cs.damping[i] == 0.0f) continue;
    add_spring(t.node(cs.cell_a[i], cs.corner_a[i]), t.node(cs.cell_b[i], cs.corner_b[i]),
               cs.rest[i], cs.stiffness[i], cs.damping[i]);
  }
}

void ReferenceModel::add_spring(std::uint32_t a, std::uint32_t b, double rest, double k, double c) {
  springs_.push_back(Spring{a, b, rest, k, c});
}

void ReferenceModel::set_grip_velocities() {
  const double ramp = grip_ramp(load_, time_);
  for (Node& n : nodes_) {
    if (n.grip == 0) continue;
    const Vec3& g = grip_velocity_.at(std::size_t(n.grip) - 1);
    n.v = {g[0] * ramp, g[1] * ramp, g[2] * ramp};
  }
}

void ReferenceModel::read_state(State& out) const {
  out.p.resize(nodes_.size());
  out.v.resize(nodes_.size());
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    out.p[i] = nodes_[i].p;
    out.v[i] = nodes_[i].v;
  }
}

void ReferenceModel::add_spring_forces(const State& s, std::vector<Vec3>& f) const {
  for (const Spring& sp : springs_) {
    // f_a = (k (L - L0) + c (Δv·d)/L) d/L, f_b = -f_a.
    const Vec3 d = minus(s.p[sp.b], s.p[sp.a]);
    const double len = std::sqrt(dot(d, d));
    const double rate = dot(minus(s.v[sp.b], s.v[sp.a]), d) / len;
    const double g = (sp.k * (len - sp.rest) + sp.c * rate) / len;
    f[sp.a] = axpy(f[sp.a], g, d);
    f[sp.b] = axpy(f[sp.b], -g, d);
  }
}

// (dp/dt, dv/dt) at s: dp/dt = v; dv/dt = F/m + g - drag v for free nodes, 0 for gripped
// ones (they keep the velocity set at the start of the step).
void ReferenceModel::rates_at(const State& s, State& out) const {
  out.p = s.v;
  out.v.assign(nodes_.size(), Vec3{0.0, 0.0, 0.0});
  add_spring_forces(s, out.v);
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    Vec3& a = out.v[i];
    if (!nodes_[i].free) {
      a = {0.0, 0.0, 0.0};
      continue;
    }
    for (std::size_t x = 0; x < 3; ++x) a[x] = a[x] / nodes_[i].mass + gravity_[x] - drag_ * s.v[i][x];
  }
}

void ReferenceModel::advance(const State& y, double h, const State& rate, State& out) {
  out.p.resize(y.p.size());
  out.v.resize(y.v.size());
  for (std::size_t i = 0; i < y.p.size(); ++i) {
    out.p[i] = axpy(y.p[i], h, rate.p[i]);
    out.v[i] = axpy(y.v[i], h, rate.v[i]);
  }
}

void ReferenceModel::step(int n) {
  for (int s = 0; s < n; ++s) {
    set_grip_velocities();
    // Classic RK4: k1..k4 at t, t + h/2, t + h/2, t + h; y += h/6 (k1 + 2 k2 + 2 k3 + k4).
    read_state(y_);
    rates_at(y_, k_[0]);
    advance(y_, 0.5 * dt_, k_[0], stage_);
    rates_at(stage_, k_[1]);
    advance(y_, 0.5 * dt_, k_[1], stage_);
    rates_at(stage_, k_[2]);
    advance(y_, dt_, k_[2], stage_);
    rates_at(stage_, k_[3]);
    for (std::size_t i = 0; i < nodes_.size(); ++i)
      for (std::size_t a = 0; a < 3; ++a) {
        nodes_[i].p[a] += dt_ / 6.0 * (k_[0].p[i][a] + 2.0 * k_[1].p[i][a] + 2.0 * k_[2].p[i][a] + k_[3].p[i][a]);
        nodes_[i].v[a] += dt_ / 6.0 * (k_[0].v[i][a] + 2.0 * k_[1].v[i][a] + 2.0 * k_[2].v[i][a] + k_[3].v[i][a]);
      }
    time_ += dt_;
  }
}

std::vector<std::array<double, 3>> ReferenceModel::spring_forces() const {
  State s;
  read_state(s);
  std::vector<Vec3> f(nodes_.size(), Vec3{0.0, 0.0, 0.0});
  add_spring_forces(s, f);
  return f;
}

double ReferenceModel::kinetic_energy() const {
  double e = 0.0;
  for (const Node& n : nodes_) e += 0.5 * n.mass * dot(n.v, n.v);
  return e;
}

double ReferenceModel::elastic_energy() const {
  double e = 0.0;
  for (const Spring& sp : springs_) {
    const Vec3 d = minus(nodes_[sp.b].p, nodes_[sp.a].p);
    const double stretch = std::sqrt(dot(d, d)) - sp.rest;
    e += 0.5 * sp.k * stretch * stretch;
  }
  return e;
}

}  // namespace papertear
