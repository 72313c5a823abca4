#include "kernels/cell_forces.hpp"

#include "kernels/lanes.hpp"

namespace papertear {
namespace {

template <class V>
struct CellLanes {
  using T = lanes::Traits<V>;
  static constexpr std::size_t W = T::width;

  // Loads the 8 corners of W cells, evaluates their 28 springs, scatters corner forces.
  static void run(const std::uint32_t* cells, const CellForceInputs& in, const ForceOutputs& out) {
    alignas(64) float buf[6][8][W];
    alignas(64) std::uint32_t node[8][W];
    alignas(64) float scale[W];
    const float* src[6] = {in.px, in.py, in.pz, in.vx, in.vy, in.vz};
    for (std::size_t l = 0; l < W; ++l) {
      const std::uint32_t c = cells[l];
      scale[l] = in.cell_scale[c];
      const std::uint32_t* corners = in.cell_nodes + std::size_t(c) * 8;
      for (int q = 0; q < 8; ++q) {
        const std::uint32_t n = corners[q];
        node[q][l] = n;
        for (int f = 0; f < 6; ++f) buf[f][q][l] = src[f][n];
      }
    }
    V x[8], y[8], z[8], u[8], v[8], w[8];
    V fx[8], fy[8], fz[8];
    for (int q = 0; q < 8; ++q) {
      x[q] = T::load(buf[0][q]); y[q] = T::load(buf[1][q]); z[q] = T::load(buf[2][q]);
      u[q] = T::load(buf[3][q]); v[q] = T::load(buf[4][q]); w[q] = T::load(buf[5][q]);
      fx[q] = fy[q] = fz[q] = T::broadcast(0.0f);
    }
    const V s = T::load(scale);
    const V one = T::broadcast(1.0f);
    const SpringTable& tab = *in.table;
    for (int i = 0; i < kSpringsPerCell; ++i) {
      const int a = kSpringSlots[std::size_t(i)].a, b = kSpringSlots[std::size_t(i)].b;
      const V dx = x[b] - x[a], dy = y[b] - y[a], dz = z[b] - z[a];
      const V du = u[b] - u[a], dv = v[b] - v[a], dw = w[b] - w[a];
      const V len = T::sqrt(dx * dx + dy * dy + dz * dz);
      const V inv = one / len;
      const V k = s * T::broadcast(tab.stiffness[std::size_t(i)]);
      const V c = s * T::broadcast(tab.damping[std::size_t(i)]);
      const V rate = (du * dx + dv * dy + dw * dz) * inv;  // Δv · d̂
      const V mag = k * (len - T::broadcast(tab.rest[std::size_t(i)])) + c * rate;
      const V g = mag * inv;
      const V gx = g * dx, gy = g * dy, gz = g * dz;
      fx[a] = fx[a] + gx; fy[a] = fy[a] + gy; fz[a] = fz[a] + gz;
      fx[b] = fx[b] - gx; fy[b] = fy[b] - gy; fz[b] = fz[b] - gz;
    }
    for (int q = 0; q < 8; ++q) {
      T::store(buf[0][q], fx[q]); T::store(buf[1][q], fy[q]); T::store(buf[2][q], fz[q]);
    }
    for (std::size_t l = 0; l < W; ++l)
      for (int q = 0; q < 8; ++q) {
        const std::uint32_t n = node[q][l];
        out.fx[n] += buf[0][q][l];
        out.fy[n] += buf[1][q][l];
        out.fz[n] += buf[2][q][l];
      }
  }
};

template <class V>
void add_forces_with(std::size_t begin, std::size_t end, const std::uint32_t* cells,
                     const CellForceInputs& in, const ForceOutputs& out) {
  constexpr std::size_t W = CellLanes<V>::W;
  std::size_t i = begin;
  for (; i + W <= end; i += W) CellLanes<V>::run(cells + i, in, out);
  for (; i < end; ++i) CellLanes<float>::run(cells + i, in, out);
}

}  // namespace

void add_cell_forces(std::size_t begin, std::size_t end, const std::uint32_t* cells,
                     const CellForceInputs& in, const ForceOutputs& out) {
  add_forces_with<lanes::Wide>(begin, end, cells, in, out);
}

void add_cell_forces_scalar(std::size_t begin, std::size_t end, const std::uint32_t* cells,
                            const CellForceInputs& in, const ForceOutputs& out) {
  add_forces_with<float>(begin, end, cells, in, out);
}

}  // namespace papertear
