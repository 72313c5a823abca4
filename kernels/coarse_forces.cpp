#include "kernels/coarse_forces.hpp"

#include "kernels/spring.hpp"

namespace papertear {

void coarse_spring_forces(std::size_t begin, std::size_t end, const CoarseSprings& sp,
                          const Topology& topo, const CellForceInputs& in, CoarseForceScratch& out) {
  for (std::size_t i = begin; i < end; ++i) {
    if (sp.stiffness[i] == 0.0f && sp.damping[i] == 0.0f) {
      out.fx[i] = out.fy[i] = out.fz[i] = 0.0f;
      continue;
    }
    const std::uint32_t a = topo.node(sp.cell_a[i], sp.corner_a[i]);
    const std::uint32_t b = topo.node(sp.cell_b[i], sp.corner_b[i]);
    const SpringEval e = eval_spring(in.px[a], in.py[a], in.pz[a], in.px[b], in.py[b], in.pz[b],
                                     in.vx[a], in.vy[a], in.vz[a], in.vx[b], in.vy[b], in.vz[b],
                                     sp.rest[i], sp.stiffness[i], sp.damping[i]);
    out.fx[i] = e.fx;
    out.fy[i] = e.fy;
    out.fz[i] = e.fz;
  }
}

void scatter_coarse_forces(const CoarseSprings& sp, const Topology& topo,
                           const CoarseForceScratch& f, const ForceOutputs& out) {
  for (std::size_t i = 0; i < sp.size(); ++i) {
    const std::uint32_t a = topo.node(sp.cell_a[i], sp.corner_a[i]);
    const std::uint32_t b = topo.node(sp.cell_b[i], sp.corner_b[i]);
    out.fx[a] += f.fx[i]; out.fy[a] += f.fy[i]; out.fz[a] += f.fz[i];
    out.fx[b] -= f.fx[i]; out.fy[b] -= f.fy[i]; out.fz[b] -= f.fz[i];
  }
}

}  // namespace papertear
