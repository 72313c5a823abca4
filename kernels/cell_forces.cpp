#include "kernels/cell_forces.hpp"

#include <algorithm>
#include <cassert>
#include <type_traits>
#include <utility>

#include "kernels/lanes.hpp"
#include "kernels/spring_lanes.hpp"

#if !defined(PAPERTEAR_NO_SIMD) && XSIMD_WITH_AVX2
#include <immintrin.h>
#endif
#if defined(__SSE__) || defined(_M_X64)
#include <xmmintrin.h>
#define PAPERTEAR_HAS_MXCSR 1
#endif

namespace papertear {
namespace {

// The sweep's vector (RowLane) and the dirty cells' (DirtyLane): 8 floats where AVX2 exists,
// else the widest the build has; AVX-512 builds sweep 16 at a time (define
// PAPERTEAR_SWEEP8 for 8). On a Zen 5 EPYC the 16-lane sweep made the quiet step 0.93 of the
// 8-lane one on 1 thread, 0.95 on 2, and on a Zen 4 EPYC (512-bit operations in two halves)
// 8 lanes made it 1.13 and 1.07 of the 16-lane one; on an AVX-512 Xeon it measured +2 to +3 %
// in the kernel, within that run's noise (bench/README.md, rounds 13 to 15). The dirty cells stay
// at 8: 16 at a time pad more lanes and made the Xeon's torn step 9 % slower.
#if !defined(PAPERTEAR_NO_SIMD) && XSIMD_WITH_AVX2
using DirtyLane = xsimd::batch<float, xsimd::avx2>;
#if XSIMD_WITH_AVX512F && !defined(PAPERTEAR_SWEEP8)
using RowLane = xsimd::batch<float, xsimd::avx512f>;
#else
using RowLane = DirtyLane;
#endif
#else
using RowLane = lanes::Wide;
using DirtyLane = lanes::Wide;
#endif

// What the sweep does with its lane type V; the scalar instantiation (V = float) is one lane.
template <class V>
struct Lanes;

template <>
struct Lanes<float> {
  static constexpr int W = 1;
  [[maybe_unused]] static constexpr bool kAvx2 = false;  // read only where AVX2 is compiled in
  static float load(const float* p) { return *p; }
  static void store(float* p, float v) { *p = v; }
  static float sqrt(float v) { return std::sqrt(v); }
  static float counts(const std::uint8_t* p) { return float(*p); }
  // v where lanes >= skip, +0 below.
  static float from_lane(float v, int skip) { return skip == 0 ? v : 0.0f; }
  // v where the cell has no split copy among its corners (copies byte 0), +0 elsewhere.
  static float where_whole(float v, const std::uint8_t* copies) { return *copies == 0 ? v : 0.0f; }
};

#ifndef PAPERTEAR_NO_SIMD
template <class A>
struct Lanes<xsimd::batch<float, A>> {
  using V = xsimd::batch<float, A>;
  static constexpr int W = int(V::size);
  static_assert(W <= 16, "the lane table covers 16 lanes");
#if XSIMD_WITH_AVX2
  static constexpr bool kAvx2 = std::is_same_v<A, xsimd::avx2>;
#else
  [[maybe_unused]] static constexpr bool kAvx2 = false;  // read only where AVX2 is compiled in
#endif
#if XSIMD_WITH_AVX512F
  static constexpr bool kAvx512 = std::is_same_v<A, xsimd::avx512f>;
#else
  static constexpr bool kAvx512 = false;
#endif

  static V load(const float* p) { return V::load_unaligned(p); }
  static void store(float* p, const V& v) { v.store_unaligned(p); }
  static V sqrt(const V& v) { return xsimd::sqrt(v); }
  // W counts (bytes) as floats; the table has padding, so reading W bytes is always safe.
  static V counts(const std::uint8_t* p) {
#if XSIMD_WITH_AVX2
    if constexpr (kAvx2)
      return _mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p))));
#endif
#if XSIMD_WITH_AVX512F
    if constexpr (kAvx512)
      return _mm512_cvtepi32_ps(_mm512_cvtepu8_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p))));
