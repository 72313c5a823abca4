#include "kernels/coarse_forces.hpp"

#include <algorithm>
#include <cassert>
#include <cstdint>
#include <type_traits>

#include "kernels/lanes.hpp"

#if !defined(PAPERTEAR_NO_SIMD) && XSIMD_WITH_AVX2
#include <immintrin.h>
#endif

namespace papertear {
namespace {

// A dead spring (block entered by a crack) contributes exactly +0, as if skipped; computing
// and then discarding keeps the vector body branch-free.
inline float zero_where_dead(float f, float k, float c) { return (k == 0.0f && c == 0.0f) ? 0.0f : f; }
#ifndef PAPERTEAR_NO_SIMD
template <class A>
xsimd::batch<float, A> zero_where_dead(const xsimd::batch<float, A>& f, const xsimd::batch<float, A>& k,
                                       const xsimd::batch<float, A>& c) {
  using V = xsimd::batch<float, A>;
  return xsimd::select((k == V(0.0f)) & (c == V(0.0f)), V(0.0f), f);
}
#endif

// f where the lane's block is live, exact +0 elsewhere.
inline float keep_live(float f, float live) { return live != 0.0f ? f : 0.0f; }
#ifndef PAPERTEAR_NO_SIMD
template <class A>
xsimd::batch<float, A> keep_live(const xsimd::batch<float, A>& f, const xsimd::batch<float, A>& live) {
  using V = xsimd::batch<float, A>;
  return xsimd::select(live != V(0.0f), f, V(0.0f));
}
#endif

// Where each spring's ends live in topo.cell_nodes.
struct SlotsFromSprings {
  const CoarseSprings& s;
  std::uint32_t slot_a(std::size_t i) const { return s.cell_a[i] * 8u + s.corner_a[i]; }
  std::uint32_t slot_b(std::size_t i) const { return s.cell_b[i] * 8u + s.corner_b[i]; }
};

// W springs at a time: their 12 end values and 3 parameters are fetched with scalar loads
// into an aligned buffer, the formula (kernels/spring.hpp, same operations in the same
// order) runs on vectors, and the forces go back through the buffer.
template <class V>
struct CoarseLanes {
  using T = lanes::Traits<V>;
  static constexpr std::size_t W = T::width;

