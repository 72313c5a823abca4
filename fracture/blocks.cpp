#include "fracture/blocks.hpp"

#include <algorithm>
#include <cmath>

#include "core/lattice_builder.hpp"
#include "core/random.hpp"

namespace papertear {
namespace {

// Fibre length in cells: log-normal with the material's mean.
int sample_length(Random& rng, const MaterialParams& m) {
  const double s = m.fiber_length_sigma;
  const double len = m.fiber_length * std::exp(s * rng.normal() - 0.5 * s * s);
  return std::max(1, int(std::lround(len)));
}

void add_block(World& w, std::array<int, 3> lo, std::array<int, 3> hi, Random& rng) {
  const double j = w.scene.material.strength_jitter;
  Block b;
  b.lo = lo;
  b.hi = hi;
  b.strength = float(1.0 + j * (2.0 * rng.uniform() - 1.0));
  const auto id = std::uint32_t(w.blocks.size());
  const LatticeDims& d = w.topo.dims;
  for (int k = lo[2]; k < hi[2]; ++k)
    for (int jj = lo[1]; jj < hi[1]; ++jj)
      for (int i = lo[0]; i < hi[0]; ++i) w.topo.cell_block[d.cell_index(i, jj, k)] = id;
  w.blocks.push_back(b);
}

// One strip of blocks along the grain: lengths from the fibre distribution, the first one
// cut short at random so that neighbouring strips are staggered like bricks.
void lay_strip(World& w, int g, std::array<int, 3> lo, std::array<int, 3> hi, Random& rng) {
  const int n = hi[std::size_t(g)];
  int pos = 0;
  int len = 1 + rng.below(sample_length(rng, w.scene.material));
  while (pos < n) {
    std::array<int, 3> blo = lo, bhi = hi;
    blo[std::size_t(g)] = pos;
    bhi[std::size_t(g)] = std::min(n, pos + len);
    add_block(w, blo, bhi, rng);
    pos += len;
    len = sample_length(rng, w.scene.material);
  }
}

// Layers are grouped into bands of 1..block_depth layers (the top layer always alone: it is
// the printed or coated surface); each band is cut across the grain into strips of
// 1..block_width cells; each strip into blocks along the grain.
void lay_blocks(World& w, Random& rng) {
  const LatticeDims& d = w.topo.dims;
  const MaterialParams& m = w.scene.material;
  const int g = m.grain == 'y' ? 1 : 0, o = 1 - g;
  const int n_other = o == 0 ? d.nx : d.ny;
  w.blocks.clear();
  for (int k0 = 0; k0 < d.nl;) {
    int depth = 1 + rng.below(m.block_depth);
    if (k0 < d.nl - 1) depth = std::min(depth, d.nl - 1 - k0);
    else depth = 1;
    for (int j0 = 0; j0 < n_other;) {
      const int width = std::min(1 + rng.below(m.block_width), n_other - j0);
      std::array<int, 3> lo{0, 0, k0}, hi{d.nx, d.ny, k0 + depth};
      lo[std::size_t(o)] = j0;
      hi[std::size_t(o)] = j0 + width;
      lay_strip(w, g, lo, hi, rng);
      j0 += width;
    }
    k0 += depth;
  }
}

// The strain that opens the bond between cells c and n across a face normal to `axis`.
float bond_strain(const World& w, std::uint32_t c, std::uint32_t n, int axis, int k_low) {
  const MaterialParams& m = w.scene.material;
  const std::uint32_t bc = w.topo.cell_block[c], bn = w.topo.cell_block[n];
  const double strength = std::min(w.blocks[bc].strength, w.blocks[bn].strength);
  // Through the thickness every bond is the sheet's z-direction bond, inside a block too: a
  // block is a bundle of fibres lying in the plane, and what holds its two layers together is
  // the same fibre-to-fibre bonding as between blocks. (Judged as strain_intra, a two-layer
  // block's midplane was 3x weaker than the interface around it, and the halves of a torn
  // sheet delaminated inside their blocks as they sprang back: 1100 mm² per seed.)
  if (axis == 2) return float(strength * ((k_low == w.topo.dims.nl - 2) ? m.strain_surface : m.strain_layer));
  double s = bc == bn ? m.strain_intra : m.strain_inter;
  // Opening a block's face normal to the grain breaks its fibres: stronger (MODEL.md §1).
  // Between blocks the bond is fibre-to-fibre bonding, as weak across as along the grain:
  // weaker along-grain boundaries would split open ahead of every crack tip (where the
  // stress parallel to the crack is as large as the opening stress) and blunt it.
  const int grain = m.grain == 'y' ? 1 : 0;
  if (bc == bn && axis == grain) s *= m.grain_strength;
  // Paper stretches further across the grain than along it before it breaks, so the bonds
  // that tension across the grain opens (faces parallel to it) take cross_stretch more strain.
  if (axis != grain) s *= m.cross_stretch;
  return float(s * strength);
}

// Cells in a grip or within load.grip_margin cells of one: their bonds never break.
// Pull: a tab at each end. Pierce: a frame along the border, inside the clamp. Tear: only
// the cells the fingers hold (grip_margin there is their distance to the tear line).
bool in_grip_tab(const World& w, int i, int j) {
  const LoadParams& l = w.scene.load;
  const LatticeDims& d = w.topo.dims;
  const int tab = l.grip_cells + l.grip_margin;
  if (l.kind == "pull") {
    const int along = l.axis == 'y' ? j : i;
    const int n = l.axis == 'y' ? d.ny : d.nx;
    return along < tab || along >= n - tab;
  }
  if (l.kind == "pierce") return i < tab || i >= d.nx - tab || j < tab || j >= d.ny - tab;
  if (l.kind == "tear") {
    const TearGrips t = tear_grips(l, d);
    const int a = l.axis == 'y' ? j : i, b = l.axis == 'y' ? i : j;
    const bool left = a >= t.left[0] && a < t.left[1], right = a >= t.right[0] && a < t.right[1];
    return b < t.depth && (left || right);
  }
  return false;
}

}  // namespace

void assign_bond_strengths(World& w) {
  const LatticeDims& d = w.topo.dims;
  for (int k = 0; k < d.nl; ++k)
    for (int j = 0; j < d.ny; ++j)
      for (int i = 0; i < d.nx; ++i) {
        const std::uint32_t c = d.cell_index(i, j, k);
        for (int f = 0; f < kFacesPerCell; ++f) {
          const std::int64_t n = d.neighbour(i, j, k, f);
          const int axis = f >> 1;
          const int k_low = (axis == 2) ? ((f & 1) ? k : k - 1) : k;
          const bool unbreakable = n < 0 || in_grip_tab(w, i, j) ||
                                   (n >= 0 && in_grip_tab(w, d.cell_ijk(std::uint32_t(n))[0], d.cell_ijk(std::uint32_t(n))[1]));
          w.topo.face_strain[std::size_t(c) * kFacesPerCell + std::size_t(f)] =
              unbreakable ? INFINITY : bond_strain(w, c, std::uint32_t(n), axis, k_low);
        }
      }
}

namespace {

// The block lattice: the 12 edges of each block's box, each end named by the block's corner
// cell and its corner. An edge along axis a stands for the bundle of the block's cells'
// edges along a: with n_a cells along a and n_b · n_c across it, its stiffness is
//   k = share / (1 - share) · k_fine · n_b · n_c / n_a,
// where k_fine is one cell's fine edge (which keeps 1 - share of the edges' stiffness,
// core/lattice_builder.cpp). Under a homogeneous strain the block's four edges along a then
// store exactly `share` of the energy of all its cells' edges along a, so the block lattice
// leaves the continuum moduli unchanged (core/elasticity.hpp) while it carries force across
// the block in one step. A block one cell long along a has its edge on its corner cell's.
void add_block_springs(World& w) {
  const LatticeDims& d = w.topo.dims;
  const MaterialParams& m = w.scene.material;
  CoarseSprings& cs = w.coarse;
  cs = CoarseSprings{};
  if (m.block_stiffness <= 0.0) return;
  const double h[3] = {d.hx, d.hy, d.hz};
  const double share = m.block_stiffness / (1.0 - m.block_stiffness);
  for (std::uint32_t b = 0; b < w.blocks.size(); ++b) {
    Block& blk = w.blocks[b];
    blk.first_spring = std::uint32_t(cs.size());
    const int cells = (blk.hi[0] - blk.lo[0]) * (blk.hi[1] - blk.lo[1]) * (blk.hi[2] - blk.lo[2]);
    if (cells < 2) continue;
    auto corner_cell = [&](int q) {
      int ijk[3];
      for (int a = 0; a < 3; ++a) ijk[a] = corner_bit(q, a) ? blk.hi[std::size_t(a)] - 1 : blk.lo[std::size_t(a)];
      return d.cell_index(ijk[0], ijk[1], ijk[2]);
    };
    for (int s = 0; s < kEdgesPerCell; ++s) {
      const SpringSlot& slot = kSpringSlots[std::size_t(s)];
      const int a = slot.axis;
      const double n_along = blk.hi[std::size_t(a)] - blk.lo[std::size_t(a)];
      const double n_across = double(cells) / n_along;
      const double len = n_along * h[a];
      const double k = share * w.springs.stiffness[std::size_t(s)] * n_across / n_along;
      cs.cell_a.push_back(corner_cell(slot.a));
      cs.cell_b.push_back(corner_cell(slot.b));
      cs.corner_a.push_back(slot.a);
      cs.corner_b.push_back(slot.b);
      cs.rest.push_back(float(len));
      cs.stiffness.push_back(float(k));
      cs.damping.push_back(float(k * m.damping));
      cs.block.push_back(b);
    }
    blk.spring_count = std::uint32_t(cs.size()) - blk.first_spring;
  }
}

}  // namespace

void lay_fibre_blocks(World& w) {
  Random rng(w.scene.run.seed * 0x9e3779b97f4a7c15ull + 0x7061706572ull);
  lay_blocks(w, rng);
  assign_bond_strengths(w);
  add_block_springs(w);
}

}  // namespace papertear