#endif
    alignas(64) float f[W];
    for (int l = 0; l < W; ++l) f[l] = float(p[l]);
    return V::load_aligned(f);
  }
  static V from_lane(const V& v, int skip) {
    // Lane l of the load at 16 - skip is all ones when l >= skip.
    alignas(64) static constexpr std::uint32_t kOnes[32] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
                                                            ~0u, ~0u, ~0u, ~0u, ~0u, ~0u, ~0u, ~0u,
                                                            ~0u, ~0u, ~0u, ~0u, ~0u, ~0u, ~0u, ~0u};
    return v & V::load_unaligned(reinterpret_cast<const float*>(kOnes + 16 - skip));
  }
  static V where_whole(const V& v, const std::uint8_t* copies) {
#if XSIMD_WITH_AVX2
    if constexpr (kAvx2) {
      const __m256i bytes = _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(copies)));
      return _mm256_and_ps(v, _mm256_castsi256_ps(_mm256_cmpeq_epi32(bytes, _mm256_setzero_si256())));
    }
#endif
#if XSIMD_WITH_AVX512F
    if constexpr (kAvx512) {
      const __m512i bytes = _mm512_cvtepu8_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(copies)));
      return _mm512_maskz_mov_ps(_mm512_testn_epi32_mask(bytes, bytes), v);
    }
#endif
    alignas(64) float keep[W];
    for (int l = 0; l < W; ++l) keep[l] = copies[l] == 0 ? 1.0f : 0.0f;
    return xsimd::select(V::load_aligned(keep) != V(0.0f), v, V(0.0f));
  }
};
#endif

// One row of cells as the sweep sees it.
struct Row {
  const CellForceInputs& in;
  const ForceOutputs& out;
  const FineRow& plan;
  std::size_t cell0;         // the row's first cell, (0, j, k)
  std::size_t vertex[2][2];  // the first vertex of the rows of vertices (j + dy, k + dz) its cells touch
  const std::vector<DirtyGroup>* dirty;  // its cells with split copies among their corners
};

// The edges along x (both ends on one row of vertices, where a node can be the a end of one
// cell and the b end of the next): their forces per cell of the chunk, kept until the a
// ends' pass and then the b ends' pass add them.
struct AlongRow {
  alignas(64) float a[3][kRowChunk];
  alignas(64) float b[3][kRowChunk];
};

// spring_force (kernels/spring_lanes.hpp): the force of W springs from their end values.

// Slot S of a row's cells, W at a time: the cells without split copies among their corners
// ("whole" cells; the others add zeros here and their springs in DirtyCells).
template <class V, int S, bool kScaled>
struct SlotPass {
  using T = Lanes<V>;
  static constexpr int W = T::W;
  static constexpr int a = kSpringSlots[std::size_t(S)].a, b = kSpringSlots[std::size_t(S)].b;
  static constexpr bool kAlongRow = (a ^ b) == 1;  // the corners differ in x only

  static std::size_t end_vertex(const Row& r, int corner) {
    return r.vertex[corner_bit(corner, 1)][corner_bit(corner, 2)] + std::size_t(corner_bit(corner, 0));
  }

  // Cells [i, i + U's width) of the row (lanes below `skip` were added by the vector before:
  // they are computed with count 0, so they add exact zeros; along x they are stored again,
  // with the same values). kMasked: the row has cells with split copies, whose lanes get
  // count 0.
  template <class U, bool kMasked>
  [[gnu::always_inline]] static inline void springs(std::size_t i, int skip, std::ptrdiff_t ab, const float* x,
                                                    const float* y, const float* z, const float* u, const float* v,
                                                    const float* w, float* fx, float* fy, float* fz,
                                                    const std::uint8_t* count, const float* scale,
                                                    const std::uint8_t* copies, const U& vk, const U& vc,
                                                    const U& rest, AlongRow* along, std::size_t chunk) {
    using L = Lanes<U>;
    const std::size_t j = std::size_t(std::ptrdiff_t(i) + ab);
    const U pa[6] = {L::load(x + i), L::load(y + i), L::load(z + i), L::load(u + i), L::load(v + i), L::load(w + i)};
    const U pb[6] = {L::load(x + j), L::load(y + j), L::load(z + j), L::load(u + j), L::load(v + j), L::load(w + j)};
    U n = L::counts(count + i);
    if constexpr (kMasked) n = L::where_whole(n, copies + i);
    if (!kAlongRow && skip != 0) n = L::from_lane(n, skip);
    U f[3];
    spring_force<U, kScaled>(pa, pb, n, kScaled ? L::load(scale + i) : vk, vk, vc, rest, f);
    if constexpr (kAlongRow) {
      for (int q = 0; q < 3; ++q) {
        L::store(along->a[q] + (i - chunk), f[q]);
        L::store(along->b[q] + (i - chunk), f[q]);
      }
    } else {
      L::store(fx + i, L::load(fx + i) + f[0]);
      L::store(fy + i, L::load(fy + i) + f[1]);
      L::store(fz + i, L::load(fz + i) + f[2]);
      L::store(fx + j, L::load(fx + j) - f[0]);
      L::store(fy + j, L::load(fy + j) - f[1]);
      L::store(fz + j, L::load(fz + j) - f[2]);
    }
  }