  template <class Slots>
  static void run(std::size_t i0, const Slots& slots, const CoarseSprings& sp, const CellForceInputs& in,
                  CoarseForceScratch& out) {
    alignas(64) float buf[15][W];
    const float* src[6] = {in.px, in.py, in.pz, in.vx, in.vy, in.vz};
    for (std::size_t l = 0; l < W; ++l) {
      const std::size_t i = i0 + l;
      const std::uint32_t a = in.cell_nodes[slots.slot_a(i)], b = in.cell_nodes[slots.slot_b(i)];
      for (int f = 0; f < 6; ++f) {
        buf[f][l] = src[f][a];
        buf[6 + f][l] = src[f][b];
      }
      buf[12][l] = sp.rest[i];
      buf[13][l] = sp.stiffness[i];
      buf[14][l] = sp.damping[i];
    }
    const V dx = T::load(buf[6]) - T::load(buf[0]);
    const V dy = T::load(buf[7]) - T::load(buf[1]);
    const V dz = T::load(buf[8]) - T::load(buf[2]);
    const V len = T::sqrt(dx * dx + dy * dy + dz * dz);
    const V inv = T::broadcast(1.0f) / len;
    const V rate = ((T::load(buf[9]) - T::load(buf[3])) * dx + (T::load(buf[10]) - T::load(buf[4])) * dy +
                    (T::load(buf[11]) - T::load(buf[5])) * dz) * inv;
    const V k = T::load(buf[13]), c = T::load(buf[14]);
    const V mag = k * (len - T::load(buf[12])) + c * rate;
    const V g = mag * inv;
    T::store(buf[0], zero_where_dead(g * dx, k, c));
    T::store(buf[1], zero_where_dead(g * dy, k, c));
    T::store(buf[2], zero_where_dead(g * dz, k, c));
    for (std::size_t l = 0; l < W; ++l) {
      out.fx[i0 + l] = buf[0][l];
      out.fy[i0 + l] = buf[1][l];
      out.fz[i0 + l] = buf[2][l];
    }
  }
};

template <class Slots>
void spring_forces_with(std::size_t begin, std::size_t end, const Slots& slots, const CoarseSprings& sp,
                        const CellForceInputs& in, CoarseForceScratch& out) {
  constexpr std::size_t W = CoarseLanes<lanes::Wide>::W;
  std::size_t i = begin;
  for (; i + W <= end; i += W) CoarseLanes<lanes::Wide>::run(i, slots, sp, in, out);
  for (; i < end; ++i) CoarseLanes<float>::run(i, slots, sp, in, out);
}

// A pack's rows: the stage state of its distinct corner nodes.
using PackState = float[kPackRows][8];

#if !defined(PAPERTEAR_NO_SIMD) && XSIMD_WITH_AVX2
// r[i][l] becomes r[l][i]: pairs interleaved, then quads, then the 128-bit halves swapped.
inline void transpose_8x8(__m256 (&r)[8]) {
  __m256 t[8], s[8];
  for (int i = 0; i < 8; i += 2) {
    t[i] = _mm256_unpacklo_ps(r[i], r[i + 1]);
    t[i + 1] = _mm256_unpackhi_ps(r[i], r[i + 1]);
  }
  for (int i = 0; i < 8; i += 4)
    for (int h = 0; h < 2; ++h) {
      s[i + 2 * h] = _mm256_shuffle_ps(t[i + h], t[i + h + 2], 0x44);
      s[i + 2 * h + 1] = _mm256_shuffle_ps(t[i + h], t[i + h + 2], 0xEE);
    }
  for (int i = 0; i < 4; ++i) {
    r[i] = _mm256_permute2f128_ps(s[i], s[i + 4], 0x20);
    r[i + 4] = _mm256_permute2f128_ps(s[i], s[i + 4], 0x31);
  }
}
#endif

#if !defined(PAPERTEAR_NO_SIMD) && XSIMD_WITH_AVX512F
// transpose_8x8 in each 256-bit half: r[i] holds row i in its low half and row i + 8 in its
// high half; afterwards r[f] holds value f of rows 0-7 low and of rows 8-15 high.
inline void transpose_8x8_halves(__m512 (&r)[8]) {
  __m512 t[8], s[8];
  for (int i = 0; i < 8; i += 2) {
    t[i] = _mm512_unpacklo_ps(r[i], r[i + 1]);
    t[i + 1] = _mm512_unpackhi_ps(r[i], r[i + 1]);
  }
  for (int i = 0; i < 8; i += 4)
    for (int h = 0; h < 2; ++h) {
      s[i + 2 * h] = _mm512_shuffle_ps(t[i + h], t[i + h + 2], 0x44);
      s[i + 2 * h + 1] = _mm512_shuffle_ps(t[i + h], t[i + h + 2], 0xEE);
    }
  // permute2f128's 0x20 and 0x31 in each half: the low (high) 128 bits of a, then of b.
  const __m512i lows = _mm512_setr_epi32(0, 1, 2, 3, 16, 17, 18, 19, 8, 9, 10, 11, 24, 25, 26, 27);
  const __m512i highs = _mm512_setr_epi32(4, 5, 6, 7, 20, 21, 22, 23, 12, 13, 14, 15, 28, 29, 30, 31);
  for (int i = 0; i < 4; ++i) {
    r[i] = _mm512_permutex2var_ps(s[i], lows, s[i + 4]);
    r[i + 4] = _mm512_permutex2var_ps(s[i], highs, s[i + 4]);
  }
}
#endif

// Copies the stage state of pack p's distinct corner nodes into its rows (columns 6 and 7,
// which pass 1 loads but never uses, are left as they are).
void fill_pack(const BlockLattice& L, std::size_t p, const CellForceInputs& in, PackState& state) {
  const std::uint32_t* nodes = L.pack_node.data() + p * kPackRows;
  for (std::size_t r = 0; r < L.pack_rows[p]; ++r) {
    const std::uint32_t n = nodes[r];
    float* row = state[r];
    row[0] = in.px[n]; row[1] = in.py[n]; row[2] = in.pz[n];
    row[3] = in.vx[n]; row[4] = in.vy[n]; row[5] = in.vz[n];
  }
}

// Pack p's distinct corner nodes, in ascending order (so that filling the pack reads the
// state columns in order), and each block corner's row among them.
void build_pack(BlockLattice& L, std::size_t p) {
  const std::size_t P = L.lanes, lo = p * kPackLanes, hi = std::min(P, lo + kPackLanes);
  std::uint32_t* nodes = L.pack_node.data() + p * kPackRows;
  std::uint32_t* end = nodes;
  for (std::size_t q = 0; q < 8; ++q) end = std::copy(&L.corner_node[q * P + lo], &L.corner_node[q * P + hi], end);
  std::sort(nodes, end);
  end = std::unique(nodes, end);
  L.pack_rows[p] = std::uint16_t(end - nodes);
  for (std::size_t q = 0; q < 8; ++q)
    for (std::size_t j = lo; j < hi; ++j)
      L.corner_row[BlockLattice::row_at(j, q)] =
          std::uint16_t(std::lower_bound(nodes, end, L.corner_node[q * P + j]) - nodes);
}

// W blocks' 28 springs on their 8 corners (the cell kernel's body with per-lane slot
// parameters). An absent spring (k = c = 0) is zeroed by select, so even a degenerate
// zero-length pair adds exactly nothing.
template <class V>
struct BlockLanes {
  using T = lanes::Traits<V>;
  static constexpr std::size_t W = T::width;

