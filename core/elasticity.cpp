#include "core/elasticity.hpp"

#include <algorithm>
#include <cmath>
#include <initializer_list>

namespace papertear {

Moduli target_moduli(const MaterialParams& m) {
  const double s = 1.0 / kMpaPerStressUnit;
  const bool md_x = m.grain != 'y';
  Moduli t;
  t.young = {(md_x ? m.E_md : m.E_cd) * s, (md_x ? m.E_cd : m.E_md) * s, m.E_zd * s};
  // shear[0] is the plane (y, z), shear[1] the plane (x, z).
  t.shear = {(md_x ? m.G_cd_zd : m.G_md_zd) * s, (md_x ? m.G_md_zd : m.G_cd_zd) * s, m.G_md_cd * s};
  return t;
}

double lattice_density(const MaterialParams& m) { return m.density / kKgPerM3PerDensityUnit; }

double cell_mass(const MaterialParams& m, const LatticeDims& d) {
  return lattice_density(m) * d.hx * d.hy * d.hz;
}

namespace {

using Mat3 = std::array<std::array<double, 3>, 3>;

// The in-plane axes (a, b) of the faces normal to axis c, a < b.
std::array<int, 2> plane_axes(int c) { return c == 0 ? std::array{1, 2} : c == 1 ? std::array{0, 2} : std::array{0, 1}; }

// The normal-stress block of the diagonals' tensor: D[a][a] and D[a][b] (= the shear, Cauchy).
Mat3 diagonal_block(const std::array<double, 3>& shear, const double (&h)[3]) {
  Mat3 d{};
  for (int c = 0; c < 3; ++c) {
    const auto [a, b] = plane_axes(c);
    const double g = shear[std::size_t(c)];
    d[a][a] += g * h[a] * h[a] / (h[b] * h[b]);
    d[b][b] += g * h[b] * h[b] / (h[a] * h[a]);
    d[a][b] += g;
    d[b][a] += g;
  }
  return d;
}

// Young's moduli 1/S_aa of the normal block C.
std::array<double, 3> young_of(const Mat3& c) {
  const double det = c[0][0] * (c[1][1] * c[2][2] - c[1][2] * c[2][1]) -
                     c[0][1] * (c[1][0] * c[2][2] - c[1][2] * c[2][0]) +
                     c[0][2] * (c[1][0] * c[2][1] - c[1][1] * c[2][0]);
  const double cof[3] = {c[1][1] * c[2][2] - c[1][2] * c[2][1], c[0][0] * c[2][2] - c[0][2] * c[2][0],
                         c[0][0] * c[1][1] - c[0][1] * c[1][0]};
  return {det / cof[0], det / cof[1], det / cof[2]};
}

// The shears the diagonals may carry: together they may carry at most kDiagonalShare of
// every Young's modulus (the Cauchy limit in the header). The in-plane family comes first;
// the two transverse ones then share what is left, scaled down by one common factor.
std::array<double, 3> limited_shear(const Moduli& t, const double (&h)[3]) {
  constexpr double kDiagonalShare = 0.75;
  std::array<double, 3> used{};
  std::array<double, 3> shear = t.shear;
  auto adds = [&](int c, double g) {  // what family c at shear g adds to each C_aa
    std::array<double, 3> out{};
    const auto [a, b] = plane_axes(c);
    out[std::size_t(a)] = g * h[a] * h[a] / (h[b] * h[b]);
    out[std::size_t(b)] = g * h[b] * h[b] / (h[a] * h[a]);
    return out;
  };
  auto scale_group = [&](std::initializer_list<int> group) {
    std::array<double, 3> total{};
    for (int c : group)
      for (int a = 0; a < 3; ++a) total[std::size_t(a)] += adds(c, t.shear[std::size_t(c)])[std::size_t(a)];
    double f = 1.0;
    for (int a = 0; a < 3; ++a)
      if (total[std::size_t(a)] > 0.0)
        f = std::min(f, std::max(kDiagonalShare * t.young[std::size_t(a)] - used[std::size_t(a)], 0.0) / total[std::size_t(a)]);
    for (int c : group) shear[std::size_t(c)] = f * t.shear[std::size_t(c)];
    for (int a = 0; a < 3; ++a) used[std::size_t(a)] += f * total[std::size_t(a)];
  };
  scale_group({2});
  scale_group({1, 0});
  return shear;
}

}  // namespace

SpringFit fit_springs(const Moduli& t, const LatticeDims& dims) {
  const double h[3] = {dims.hx, dims.hy, dims.hz};
  const double volume = h[0] * h[1] * h[2];
  SpringFit fit;
  const std::array<double, 3> shear = limited_shear(t, h);
  for (int c = 0; c < 3; ++c) {
    const auto [a, b] = plane_axes(c);
    const double len2 = h[a] * h[a] + h[b] * h[b];
    fit.face[std::size_t(c)] = shear[std::size_t(c)] * volume * len2 / (4.0 * h[a] * h[a] * h[b] * h[b]);
    fit.shear_limited[std::size_t(c)] = shear[std::size_t(c)] < t.shear[std::size_t(c)] * (1.0 - 1e-12);
  }
  // Edges: C_aa = e_a + D_aa; Newton-like steps on e until 1/S_aa meets the target (each
  // E_a rises with e_a at a slope just below 1, so the steps converge quickly).
  const Mat3 d = diagonal_block(shear, h);
  std::array<double, 3> e{};
  for (int a = 0; a < 3; ++a) e[std::size_t(a)] = std::max(t.young[std::size_t(a)] - d[a][a], 0.0);
  for (int iter = 0; iter < 200; ++iter) {
    Mat3 c = d;
    for (int a = 0; a < 3; ++a) c[a][a] += e[std::size_t(a)];
    const std::array<double, 3> young = young_of(c);
    double worst = 0.0;
    for (int a = 0; a < 3; ++a) {
      const double miss = t.young[std::size_t(a)] - young[std::size_t(a)];
      worst = std::max(worst, std::abs(miss) / t.young[std::size_t(a)]);
      e[std::size_t(a)] = std::max(e[std::size_t(a)] + miss, 1e-6 * t.young[std::size_t(a)]);
    }
    if (worst < 1e-12) break;
  }
  for (int a = 0; a < 3; ++a) fit.edge[std::size_t(a)] = e[std::size_t(a)] * volume / (4.0 * h[a] * h[a]);
  std::array<double, kSpringsPerCell> k{};
  for (int s = 0; s < kSpringsPerCell; ++s) {
    const SpringSlot& slot = kSpringSlots[std::size_t(s)];
    k[std::size_t(s)] = slot.family == SpringFamily::Edge ? fit.edge[slot.axis]
                        : slot.family == SpringFamily::Face ? fit.face[slot.axis] : fit.body;
  }
  fit.achieved = moduli_of_springs(k, dims);
  return fit;
}

std::array<double, 3> bond_failure_time(const MaterialParams& m, const LatticeDims& d) {
  const Moduli g = fit_springs(target_moduli(m), d).achieved;
  const double rho = lattice_density(m);
  auto rayleigh = [rho](double shear) { return 0.92 * std::sqrt(shear / rho); };
  // In the plane: the faster of the two in-plane longitudinal waves (core/elasticity.hpp).
  const double in_plane = std::sqrt(std::max(g.young[0], g.young[1]) / rho);
  return {d.hy / in_plane, d.hx / in_plane, std::min(d.hx / rayleigh(g.shear[1]), d.hy / rayleigh(g.shear[0]))};
}

Moduli moduli_of_springs(const std::array<double, kSpringsPerCell>& k, const LatticeDims& dims) {
  const double h[3] = {dims.hx, dims.hy, dims.hz};
  const double volume = h[0] * h[1] * h[2];
  Mat3 c{};  // C_aabb
  std::array<double, 3> shear{};
  for (int s = 0; s < kSpringsPerCell; ++s) {
    const SpringSlot& slot = kSpringSlots[std::size_t(s)];
    double d[3], len2 = 0.0;
    for (int a = 0; a < 3; ++a) {
      d[a] = corner_bit(slot.a, a) != corner_bit(slot.b, a) ? h[a] : 0.0;
      len2 += d[a] * d[a];
    }
    // k L² n_a² n_b² = k d_a² d_b² / L²
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) c[a][b] += k[std::size_t(s)] * d[a] * d[a] * d[b] * d[b] / len2 / volume;
  }
  for (int cn = 0; cn < 3; ++cn) {
    const auto [a, b] = plane_axes(cn);
    shear[std::size_t(cn)] = c[a][b];  // Cauchy: C_abab = C_aabb for central springs
  }
  return {young_of(c), shear};
}

}  // namespace papertear
