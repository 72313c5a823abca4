// The fine-spring kernel's force of W springs at once (kernels/cell_forces.hpp states the
// model). In a header of its own so that the benchmark's spring probe
// (bench/probe_bench.cpp, probe/spring) times the very arithmetic the kernel does per spring.
#pragma once
#include "kernels/lanes.hpp"

namespace papertear {

// The force of W springs from their end values (pa: the a ends' x, y, z, vx, vy, vz; pb: the
// b ends'), count n, stiffness factor s (kScaled; otherwise k = K and c = C, the same bits
// as 1 * K and 1 * C). L and 1 / L^2 both start from L^2 = d · d, so that the square root and
// the division overlap (1 / L is L / L^2): the loop waits on this chain more than on anything
// else, and the version dividing by L after the square root was ~7 % slower (Zen 3).
// Besides the square root and the division, 28 operations per lane (no FMA: the build uses
// -ffp-contract=off): 6 differences, 5 for L^2, 14 for g, 3 for f (kScaled: 2 more).
template <class V, bool kScaled>
[[gnu::always_inline]] inline void spring_force(const V (&pa)[6], const V (&pb)[6], const V& n, const V& s, const V& vk,
                                                const V& vc, const V& rest, V (&f)[3]) {
  using T = lanes::Traits<V>;
  const V dx = pb[0] - pa[0], dy = pb[1] - pa[1], dz = pb[2] - pa[2];
  const V du = pb[3] - pa[3], dv = pb[4] - pa[4], dw = pb[5] - pa[5];
  const V d2 = dx * dx + dy * dy + dz * dz;
  const V len = T::sqrt(d2), r2 = V(1.0f) / d2;
  V k = vk, c = vc;
  if constexpr (kScaled) {
    k = s * vk;
    c = s * vc;
  }
  const V g = ((k * n) * (len - rest)) * (len * r2) + ((c * n) * (du * dx + dv * dy + dw * dz)) * r2;
  f[0] = g * dx;
  f[1] = g * dy;
  f[2] = g * dz;
}

}  // namespace papertear