  // Corner q of lane l is row rows[q * stride + l] of the pack's state (x y z vx vy vz, and two
  // unused columns).
  static void load_corners(const std::uint16_t* rows, std::size_t stride, const PackState& state, V (&x)[8],
                           V (&y)[8], V (&z)[8], V (&u)[8], V (&v)[8], V (&w)[8]) {
#if !defined(PAPERTEAR_NO_SIMD) && XSIMD_WITH_AVX2
    // Row l holds lane l's 6 values; after the transpose, register f holds value f of all 8.
    if constexpr (std::is_same_v<V, xsimd::batch<float, xsimd::avx2>>) {
      for (std::size_t q = 0; q < 8; ++q) {
        __m256 r[8];
        for (std::size_t l = 0; l < 8; ++l) r[l] = _mm256_load_ps(state[rows[q * stride + l]]);
        transpose_8x8(r);
        x[q] = r[0]; y[q] = r[1]; z[q] = r[2]; u[q] = r[3]; v[q] = r[4]; w[q] = r[5];
      }
      return;
    }
#endif
#if !defined(PAPERTEAR_NO_SIMD) && XSIMD_WITH_AVX512F
    // Rows l and l + 8 share a register, one per 256-bit half, for the transpose above.
    if constexpr (std::is_same_v<V, xsimd::batch<float, xsimd::avx512f>>) {
      for (std::size_t q = 0; q < 8; ++q) {
        __m512 r[8];
        for (std::size_t l = 0; l < 8; ++l)
          r[l] = _mm512_insertf32x8(_mm512_castps256_ps512(_mm256_load_ps(state[rows[q * stride + l]])),
                                    _mm256_load_ps(state[rows[q * stride + l + 8]]), 1);
        transpose_8x8_halves(r);
        x[q] = r[0]; y[q] = r[1]; z[q] = r[2]; u[q] = r[3]; v[q] = r[4]; w[q] = r[5];
      }
      return;
    }
#endif
    alignas(64) float buf[6][8][W];
    for (std::size_t q = 0; q < 8; ++q)
      for (std::size_t l = 0; l < W; ++l) {
        const float* row = state[rows[q * stride + l]];
        for (int f = 0; f < 6; ++f) buf[f][q][l] = row[f];
      }
    for (int q = 0; q < 8; ++q) {
      x[q] = T::load(buf[0][q]); y[q] = T::load(buf[1][q]); z[q] = T::load(buf[2][q]);
      u[q] = T::load(buf[3][q]); v[q] = T::load(buf[4][q]); w[q] = T::load(buf[5][q]);
    }
  }

