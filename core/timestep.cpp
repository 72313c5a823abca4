#include "core/timestep.hpp"

#include <cmath>
#include <sstream>
#include <vector>

namespace papertear {

double stable_dt_limit(const World& w) {
  std::vector<double> ksum(w.nodes.count, 0.0), csum(w.nodes.count, 0.0);
  const std::size_t cells = std::size_t(w.topo.dims.cells());
  for (std::size_t c = 0; c < cells; ++c)
    for (int s = 0; s < kSpringsPerCell; ++s) {
      const SpringSlot& slot = kSpringSlots[std::size_t(s)];
      const double k = double(w.topo.cell_scale[c]) * w.springs.stiffness[std::size_t(s)];
      const double cd = double(w.topo.cell_scale[c]) * w.springs.damping[std::size_t(s)];
      for (std::uint8_t q : {slot.a, slot.b}) {
        const std::uint32_t n = w.topo.node(std::uint32_t(c), q);
        ksum[n] += k;
        csum[n] += cd;
      }
    }
  for (std::size_t i = 0; i < w.coarse.size(); ++i)
    for (auto [cell, corner] : {std::pair{w.coarse.cell_a[i], w.coarse.corner_a[i]},
                                std::pair{w.coarse.cell_b[i], w.coarse.corner_b[i]}}) {
      const std::uint32_t n = w.topo.node(cell, corner);
      ksum[n] += w.coarse.stiffness[i];
      csum[n] += w.coarse.damping[i];
    }
  double mu_max = 0.0;
  for (std::size_t n = 0; n < w.nodes.count; ++n) {
    if (w.nodes.mass[n] <= 0.0f) continue;
    const double m = w.nodes.mass[n];
    const double lk = 2.0 * ksum[n] / m;
    const double lc = 2.0 * csum[n] / m + w.scene.world.drag;
    mu_max = std::max(mu_max, 0.5 * (lc + std::sqrt(lc * lc + 4.0 * lk)));
  }
  return mu_max > 0.0 ? kRk4StabilityRadius / mu_max : INFINITY;
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
