#include "core/timestep.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <sstream>
#include <vector>

#include "core/contact.hpp"

namespace papertear {

namespace {

// λ_K: the Gershgorin bound on the eigenvalues of M⁻¹K.
double stiffness_bound(const World& w) {
  std::vector<double> ksum(w.nodes.count, 0.0);
  const std::size_t cells = std::size_t(w.topo.dims.cells());
  for (std::size_t c = 0; c < cells; ++c)
    for (int s = 0; s < kSpringsPerCell; ++s) {
      const SpringSlot& slot = kSpringSlots[std::size_t(s)];
      const double k = double(w.topo.cell_scale[c]) * w.springs.stiffness[std::size_t(s)];
      ksum[w.topo.node(std::uint32_t(c), slot.a)] += k;
      ksum[w.topo.node(std::uint32_t(c), slot.b)] += k;
    }
  for (std::size_t i = 0; i < w.coarse.size(); ++i) {
    ksum[w.topo.node(w.coarse.cell_a[i], w.coarse.corner_a[i])] += w.coarse.stiffness[i];
    ksum[w.topo.node(w.coarse.cell_b[i], w.coarse.corner_b[i])] += w.coarse.stiffness[i];
  }
  double bound = 0.0;
  for (std::size_t n = 0; n < w.nodes.count; ++n)
    if (w.nodes.mass[n] > 0.0f) bound = std::max(bound, 2.0 * ksum[n] / w.nodes.mass[n]);
  // An indenter's penalty (core/contact.hpp) adds its stiffness per unit mass to every
  // node's own diagonal block of M⁻¹K: the indenter is rigid, so no off-diagonal block.
  if (const std::optional<Indenter> indenter = make_indenter(w)) bound += indenter->stiffness;
  return bound;
}

bool rk4_stable(std::complex<double> z) {
  const std::complex<double> r = 1.0 + z * (1.0 + z * (0.5 + z * (1.0 / 6.0 + z / 24.0)));
  return std::abs(r) <= 1.0 + 1e-12;
}

// Whether every mode with ω² in [0, lambda] is stable at step dt.
bool all_modes_stable(double dt, double lambda, double damping, double drag) {
  constexpr int kSamples = 2048;
  for (int i = 0; i <= kSamples; ++i) {
    const double t = double(i) / kSamples;
    const double w2 = lambda * t * t;  // denser near 0, where drag matters
    const double b = damping * w2 + drag;
    const std::complex<double> root = std::sqrt(std::complex<double>(b * b - 4.0 * w2, 0.0));
    if (!rk4_stable(dt * 0.5 * (-b + root)) || !rk4_stable(dt * 0.5 * (-b - root))) return false;
  }
  return true;
}

}  // namespace

double stable_dt_limit(const World& w) {
  const double lambda = stiffness_bound(w);
  const double damping = w.scene.material.damping, drag = w.scene.world.drag;
  if (lambda == 0.0 && drag == 0.0) return INFINITY;
  // |μ| ≤ (b + sqrt(b² + 4 ω²)) / 2 and RK4 is unstable beyond |z| = 2.9, so this dt is not.
  const double b = damping * lambda + drag;
  double lo = 0.0, hi = 2.9 * 2.0 / (b + std::sqrt(b * b + 4.0 * lambda)) * 4.0;
  while (all_modes_stable(hi, lambda, damping, drag)) hi *= 2.0;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (all_modes_stable(mid, lambda, damping, drag) ? lo : hi) = mid;
  }
  return lo;
}

double in_plane_wave_speed(const MaterialParams& m) { return std::sqrt(std::min(m.E_md, m.E_cd) / m.density); }

namespace {

// A load at a tenth of the wave speed already tears the sheet as a shock front, not as paper
// being pulled (the defaults pull at 2 %); far above it the lattice cannot carry it at all.
constexpr double kFastLoad = 0.1;
// A penalty contact this many times the stiffest spring dominates the step's stability.
constexpr double kStiffContact = 100.0;
// At this share of the stable limit RK4's damping of the stiffest modes is nearly gone.
constexpr double kStepNearLimit = 0.8;

}  // namespace

std::string blow_up_cause(const World& w) {
  const LoadParams& l = w.scene.load;
  const double c = in_plane_wave_speed(w.scene.material), speed = std::abs(l.speed);
  std::ostringstream out;
  out.precision(3);
  if (l.kind != "none" && speed > kFastLoad * c) {
    out << "likely cause: load.speed " << speed << " mm/µs is " << speed / c
        << " times the sheet's in-plane wave speed " << c
        << " mm/µs, so the load outruns the lattice (keep it below about " << kFastLoad * c << ")";
    return out.str();
  }
  if (l.kind == "pierce" && l.contact_stiffness > kStiffContact) {
    out << "likely cause: load.contact_stiffness " << l.contact_stiffness
        << " is far above the sheet's own stiffness (1 is its stiffest spring; the default is 10)";
    return out.str();
  }
  const double share = w.dt / stable_dt_limit(w);
  if (share > kStepNearLimit) {
    out << "likely cause: the time step, " << 100.0 * share
        << " % of the stable limit (lower run.dt_safety or run.dt)";
    return out.str();
  }
  out << "no input stands out (load.speed is " << 100.0 * speed / c << " % of the wave speed, the step "
      << 100.0 * share << " % of the stable limit): try a smaller run.dt_safety";
  return out.str();
}

double choose_dt(const World& w) {
  const double limit = stable_dt_limit(w);
  const double dt = w.scene.run.dt;
  if (dt > 0.0) {
    if (dt > limit) {
      std::ostringstream msg;
      msg << "run.dt: " << dt << " is above the stable limit " << limit
          << " for this lattice and material (use a smaller step or run.dt = \"auto\")";
      throw SceneError(msg.str());
    }
    return dt;
  }
  return limit * w.scene.run.dt_safety;
}

}  // namespace papertear