  static void run(std::size_t j, const PackState& state, BlockLattice& L) {
    const std::size_t P = L.lanes;
    V x[8], y[8], z[8], u[8], v[8], w[8], fx[8], fy[8], fz[8];
    load_corners(L.corner_row.data() + BlockLattice::row_at(j, 0), kBlockGroup, state, x, y, z, u, v, w);
    for (int q = 0; q < 8; ++q) fx[q] = fy[q] = fz[q] = T::broadcast(0.0f);
    const V one = T::broadcast(1.0f);
    // Fully unrolled, so that corner values and sums index registers, not a stack array.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC unroll 28
#elif defined(__clang__)
#pragma unroll
#endif
    for (int i = 0; i < kSpringsPerCell; ++i) {
      const int a = kSpringSlots[std::size_t(i)].a, b = kSpringSlots[std::size_t(i)].b;
      const std::size_t at = BlockLattice::param_at(j, std::size_t(i));
      const V k = T::load(L.stiffness.data() + at), c = T::load(L.damping.data() + at);
      const V dx = x[b] - x[a], dy = y[b] - y[a], dz = z[b] - z[a];
      const V len = T::sqrt(dx * dx + dy * dy + dz * dz);
      const V inv = one / len;
      const V rate = ((u[b] - u[a]) * dx + (v[b] - v[a]) * dy + (w[b] - w[a]) * dz) * inv;
      const V mag = k * (len - T::load(L.rest.data() + at)) + c * rate;
      const V g = mag * inv;
      const V gx = zero_where_dead(g * dx, k, c), gy = zero_where_dead(g * dy, k, c),
              gz = zero_where_dead(g * dz, k, c);
      fx[a] = fx[a] + gx; fy[a] = fy[a] + gy; fz[a] = fz[a] + gz;
      fx[b] = fx[b] - gx; fy[b] = fy[b] - gy; fz[b] = fz[b] - gz;
    }
    const V live = T::load(L.live.data() + j);
    for (int q = 0; q < 8; ++q) {
      const std::size_t at = std::size_t(q) * P + j;
      T::store(L.fx.data() + at, keep_live(fx[q], live));
      T::store(L.fy.data() + at, keep_live(fy[q], live));
      T::store(L.fz.data() + at, keep_live(fz[q], live));
    }
  }
};

// One parameter group per vector: kBlockGroup (coarse_forces.hpp, the one place the width is
// chosen) is 16 blocks in AVX-512 builds, 8 where AVX2 exists. On a Zen 4 EPYC, whose AVX-512
// runs in 256-bit halves, 16 made the quiet step 0.95 of the 8-lane one on 2 threads
// (bench/README.md, round 15): half the instructions per block for the corner loads,
// parameter loads and stores, the same arithmetic per lane.
#if !defined(PAPERTEAR_NO_SIMD) && XSIMD_WITH_AVX512F
using BlockLane =
    std::conditional_t<kBlockGroup == 16, xsimd::batch<float, xsimd::avx512f>, xsimd::batch<float, xsimd::avx2>>;
#elif !defined(PAPERTEAR_NO_SIMD) && XSIMD_WITH_AVX2
using BlockLane = xsimd::batch<float, xsimd::avx2>;
#else
using BlockLane = lanes::Wide;
#endif
static_assert(kBlockGroup % lanes::Traits<BlockLane>::width == 0, "a vector never straddles a parameter group");

// Pass 1 loads all 8 corners of every lane, so corners no spring joins and padding lanes
// still name a node, whose stage state the pack copies. Left at slot 0 they would name node 0,
// which the block chunk's task is not ordered against: the solver orders it only before the
// bands of rows that hold its blocks' corners (core/solver.cpp), and band 0 updates node 0
// meanwhile, a data race. So an unused corner names a used corner of its own block, and a
// padding lane the corners of the last block (the padding shares its chunk). The springs
// to such corners are absent and add exactly zero, so this changes no bits.
void alias_unused_corners(const std::vector<std::uint8_t>& used, std::size_t real_lanes, BlockLattice& L) {
  const std::size_t P = L.lanes;
  for (std::size_t j = 0; j < real_lanes; ++j) {
    std::size_t q0 = 0;
    while (!used[q0 * P + j]) ++q0;  // a block with springs uses some corner
    for (std::size_t q = 0; q < 8; ++q)
      if (!used[q * P + j]) L.corner_slot[q * P + j] = L.corner_slot[q0 * P + j];
  }
  for (std::size_t j = real_lanes; j < P; ++j)
    for (std::size_t q = 0; q < 8; ++q) L.corner_slot[q * P + j] = L.corner_slot[q * P + real_lanes - 1];
}

}  // namespace

void build_block_lattice(const CoarseSprings& sp, const std::vector<Block>& blocks, const LatticeDims& d,
                         BlockLattice& L) {
  std::vector<std::uint32_t> with_springs;
  for (std::uint32_t b = 0; b < blocks.size(); ++b)
    if (blocks[b].spring_count > 0) with_springs.push_back(b);
  // Lanes by the block's first row of cells (then by id): block ids run layer band after
  // layer band, and the solver hands out the lanes, the fine springs' strips and the node
  // update's bands of rows in the same order (core/solver.cpp), so a thread's blocks are
  // mostly in the rows whose nodes it updates and sweeps. The gather still adds a vertex's
  // corner sums in block id order (below), so the lane order does not change any bits.
  std::stable_sort(with_springs.begin(), with_springs.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return blocks[a].lo[1] < blocks[b].lo[1]; });
  const std::size_t P = (with_springs.size() + kBlockLanes - 1) / kBlockLanes * kBlockLanes;
  L.lanes = P;
  L.block.assign(P, UINT32_MAX);
  L.corner_slot.resize(8 * P);
  std::fill(L.corner_slot.begin(), L.corner_slot.end(), 0u);
  L.corner_node.resize(8 * P);
  L.live.resize(P);
  L.pack_node.assign((P + kPackLanes - 1) / kPackLanes * kPackRows, 0u);
  L.pack_rows.assign((P + kPackLanes - 1) / kPackLanes, 0);
  L.corner_row.assign(8 * P, 0);
  for (AlignedArray<float>* a : {&L.rest, &L.stiffness, &L.damping}) {
    a->resize(kSpringsPerCell * P);
    std::fill(a->begin(), a->end(), 0.0f);
  }
  for (AlignedArray<float>* a : {&L.fx, &L.fy, &L.fz}) a->resize(8 * P);
  std::vector<std::uint8_t> used(8 * P, 0);
  for (std::size_t j = 0; j < with_springs.size(); ++j) {
    const Block& blk = blocks[with_springs[j]];
    L.block[j] = with_springs[j];
    for (std::uint32_t i = blk.first_spring; i < blk.first_spring + blk.spring_count; ++i) {
      int slot = 0;
      while (kSpringSlots[std::size_t(slot)].a != sp.corner_a[i] || kSpringSlots[std::size_t(slot)].b != sp.corner_b[i]) ++slot;
      const std::size_t at = BlockLattice::param_at(j, std::size_t(slot));
      L.rest[at] = sp.rest[i];
      L.stiffness[at] = sp.stiffness[i];
      L.damping[at] = sp.damping[i];
      L.corner_slot[std::size_t(sp.corner_a[i]) * P + j] = sp.cell_a[i] * 8u + sp.corner_a[i];
      L.corner_slot[std::size_t(sp.corner_b[i]) * P + j] = sp.cell_b[i] * 8u + sp.corner_b[i];
      used[std::size_t(sp.corner_a[i]) * P + j] = used[std::size_t(sp.corner_b[i]) * P + j] = 1;
    }
  }
  alias_unused_corners(used, with_springs.size(), L);
  // Per vertex, the used block corners in ascending block id.
  const std::size_t vertices = std::size_t(d.vertices());
  L.first.assign(vertices + 1, 0);
  auto vertex_of = [&](std::size_t j, int q) {
    const std::uint32_t s = L.corner_slot[std::size_t(q) * P + j];
    return d.corner_vertex(s / 8u, int(s % 8u));
  };
  for (std::size_t j = 0; j < P; ++j)
    for (int q = 0; q < 8; ++q)
      if (used[std::size_t(q) * P + j]) ++L.first[vertex_of(j, q) + 1];
  for (std::size_t v = 0; v < vertices; ++v) L.first[v + 1] += L.first[v];
  L.entry.resize(L.first[vertices]);
  L.entry_node.assign(L.first[vertices], 0u);
  std::vector<std::uint32_t> fill(L.first.begin(), L.first.end() - 1);
  for (std::size_t j = 0; j < P; ++j)
    for (int q = 0; q < 8; ++q)
      if (used[std::size_t(q) * P + j]) {
        const std::uint32_t v = vertex_of(j, q);
        L.entry[fill[v]++] = std::uint32_t(std::size_t(q) * P + j);
      }
  // A block has one corner per vertex, so block ids order a vertex's entries strictly.
  for (std::size_t v = 0; v < vertices; ++v)
    std::sort(L.entry.begin() + L.first[v], L.entry.begin() + L.first[v + 1],
              [&](std::uint32_t a, std::uint32_t b) { return L.block[a % P] < L.block[b % P]; });
  L.springs = sp.size();
  L.built_from = sp.cell_a.data();
}

