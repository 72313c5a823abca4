// The per-node half of classic 4th-order Runge–Kutta (the paper's integrator, MODEL.md §4).
//
// The state is y = (p, v) with dp/dt = v and dv/dt = a(p, v). Stage s (1..4) evaluates
// forces at the stage state (sp, sv) — done by the force kernels — then this kernel:
//   a    = free * (F / m + g - drag * sv)          (free = 0 for gripped nodes: a = 0)
//   acc  = s == 1 ? (sv, a) : acc + 2 (sv, a)     (the RK4 weights 1, 2, 2, 1)
//   next stage state: p + h sv, v + h a with h = dt/2, dt/2, dt after stages 1, 2, 3;
//   after stage 4: p += dt/6 (accp + sv), v += dt/6 (accv + a), and (sp, sv) = (p, v).
// It also clears F for the next stage. Each node is read and written only by the lane that
// owns it, so the kernel is race-free and the same on any partition.
#pragma once
#include <cstddef>
#include <cstdint>

#include "core/world.hpp"

namespace papertear {

struct StageParams {
  int stage = 1;  // 1..4
  float dt = 0.0f;
  float gravity[3] = {0.0f, 0.0f, 0.0f};
  float drag = 0.0f;
  float blowup_limit = 1e6f;  // |p| or |v| beyond this counts as a blow-up
};

// Runs one stage on nodes [begin, end). After stage 4, returns the first node in the range
// whose new position or velocity is non-finite or beyond the blow-up limit, or UINT32_MAX.
std::uint32_t rk4_stage(std::size_t begin, std::size_t end, const StageParams& params,
                        NodeStore& nodes, IntegratorScratch& scratch);
std::uint32_t rk4_stage_scalar(std::size_t begin, std::size_t end, const StageParams& params,
                               NodeStore& nodes, IntegratorScratch& scratch);

}  // namespace papertear