  // Cells [lo, hi) of the row (in the chunk from cell `chunk`): vectors from lo, then one
  // overlapping the last for the remainder; a range shorter than a vector one lane at a time.
  // An edge along x then adds its a ends, then its b ends. Every pointer and constant is a
  // parameter of its own: taken from arrays or a struct, GCC packed the pointers into vector
  // registers and unpacked them in every iteration.
  template <bool kMasked>
  [[gnu::noinline]] static void run(std::size_t lo, std::size_t hi, std::ptrdiff_t ab, const float* __restrict x,
                                    const float* __restrict y, const float* __restrict z, const float* __restrict u,
                                    const float* __restrict v, const float* __restrict w, float* __restrict fx,
                                    float* __restrict fy, float* __restrict fz, const std::uint8_t* __restrict count,
                                    const float* __restrict scale, const std::uint8_t* __restrict copies, float K,
                                    float C, float L0, AlongRow* __restrict along, std::size_t chunk) {
    if (hi - lo < std::size_t(W)) {
      for (std::size_t i = lo; i < hi; ++i)
        springs<float, kMasked>(i, 0, ab, x, y, z, u, v, w, fx, fy, fz, count, scale, copies, K, C, L0, along, chunk);
    } else {
      const V vk(K), vc(C), rest(L0);
      const std::size_t whole = lo + (hi - lo) / std::size_t(W) * std::size_t(W);
      for (std::size_t i = lo; i < whole; i += std::size_t(W))
        springs<V, kMasked>(i, 0, ab, x, y, z, u, v, w, fx, fy, fz, count, scale, copies, vk, vc, rest, along, chunk);
      if (whole < hi)
        springs<V, kMasked>(hi - std::size_t(W), int(std::size_t(W) - (hi - whole)), ab, x, y, z, u, v, w, fx, fy, fz,
                            count, scale, copies, vk, vc, rest, along, chunk);
    }
    if constexpr (kAlongRow) {
      float* dst[3] = {fx, fy, fz};
      for (int q = 0; q < 3; ++q) {
        float* __restrict f = dst[q] + lo;
        const float* __restrict g = along->a[q] + (lo - chunk);
        for (std::size_t i = 0; i < hi - lo; ++i) f[i] += g[i];
      }
      for (int q = 0; q < 3; ++q) {
        float* __restrict f = dst[q] + ab + std::ptrdiff_t(lo);
        const float* __restrict g = along->b[q] + (lo - chunk);
        for (std::size_t i = 0; i < hi - lo; ++i) f[i] -= g[i];
      }
    }
  }
};