void refresh_block_lattice(std::size_t begin, std::size_t end, const Topology& topo,
                           const std::vector<Block>& blocks, BlockLattice& L) {
  assert(begin % kPackLanes == 0 && (end % kPackLanes == 0 || end == L.lanes));
  const std::size_t P = L.lanes;
  for (std::size_t lo = begin; lo < end; lo += kPackLanes) {
    const std::size_t hi = std::min(end, lo + kPackLanes), p = lo / kPackLanes;
    bool moved = L.pack_rows[p] == 0;  // a split gives some corner a new node: pack again
    for (std::size_t q = 0; q < 8; ++q)
      for (std::size_t j = lo; j < hi; ++j) {
        const std::uint32_t n = topo.cell_nodes[L.corner_slot[q * P + j]];
        moved |= n != L.corner_node[q * P + j];
        L.corner_node[q * P + j] = n;
      }
    if (moved) build_pack(L, p);
  }
  for (std::size_t j = begin; j < end; ++j)
    L.live[j] = L.block[j] != UINT32_MAX && blocks[L.block[j]].intact ? 1.0f : 0.0f;
}

void block_lattice_forces(std::size_t begin, std::size_t end, const CellForceInputs& in, BlockLattice& L) {
  const FlushSubnormals flush;
  constexpr std::size_t W = BlockLanes<BlockLane>::W;
  alignas(64) PackState state;
  for (float* row : state) row[6] = row[7] = 0.0f;  // never used; set so that no load reads indeterminate values
  std::size_t packed = SIZE_MAX;
  for (std::size_t j = begin; j < end; j += W) {
    if (j / kPackLanes != packed) fill_pack(L, packed = j / kPackLanes, in, state);
    BlockLanes<BlockLane>::run(j, state, L);
  }
}

