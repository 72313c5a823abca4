#include "kernels/rk4.hpp"

#include <limits>

#include "kernels/cell_forces.hpp"
#include "kernels/lanes.hpp"

namespace papertear {
namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

template <class V>
struct StageLanes {
  using T = lanes::Traits<V>;
  static constexpr std::size_t W = T::width;

  // One RK4 component for one axis: position column p, velocity v, stage sp, sv, sums
  // accp, accv, force f. Returns true when the new values stay finite and bounded.
  static bool axis(std::size_t i, const StageParams& P, float g, float* p, float* v, float* sp,
                   float* sv, float* accp, float* accv, float* f, const V& inv_m, const V& free) {
    const V svi = T::load(sv + i);
    const V a = free * (T::load(f + i) * inv_m + T::broadcast(g) - T::broadcast(P.drag) * svi);
    T::store(f + i, T::broadcast(0.0f));
    const V two = T::broadcast(2.0f);
    switch (P.stage) {
      case 1:
      case 2:
      case 3: {
        const V h = T::broadcast(P.stage == 3 ? P.dt : 0.5f * P.dt);
        if (P.stage == 1) {
          T::store(accp + i, svi);
          T::store(accv + i, a);
        } else {
          T::store(accp + i, T::load(accp + i) + two * svi);
          T::store(accv + i, T::load(accv + i) + two * a);
        }
        T::store(sp + i, T::load(p + i) + h * svi);
        T::store(sv + i, T::load(v + i) + h * a);
        return true;
      }
      default: {
        const V h6 = T::broadcast(P.dt / 6.0f);
        const V pn = T::load(p + i) + h6 * (T::load(accp + i) + svi);
        const V vn = T::load(v + i) + h6 * (T::load(accv + i) + a);
        T::store(p + i, pn);
        T::store(v + i, vn);
        T::store(sp + i, pn);
        T::store(sv + i, vn);
        return T::all_within(pn, P.blowup_limit) && T::all_within(vn, P.blowup_limit);
      }
    }
  }

  // Returns true when all W nodes at i stay finite and bounded.
  static bool run(std::size_t i, const StageParams& P, NodeStore& n, IntegratorScratch& s) {
    const V inv_m = T::load(n.inv_mass.data() + i);
    const V free = T::load(n.free_mask.data() + i);
    bool ok = axis(i, P, P.gravity[0], n.px.data(), n.vx.data(), s.sx.data(), s.svx.data(),
                   s.ax.data(), s.avx.data(), s.fx.data(), inv_m, free);
    ok &= axis(i, P, P.gravity[1], n.py.data(), n.vy.data(), s.sy.data(), s.svy.data(),
               s.ay.data(), s.avy.data(), s.fy.data(), inv_m, free);
    ok &= axis(i, P, P.gravity[2], n.pz.data(), n.vz.data(), s.sz.data(), s.svz.data(),
               s.az.data(), s.avz.data(), s.fz.data(), inv_m, free);
    return ok;
  }
};

// The first node of [i, i + W) whose state is out of bounds (scanned one by one).
std::uint32_t first_bad(std::size_t i, std::size_t w, const NodeStore& n, float limit) {
  for (std::size_t j = i; j < i + w; ++j) {
    const float vals[6] = {n.px[j], n.py[j], n.pz[j], n.vx[j], n.vy[j], n.vz[j]};
    for (float x : vals)
      if (!(std::fabs(x) < limit)) return std::uint32_t(j);
  }
  return kNone;
}

template <class V>
std::uint32_t stage_with(std::size_t begin, std::size_t end, const StageParams& P, NodeStore& n,
                         IntegratorScratch& s) {
  constexpr std::size_t W = StageLanes<V>::W;
  std::uint32_t bad = kNone;
  std::size_t i = begin;
  // Columns are aligned, so vector loads are from the first multiple of the width on; the
  // nodes before it (a run of a band starts at a row) go one by one, with the same operations.
  for (; i < end && i % W != 0; ++i)
    if (!StageLanes<float>::run(i, P, n, s) && bad == kNone) bad = std::uint32_t(i);
  for (; i + W <= end; i += W)
    if (!StageLanes<V>::run(i, P, n, s) && bad == kNone) bad = first_bad(i, W, n, P.blowup_limit);
  for (; i < end; ++i)
    if (!StageLanes<float>::run(i, P, n, s) && bad == kNone) bad = std::uint32_t(i);
  return bad;
}

}  // namespace

std::uint32_t rk4_stage(std::size_t begin, std::size_t end, const StageParams& params,
                        NodeStore& nodes, IntegratorScratch& scratch) {
  const FlushSubnormals flush;  // kernels/cell_forces.hpp: the state stays free of subnormals
  return stage_with<lanes::Wide>(begin, end, params, nodes, scratch);
}

std::uint32_t rk4_stage_scalar(std::size_t begin, std::size_t end, const StageParams& params,
                               NodeStore& nodes, IntegratorScratch& scratch) {
  const FlushSubnormals flush;
  return stage_with<float>(begin, end, params, nodes, scratch);
}

}  // namespace papertear
