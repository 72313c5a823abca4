// From paper's orthotropic constants to the lattice's springs (MODEL.md §4).
//
// Units. A scene states the material in published units (moduli in MPa, density in kg/m³)
// and the sheet in lattice units. The lattice's units are: length 1 = 1 mm, stress 1 =
// 1 GPa, density 1 = 1000 kg/m³; hence time 1 = 1 µs, mass 1 = 1 mg, force 1 = 1 kN and
// speed 1 = 1 km/s. A cell of `sheet.cell_size = [1, 1, 0.3]` is 1 × 1 × 0.3 mm.
//
// Springs. Under a homogeneous strain ε a spring of stiffness k, rest length L and direction
// n stores ½ k L² (n·ε·n)², so the 28 springs of a cell of volume V = hx·hy·hz give the
// stiffness tensor C_ijkl = Σ k L² n_i n_j n_k n_l / V. Every cell owns its own springs,
// so that tensor is the lattice's continuum response for any cell shape. With the cell's
// symmetry it is orthotropic in the lattice axes:
//   a face-diagonal family (4 springs on the two faces normal to axis c) alone sets the
//   shear modulus of the plane (a, b): G_ab = 4 k h_a² h_b² / (L² V), and adds G_ab h_a²/h_b²
//   to C_aa and G_ab h_b²/h_a² to C_bb;
//   the edges along axis a add 4 k h_a² / V to C_aa only.
// So the face diagonals are fitted to the three shear moduli and the edges to the three
// Young's moduli (uniaxial stress, 1/S_aa, with the diagonals' Poisson coupling included).
// Body diagonals carry nothing (k = 0): every shear is already set by a face family.
//
// A central-force lattice obeys the Cauchy relations (C12 = C66, C13 = C55, C23 = C44), so
// its Poisson ratios follow from its shear moduli, and a face family whose plane is far
// from square stiffens the long axis by (h_long/h_short)² times its shear. Paper is soft
// in transverse shear and very soft through its thickness (E_ZD ~ E_MD / 150); a family is
// therefore limited so that the diagonals carry at most 3/4 of any Young's modulus (the
// in-plane family first, the transverse ones from what is left). When
// that limit binds, the transverse shear comes out below its target and the fit says so
// (SpringFit::shear_limited; `papertear info` prints what was reached). E_MD, E_CD, E_ZD and
// G_MD-CD are met for cubes and flat cells alike; with paper's constants the transverse
// shears are reached only in part at any cell shape (cubes: the ZD budget binds; flat cells:
// the CD budget). Bending and in-plane tearing of a thin sheet depend little on them.
#pragma once
#include <array>

#include "core/lattice.hpp"
#include "core/scene.hpp"

namespace papertear {

inline constexpr double kMpaPerStressUnit = 1000.0;     // 1 lattice stress unit = 1 GPa
inline constexpr double kKgPerM3PerDensityUnit = 1000.0; // 1 lattice density unit = 1000 kg/m³

// Orthotropic moduli along the lattice axes x, y, z, in lattice stress units.
// shear[0] = G_yz, shear[1] = G_xz, shear[2] = G_xy (the plane normal to axis c).
struct Moduli {
  std::array<double, 3> young{};
  std::array<double, 3> shear{};
};

// The material's target moduli in lattice axes and units: MD along the grain axis.
Moduli target_moduli(const MaterialParams& material);
// Mass per unit volume of the sheet in lattice units.
double lattice_density(const MaterialParams& material);
// One cell's mass.
double cell_mass(const MaterialParams& material, const LatticeDims& dims);

struct SpringFit {
  std::array<double, 3> edge{};  // one cell's edge spring along axis a (the full modulus)
  std::array<double, 3> face{};  // one cell's face diagonal on faces normal to axis c
  double body = 0.0;
  Moduli achieved;                 // the continuum moduli of those springs
  std::array<bool, 3> shear_limited{};  // shear[c] below its target (the limit above)
};

// The springs of one cell for `target` on cells of `dims`' shape.
SpringFit fit_springs(const Moduli& target, const LatticeDims& dims);

// How long a bond on a face normal to axis a must stay over its strength before it fails
// (fracture/fracture_pass.hpp): the time the fastest in-plane wave, the longitudinal one at
// c_L = sqrt(max(E_x, E_y) / ρ), takes to cross one cell. A crack through faces normal to x
// runs along y, so τ_x = hy / c_L and τ_y = hx / c_L; a delamination front runs in the plane
// between layers at the Rayleigh speed c_R ≈ 0.92 √(G/ρ) of that plane,
// τ_z = min(hx / c_R(G_xz), hy / c_R(G_yz)). A stress spike shorter than a wave's crossing
// of the cell cannot break a bond. Why c_L and not c_R in the plane: with c_R the tip waited
// long enough at each vertex for the bonds one cell beside it to gather damage too, and the
// default pull forked into two cracks on one seed in four (README, "Delayed failure").
std::array<double, 3> bond_failure_time(const MaterialParams& material, const LatticeDims& dims);

// The continuum moduli of a cell whose 28 slots have stiffness k[s] (kSpringSlots order).
Moduli moduli_of_springs(const std::array<double, kSpringsPerCell>& k, const LatticeDims& dims);

}  // namespace papertear