// Slot S over cells [lo, hi) of the row (within the chunk starting at cell `chunk`).
template <class V, int S, bool kScaled>
void sweep_slot(const Row& r, std::size_t lo, std::size_t hi, std::size_t chunk, AlongRow& along) {
  using Pass = SlotPass<V, S, kScaled>;
  const CellForceInputs& in = r.in;
  const std::size_t va = Pass::end_vertex(r, Pass::a);
  const std::ptrdiff_t ab = std::ptrdiff_t(Pass::end_vertex(r, Pass::b)) - std::ptrdiff_t(va);
  const std::uint8_t* count = in.fine->kernel_counts(r.plan, r.cell0, S);
  const float K = in.table->stiffness[std::size_t(S)], C = in.table->damping[std::size_t(S)],
              L0 = in.table->rest[std::size_t(S)];
  auto go = [&]<bool kMasked>() {
    Pass::template run<kMasked>(lo, hi, ab, in.px + va, in.py + va, in.pz + va, in.vx + va, in.vy + va, in.vz + va,
                                r.out.fx + va, r.out.fy + va, r.out.fz + va, count, in.cell_scale + r.cell0,
                                in.fine->copies.data() + r.cell0, K, C, L0, &along, chunk);
  };
  if (r.plan.copies) go.template operator()<true>();
  else go.template operator()<false>();
}

template <class V, int... S>
void sweep_slots(std::integer_sequence<int, S...>, const Row& r, std::size_t c0, std::size_t c1, AlongRow& along) {
  auto one = [&]<int I>() {
    const std::size_t lo = std::max<std::size_t>(r.plan.lo[I], c0), hi = std::min<std::size_t>(r.plan.hi[I], c1);
    if (lo >= hi) return;
    if (r.plan.scaled) sweep_slot<V, I, true>(r, lo, hi, c0, along);
    else sweep_slot<V, I, false>(r, lo, hi, c0, along);
  };
  (one.template operator()<S>(), ...);
}

// The cells of a chunk with split copies among their corners ("dirty" cells), after the
// slots' passes: W of them at a time (the row's DirtyGroups, kernels/fine_springs.hpp, each
// taken W lanes at a time), each with its 8 corners' values fetched by node and all 28 slots
// run (counts of 0 add exact zeros) into a sum per corner, which is then added to the
// corner's node, cell by cell and corner by corner. A dirty cell's terms thus come in the
// order of the cells, whatever W is. Why not patch the copies into the slots' vectors: a
// copy then had to be fetched and its term added once per slot, and the lanes' tests and
// patches cost the torn sheet more than all its whole cells (a copy lies in ~35 % of the
// vectors of the default scene at step 800).
template <class V>
struct DirtyCells {
  using T = Lanes<V>;
  static constexpr int W = T::W;
  static_assert(DirtyGroup::kLanes % W == 0, "a group is a whole number of vectors");

  // Lanes [l0, l0 + W) of group g: the corners' values, the stiffness factors and the 28
  // slots' counts.
  [[gnu::always_inline]] static inline void load(const Row& r, const DirtyGroup& g, int l0, V (&corner)[8][6], V& s,
                                                 V (&n)[kSpringsPerCell]) {
    const CellForceInputs& in = r.in;
    const float* src[6] = {in.px, in.py, in.pz, in.vx, in.vy, in.vz};
    s = T::load(g.scale + l0);
    for (int k = 0; k < kSpringsPerCell; ++k) n[k] = T::counts(g.count[k] + l0);
#if !defined(PAPERTEAR_NO_SIMD) && XSIMD_WITH_AVX2
    if constexpr (T::kAvx2) {
      // Hardware gathers: the lanes' values written one by one to the stack and read back as
      // vectors made every such read wait on eight stores it cannot forward from.
      for (int q = 0; q < 8; ++q) {
        const __m256i nq = _mm256_load_si256(reinterpret_cast<const __m256i*>(g.node[q]));
        for (int f = 0; f < 6; ++f) corner[q][f] = _mm256_i32gather_ps(src[f], nq, 4);
      }
      return;
    }
#endif
    alignas(64) float value[6][8][W];
    for (int l = 0; l < W; ++l)
      for (int q = 0; q < 8; ++q)
        for (int f = 0; f < 6; ++f) value[f][q][l] = src[f][g.node[q][l0 + l]];
    for (int q = 0; q < 8; ++q)
      for (int f = 0; f < 6; ++f) corner[q][f] = T::load(value[f][q]);
  }

