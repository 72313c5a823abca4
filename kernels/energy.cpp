#include "kernels/energy.hpp"

#include <cmath>

namespace papertear {
namespace {

double spring_energy(const NodeStore& n, std::uint32_t a, std::uint32_t b, double rest, double k) {
  const double dx = double(n.px[b]) - n.px[a], dy = double(n.py[b]) - n.py[a],
               dz = double(n.pz[b]) - n.pz[a];
  const double stretch = std::sqrt(dx * dx + dy * dy + dz * dz) - rest;
  return 0.5 * k * stretch * stretch;
}

}  // namespace

double kinetic_energy(std::size_t begin, std::size_t end, const NodeStore& n) {
  double e = 0.0;
  for (std::size_t i = begin; i < end; ++i) {
    const double v2 = double(n.vx[i]) * n.vx[i] + double(n.vy[i]) * n.vy[i] + double(n.vz[i]) * n.vz[i];
    e += 0.5 * double(n.mass[i]) * v2;
  }
  return e;
}

double cell_elastic_energy(std::size_t begin, std::size_t end, const World& w) {
  double e = 0.0;
  for (std::size_t c = begin; c < end; ++c) {
    const double scale = w.topo.cell_scale[c];
    for (int s = 0; s < kSpringsPerCell; ++s) {
      const SpringSlot& slot = kSpringSlots[std::size_t(s)];
      e += spring_energy(w.nodes, w.topo.node(std::uint32_t(c), slot.a),
                         w.topo.node(std::uint32_t(c), slot.b), w.springs.rest[std::size_t(s)],
                         scale * w.springs.stiffness[std::size_t(s)]);
    }
  }
  return e;
}

double coarse_elastic_energy(std::size_t begin, std::size_t end, const World& w) {
  double e = 0.0;
  const CoarseSprings& sp = w.coarse;
  for (std::size_t i = begin; i < end; ++i) {
    if (sp.stiffness[i] == 0.0f) continue;
    e += spring_energy(w.nodes, w.topo.node(sp.cell_a[i], sp.corner_a[i]),
                       w.topo.node(sp.cell_b[i], sp.corner_b[i]), sp.rest[i], sp.stiffness[i]);
  }
  return e;
}

}  // namespace papertear
