// The largest stable time step of explicit RK4 on this lattice (MODEL.md §4).
//
// Linearised, the system is M ẍ + C ẋ + K x = 0. By block Gershgorin on M⁻¹K (each spring
// contributes k d̂d̂ᵀ, of norm k, to its two nodes' diagonal blocks and off-diagonal block)
// every eigenvalue satisfies λ_K ≤ max_n 2 Σk_n / m_n; likewise λ_C ≤ max_n 2 Σc_n / m_n + drag.
// A mode's RK4 eigenvalue μ solves μ² + c μ + k = 0 with c ≤ λ_C, k ≤ λ_K, so
// |μ| ≤ (λ_C + sqrt(λ_C² + 4 λ_K)) / 2. RK4 is stable for dt |μ| inside its stability region,
// which contains the left half-disc of radius 2.5 (it reaches 2.83 on the imaginary axis and
// 2.79 on the real axis), hence dt_max = 2.5 / |μ|max.
#pragma once
#include "core/world.hpp"

namespace papertear {

inline constexpr double kRk4StabilityRadius = 2.5;

double stable_dt_limit(const World& world);

// The step a run uses: run.dt if set (refused with SceneError when above the limit),
// otherwise the limit times run.dt_safety.
double choose_dt(const World& world);

}  // namespace papertear