  // Lanes [l0, l0 + W) of group g (lanes from g.valid on are not added).
  static void run(const Row& r, const DirtyGroup& g, int l0) {
    const CellForceInputs& in = r.in;
    V corner[8][6], sum[8][3], s, n[kSpringsPerCell];
    load(r, g, l0, corner, s, n);
    for (int q = 0; q < 8; ++q)
      for (int f = 0; f < 3; ++f) sum[q][f] = V(0.0f);
    auto slot = [&]<int I>() __attribute__((always_inline)) {
      constexpr int a = kSpringSlots[std::size_t(I)].a, b = kSpringSlots[std::size_t(I)].b;
      V f[3];
      spring_force<V, true>(corner[a], corner[b], n[I], s, V(in.table->stiffness[std::size_t(I)]),
                            V(in.table->damping[std::size_t(I)]), V(in.table->rest[std::size_t(I)]), f);
      for (int q = 0; q < 3; ++q) {
        sum[a][q] = sum[a][q] + f[q];
        sum[b][q] = sum[b][q] - f[q];
      }
    };
    [&]<int... I>(std::integer_sequence<int, I...>) __attribute__((always_inline)) {
      (slot.template operator()<I>(), ...);
    }(std::make_integer_sequence<int, kSpringsPerCell>{});
    alignas(64) float out[3][8][W];
    for (int q = 0; q < 8; ++q)
      for (int f = 0; f < 3; ++f) T::store(out[f][q], sum[q][f]);
    float* dst[3] = {r.out.fx, r.out.fy, r.out.fz};
    const int valid = std::min(W, int(g.valid) - l0);
    for (int l = 0; l < valid; ++l)
      for (int q = 0; q < 8; ++q)
        for (int f = 0; f < 3; ++f) dst[f][g.node[q][l0 + l]] += out[f][q][l];
  }

  // The dirty cells of the row's chunk starting at cell c0, in order.
  static void run_chunk(const Row& r, std::size_t c0) {
    const std::uint32_t chunk = std::uint32_t(c0 / kRowChunk);
    for (const DirtyGroup& g : *r.dirty)
      if (g.chunk == chunk)
        for (int l0 = 0; l0 < int(g.valid); l0 += W) run(r, g, l0);
  }
};

template <class V, class D>
void rows_with(int j_begin, int j_end, const CellForceInputs& in, const ForceOutputs& out) {
  const FlushSubnormals flush;
  const LatticeDims& d = *in.dims;
  AlongRow along;
  for (int j = j_begin; j < j_end; ++j)
    for (int k = 0; k < d.nl; ++k) {
      const std::size_t row = std::size_t(k) * std::size_t(d.ny) + std::size_t(j);
      const Row r{in,
                  out,
                  in.fine->rows[row],
                  d.cell_index(0, j, k),
                  {{d.vertex_index(0, j, k), d.vertex_index(0, j, k + 1)},
                   {d.vertex_index(0, j + 1, k), d.vertex_index(0, j + 1, k + 1)}},
                  &in.fine->dirty[row]};
      for (std::size_t c0 = 0; c0 < std::size_t(d.nx); c0 += kRowChunk) {
        const std::size_t c1 = std::min(std::size_t(d.nx), c0 + kRowChunk);
        sweep_slots<V>(std::make_integer_sequence<int, kSpringsPerCell>{}, r, c0, c1, along);
        if (!r.dirty->empty()) DirtyCells<D>::run_chunk(r, c0);
      }
    }
}

}  // namespace

#ifdef PAPERTEAR_HAS_MXCSR
FlushSubnormals::FlushSubnormals() : saved_(_mm_getcsr()) { _mm_setcsr(saved_ | _MM_FLUSH_ZERO_ON | 0x0040u /* DAZ */); }
FlushSubnormals::~FlushSubnormals() { _mm_setcsr(saved_); }
#else
FlushSubnormals::FlushSubnormals() = default;
FlushSubnormals::~FlushSubnormals() = default;
#endif

void add_cell_row_forces(int j_begin, int j_end, const CellForceInputs& in, const ForceOutputs& out) {
  assert(in.fine->stale_rows.empty() && "plan_stale_dirty_cells first");
  rows_with<RowLane, DirtyLane>(j_begin, j_end, in, out);
}

void add_cell_row_forces_scalar(int j_begin, int j_end, const CellForceInputs& in, const ForceOutputs& out) {
  assert(in.fine->stale_rows.empty() && "plan_stale_dirty_cells first");
  rows_with<float, float>(j_begin, j_end, in, out);
}

}  // namespace papertear