void refresh_block_entries(std::size_t vbegin, std::size_t vend, BlockLattice& L) {
  for (std::size_t e = L.first[vbegin]; e < L.first[vend]; ++e) L.entry_node[e] = L.corner_node[L.entry[e]];
}

// A vertex's entries mostly name one node (all of them until a split there), so a run of
// entries with the same node is summed in registers and stored once: the same additions in
// the same order as one read-modify-write per entry, without each waiting on the last's store.
void gather_block_lattice_forces(std::size_t vbegin, std::size_t vend, const BlockLattice& L, const ForceOutputs& out) {
  const FlushSubnormals flush;
  const std::uint32_t* entry = L.entry.data();
  const std::uint32_t* node = L.entry_node.data();
  const float *cx = L.fx.data(), *cy = L.fy.data(), *cz = L.fz.data();
  const std::size_t end = L.first[vend];
  for (std::size_t e = L.first[vbegin]; e < end;) {
    const std::uint32_t n = node[e];
    float sx = out.fx[n], sy = out.fy[n], sz = out.fz[n];
    do {
      const std::uint32_t at = entry[e];
      sx += cx[at];
      sy += cy[at];
      sz += cz[at];
    } while (++e < end && node[e] == n);
    out.fx[n] = sx;
    out.fy[n] = sy;
    out.fz[n] = sz;
  }
}

void coarse_spring_forces(std::size_t begin, std::size_t end, const CoarseSprings& sp, const Topology&,
                          const CellForceInputs& in, CoarseForceScratch& out) {
  const FlushSubnormals flush;
  spring_forces_with(begin, end, SlotsFromSprings{sp}, sp, in, out);
}

void scatter_coarse_forces(const CoarseSprings& sp, const Topology& topo, const CoarseForceScratch& f,
                           const ForceOutputs& out) {
  const FlushSubnormals flush;
  for (std::size_t i = 0; i < sp.size(); ++i) {
    const std::uint32_t a = topo.node(sp.cell_a[i], sp.corner_a[i]);
    const std::uint32_t b = topo.node(sp.cell_b[i], sp.corner_b[i]);
    out.fx[a] += f.fx[i]; out.fy[a] += f.fy[i]; out.fz[a] += f.fz[i];
    out.fx[b] -= f.fx[i]; out.fy[b] -= f.fy[i]; out.fz[b] -= f.fz[i];
  }
}

}  // namespace papertear
