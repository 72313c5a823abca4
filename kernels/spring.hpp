// One spring's force and energy in scalar code, for the serial and per-spring paths (block
// lattice springs, energies, fracture's force sums). The same model as the fine-spring
// kernel (kernels/cell_forces.hpp), which arranges the arithmetic differently (1 / L as
// L / L^2, so that the square root and the division overlap): the two agree to rounding.
#pragma once
#include <cmath>

namespace papertear {

struct SpringEval {
  float fx, fy, fz;   // force on end a (end b gets the opposite)
  float magnitude;    // |k (L - L0) + c Δv·d̂|
  float length;
};

inline SpringEval eval_spring(float ax, float ay, float az, float bx, float by, float bz,
                              float avx, float avy, float avz, float bvx, float bvy, float bvz,
                              float rest, float k, float c) {
  const float dx = bx - ax, dy = by - ay, dz = bz - az;
  const float len = std::sqrt(dx * dx + dy * dy + dz * dz);
  const float inv = 1.0f / len;
  const float rate = ((bvx - avx) * dx + (bvy - avy) * dy + (bvz - avz) * dz) * inv;
  const float mag = k * (len - rest) + c * rate;
  const float g = mag * inv;
  return {g * dx, g * dy, g * dz, std::fabs(mag), len};
}

}  // namespace papertear
