// The largest stable time step of explicit RK4 on this lattice (MODEL.md §4).
//
// Linearised, the system is M ẍ + C ẋ + K x = 0. Every spring, fine or block, has damping
// c = d·k (d = material.damping), so C = d·K + drag·M, and a mode of M⁻¹K with eigenvalue
// ω² evolves with the roots μ of   μ² + (d ω² + drag) μ + ω² = 0.
// By block Gershgorin on M⁻¹K (a spring adds k d̂d̂ᵀ, of norm k, to its nodes' diagonal
// blocks and to their off-diagonal block), every ω² ≤ λ_K = max_n 2 Σk_n / m_n; a pierce
// load's penalty contact (per unit mass, damped like a spring) adds its stiffness to λ_K.
// RK4 multiplies a mode by R(z) = 1 + z + z²/2 + z³/6 + z⁴/24 with z = dt μ per step, so dt
// is stable when |R(dt μ)| ≤ 1 for both roots at every ω² in [0, λ_K]. The limit is found by
// bisection on dt, checking ω² on a fine grid. (Checking the roots against the exact RK4
// region matters: a disc-shaped bound would halve the step whenever damping is on.)
#pragma once
#include <string>

#include "core/world.hpp"

namespace papertear {

double stable_dt_limit(const World& world);

// The step a run uses: run.dt if set (refused with SceneError when above the limit),
// otherwise the limit times run.dt_safety.
double choose_dt(const World& world);

// The slower of the sheet's two in-plane longitudinal wave speeds, sqrt(E / density) with E
// the smaller of E_md and E_cd, in mm/µs (MPa over kg/m³ gives (mm/µs)² exactly).
double in_plane_wave_speed(const MaterialParams& material);

// For a run that diverged: which input most likely made it, as one clause for the error
// line ("likely cause: ..."). It weighs a load faster than the sheet's waves, a penalty
// contact far stiffer than the sheet, and a step near the stable limit, in that order: the
// step is stable by construction (choose_dt), so a blow-up at a safe step is the load's.
std::string blow_up_cause(const World& world);

}  // namespace papertear
