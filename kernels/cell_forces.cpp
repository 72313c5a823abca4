#include "kernels/cell_forces.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <type_traits>
#include <utility>

#include "kernels/lanes.hpp"

#if !defined(PAPERTEAR_NO_SIMD) && XSIMD_WITH_AVX2
#include <immintrin.h>
#endif
#if defined(__SSE__) || defined(_M_X64)
#include <xmmintrin.h>
#define PAPERTEAR_HAS_MXCSR 1
#endif

namespace papertear {
namespace {

// CellGroup::kind: the general loader, or a regular group's slot set.
enum GroupKind : std::uint32_t { kIrregular, kScaled, kLow, kLowXSide, kLowZSide, kLowXZSide, kAll };
constexpr std::uint32_t kPatchedGroup = 1u << 8;  // or'ed into a regular kind: see RegularGroup::plan

// The springs in kSlots of W cells at once, on corner values already in registers; adds each
// spring's force, times its lane's count (`count(slot)`, kernels/fine_springs.hpp), into the
// corner sums f*. Every loader below feeds this one body, so a cell gets the same operations
// in the same order whichever way its corners were fetched.
template <class V>
struct CellSprings {
  using T = lanes::Traits<V>;

  // kUnitScale: every lane's cell factor s is exactly 1 (all cells of every scene the
  // library builds), so k = s * K is K bit for bit and the two multiplications per spring
  // are skipped.
  // Always inlined into its loader: called out of line, the corner values and sums would
  // pass through memory.
  template <std::uint32_t kSlots, bool kUnitScale, class Count>
  [[gnu::always_inline]] static inline void run(const V (&x)[8], const V (&y)[8], const V (&z)[8], const V (&u)[8], const V (&v)[8],
                  const V (&w)[8], const V& s, const SpringTable& tab, const Count& count, V (&fx)[8],
                  V (&fy)[8], V (&fz)[8]) {
    const V one = T::broadcast(1.0f);
    for (int q = 0; q < 8; ++q) fx[q] = fy[q] = fz[q] = T::broadcast(0.0f);
    // One instantiation per slot, so the loop is unrolled by construction and corner values
    // and sums index registers, not a stack array.
    auto spring = [&]<int I>() __attribute__((always_inline)) {
      if constexpr (((kSlots >> I) & 1u) != 0) {
        constexpr int a = kSpringSlots[std::size_t(I)].a, b = kSpringSlots[std::size_t(I)].b;
        const V dx = x[b] - x[a], dy = y[b] - y[a], dz = z[b] - z[a];
        const V du = u[b] - u[a], dv = v[b] - v[a], dw = w[b] - w[a];
        const V len = T::sqrt(dx * dx + dy * dy + dz * dz);
        const V inv = one / len;
        const V k = kUnitScale ? T::broadcast(tab.stiffness[std::size_t(I)]) : s * T::broadcast(tab.stiffness[std::size_t(I)]);
        const V c = kUnitScale ? T::broadcast(tab.damping[std::size_t(I)]) : s * T::broadcast(tab.damping[std::size_t(I)]);
        const V rate = (du * dx + dv * dy + dw * dz) * inv;  // Δv · d̂
        const V mag = k * (len - T::broadcast(tab.rest[std::size_t(I)])) + c * rate;
        const V g = (mag * inv) * count(I);
        const V gx = g * dx, gy = g * dy, gz = g * dz;
        fx[a] = fx[a] + gx; fy[a] = fy[a] + gy; fz[a] = fz[a] + gz;
        fx[b] = fx[b] - gx; fy[b] = fy[b] - gy; fz[b] = fz[b] - gz;
      }
    };
    [&]<int... I>(std::integer_sequence<int, I...>) __attribute__((always_inline)) {
      (spring.template operator()<I>(), ...);
    }(std::make_integer_sequence<int, kSpringsPerCell>{});
  }
};

// Any W cells of one colour: corners fetched with scalar loads into an aligned buffer, then
// loaded as vectors; forces scattered back one node at a time.
template <class V>
struct CellLanes {
  using T = lanes::Traits<V>;
  static constexpr std::size_t W = T::width;

  // Lanes below `skip` are computed but not added (their cells were done by another group).
  static void run(const std::uint32_t* cells, const CellForceInputs& in, const ForceOutputs& out,
                  std::size_t skip = 0) {
    alignas(64) float buf[6][8][W];
    alignas(64) std::uint32_t node[8][W];
    alignas(64) float scale[W];
    alignas(64) float counts[kSpringsPerCell][W];
    const float* src[6] = {in.px, in.py, in.pz, in.vx, in.vy, in.vz};
    for (std::size_t l = 0; l < W; ++l) {
      const std::uint32_t c = cells[l];
      scale[l] = in.cell_scale[c];
      for (int q = 0; q < kSpringsPerCell; ++q) counts[q][l] = float(in.fine->at(c, q));
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
    }
    const auto count = [&](int slot) { return T::load(counts[slot]); };
    CellSprings<V>::template run<kAllSlots, false>(x, y, z, u, v, w, T::load(scale), *in.table, count, fx, fy, fz);
    for (int q = 0; q < 8; ++q) {
      T::store(buf[0][q], fx[q]); T::store(buf[1][q], fy[q]); T::store(buf[2][q], fz[q]);
    }
    for (std::size_t l = skip; l < W; ++l)
      for (int q = 0; q < 8; ++q) {
        const std::uint32_t n = node[q][l];
        out.fx[n] += buf[0][q][l];
        out.fy[n] += buf[1][q][l];
        out.fz[n] += buf[2][q][l];
      }
  }
};

#if !defined(PAPERTEAR_NO_SIMD) && XSIMD_WITH_AVX2
#define PAPERTEAR_CELL_REGULAR 1

// The nodes of a run of corner pairs a regular group adds to: node 2l (lane l's dx = 0
// corner) and 2l + 1 (its dx = 1 corner). Bit t of the result is set when node t gets its
// addition: lanes below `skip` and from `lanes` on are left out, and so are the corners in
// `drop_even`/`drop_odd` (lane masks of corners whose node is a split copy elsewhere).
inline unsigned spread_bits(unsigned x) {  // bit l -> bit 2l, for 16 bits
  x = (x | (x << 8)) & 0x00FF00FFu;
  x = (x | (x << 4)) & 0x0F0F0F0Fu;
  x = (x | (x << 2)) & 0x33333333u;
  return (x | (x << 1)) & 0x55555555u;
}
inline unsigned node_keep_mask(int skip, int lanes, unsigned drop_even, unsigned drop_odd) {
  const unsigned first = 2u * unsigned(skip);
  const unsigned from_skip = first >= 32 ? 0u : ~0u << first;
  const unsigned within = unsigned((std::uint64_t(1) << (2 * lanes)) - 1u);  // a short row's lanes
  return from_skip & within & ~(spread_bits(drop_even) | (spread_bits(drop_odd) << 1));
}

// The lane type of regular groups and how it fetches and returns pairs of consecutive nodes.
// AVX-512 takes 16 cells per vector, AVX2 8. With 28 springs per cell 8 lanes had measured
// faster (48 corner values and 24 sums spill either way); with the 13 merged springs the
// per-group loads, stores and spills weigh more and 16 lanes measured 4-9 % faster
// (bench/README.md, round 5).
// AVX2: 8 cells per vector.
struct Pairs8 {
  using V = xsimd::batch<float, xsimd::avx2>;
  static constexpr int kLanes = 8;

  // Lanes l < lanes (all 8 unless a short row's) of (src[base + 2l], src[base + 2l + 1]);
  // nothing is read past them.
  static void load(const float* p, V& even, V& odd, int lanes = kLanes) {
    __m256 lo, hi;
    if (lanes == kLanes) {
      lo = _mm256_loadu_ps(p);
      hi = _mm256_loadu_ps(p + 8);
    } else {
      lo = _mm256_maskload_ps(p, node_mask(unsigned((1u << (2 * lanes)) - 1u)));
      hi = _mm256_maskload_ps(p + 8, node_mask(unsigned((1u << (2 * lanes)) - 1u) >> 8));
    }
    even = _mm256_castpd_ps(_mm256_permute4x64_pd(_mm256_castps_pd(_mm256_shuffle_ps(lo, hi, 0x88)), 0xD8));
    odd = _mm256_castpd_ps(_mm256_permute4x64_pd(_mm256_castps_pd(_mm256_shuffle_ps(lo, hi, 0xDD)), 0xD8));
  }

  // Bits 0..7 of `nodes` as an element mask.
  static __m256i node_mask(unsigned nodes) {
    const __m256i bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    return _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(int(nodes & 0xFFu)), bit), bit);
  }

  // dst[base + 2l] += even[l], dst[base + 2l + 1] += odd[l] for the nodes node_keep_mask()
  // keeps; the others are neither read nor written.
  static void add(float* p, const V& even, const V& odd, int skip, unsigned drop_even = 0, unsigned drop_odd = 0,
                  int lanes = kLanes) {
    const __m256 a = _mm256_unpacklo_ps(even, odd), b = _mm256_unpackhi_ps(even, odd);
    const __m256 add_lo = _mm256_permute2f128_ps(a, b, 0x20), add_hi = _mm256_permute2f128_ps(a, b, 0x31);
    const unsigned keep = node_keep_mask(skip, lanes, drop_even, drop_odd) & 0xFFFFu;
    if (keep == 0xFFFFu) {
      _mm256_storeu_ps(p, _mm256_add_ps(_mm256_loadu_ps(p), add_lo));
      _mm256_storeu_ps(p + 8, _mm256_add_ps(_mm256_loadu_ps(p + 8), add_hi));
      return;
    }
    // Masked: the other nodes are neither read nor written (a short row may end the columns).
    const __m256i lo = node_mask(keep), hi = node_mask(keep >> 8);
    _mm256_maskstore_ps(p, lo, _mm256_add_ps(_mm256_maskload_ps(p, lo), add_lo));
    _mm256_maskstore_ps(p + 8, hi, _mm256_add_ps(_mm256_maskload_ps(p + 8, hi), add_hi));
  }

  // `v` with lane l set to `value`.
  static V insert(const V& v, int l, float value) {
    const __m256i lane = _mm256_set1_epi32(l), ids = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    return _mm256_blendv_ps(v, _mm256_set1_ps(value), _mm256_castsi256_ps(_mm256_cmpeq_epi32(ids, lane)));
  }
  // Lane l of `v`.
  static float lane(const V& v, int l) {
    return _mm_cvtss_f32(_mm256_castps256_ps128(_mm256_permutevar8x32_ps(v, _mm256_set1_epi32(l))));
  }

  // Bytes first[2l], widened to floats.
  static V even_bytes(const std::uint8_t* first) {
    const __m128i pick = _mm_setr_epi8(0, 2, 4, 6, 8, 10, 12, 14, -1, -1, -1, -1, -1, -1, -1, -1);
    const __m128i bytes = _mm_loadu_si128(reinterpret_cast<const __m128i*>(first));
    return _mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(_mm_shuffle_epi8(bytes, pick)));
  }

  // The bitwise or of first[2l] over the lanes.
  static std::uint32_t or_even(const std::uint32_t* first) {
    std::uint32_t bits = 0;
    for (int l = 0; l < kLanes; ++l) bits |= first[2 * l];
    return bits;
  }

  // True when cells[l] == cells[0] + 2l for every lane.
  static bool stride_two(const std::uint32_t* cells) {
    const __m256i two_l = _mm256_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14);
    const __m256i ids = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(cells));
    return _mm256_movemask_epi8(_mm256_cmpeq_epi32(ids, _mm256_add_epi32(_mm256_set1_epi32(int(cells[0])), two_l))) == -1;
  }
};

#if XSIMD_WITH_AVX512F
// AVX-512: 16 cells per vector.
struct Pairs16 {
  using V = xsimd::batch<float, xsimd::avx512f>;
  static constexpr int kLanes = 16;

  static void load(const float* p, V& even, V& odd, int lanes = kLanes) {
    const unsigned nodes = unsigned((std::uint64_t(1) << (2 * lanes)) - 1u);
    const __m512 lo = lanes == kLanes ? _mm512_loadu_ps(p) : _mm512_maskz_loadu_ps(__mmask16(nodes), p);
    const __m512 hi = lanes == kLanes ? _mm512_loadu_ps(p + 16) : _mm512_maskz_loadu_ps(__mmask16(nodes >> 16), p + 16);
    const __m512i e = _mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30);
    even = _mm512_permutex2var_ps(lo, e, hi);
    odd = _mm512_permutex2var_ps(lo, _mm512_add_epi32(e, _mm512_set1_epi32(1)), hi);
  }

  static void add(float* p, const V& even, const V& odd, int skip, unsigned drop_even = 0, unsigned drop_odd = 0,
                  int lanes = kLanes) {
    const __m512i lo_idx = _mm512_setr_epi32(0, 16, 1, 17, 2, 18, 3, 19, 4, 20, 5, 21, 6, 22, 7, 23);
    const __m512 a = _mm512_permutex2var_ps(even, lo_idx, odd);
    const __m512 b = _mm512_permutex2var_ps(even, _mm512_add_epi32(lo_idx, _mm512_set1_epi32(8)), odd);
    // Nodes 2l and 2l + 1 belong to lane l; the others are neither read nor written.
    const unsigned keep = node_keep_mask(skip, lanes, drop_even, drop_odd);
    const __mmask16 lo = __mmask16(keep), hi = __mmask16(keep >> 16);
    _mm512_mask_storeu_ps(p, lo, _mm512_add_ps(_mm512_maskz_loadu_ps(lo, p), a));
    _mm512_mask_storeu_ps(p + 16, hi, _mm512_add_ps(_mm512_maskz_loadu_ps(hi, p + 16), b));
  }

  static V insert(const V& v, int l, float value) {
    return _mm512_mask_broadcastss_ps(v, __mmask16(1u << l), _mm_set_ss(value));
  }
  static float lane(const V& v, int l) {
    return _mm_cvtss_f32(_mm512_castps512_ps128(_mm512_permutexvar_ps(_mm512_set1_epi32(l), v)));
  }

  static V even_bytes(const std::uint8_t* first) {
    const __m256i bytes = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(first));
    const __m512i words = _mm512_and_si512(_mm512_cvtepu16_epi32(bytes), _mm512_set1_epi32(0xFF));
    return _mm512_cvtepi32_ps(words);
  }

  static std::uint32_t or_even(const std::uint32_t* first) {
    const __m512i even = _mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30);
    const __m512i picked = _mm512_permutex2var_epi32(_mm512_loadu_si512(first), even, _mm512_loadu_si512(first + 16));
    return std::uint32_t(_mm512_reduce_or_epi32(picked));
  }

  static bool stride_two(const std::uint32_t* cells) {
    const __m512i two_l = _mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30);
    const __m512i ids = _mm512_loadu_si512(cells);
    return _mm512_cmpeq_epi32_mask(ids, _mm512_add_epi32(_mm512_set1_epi32(int(cells[0])), two_l)) == 0xFFFF;
  }
};
using CellPairs = Pairs16;
#else
using CellPairs = Pairs8;
#endif
using CellLane = CellPairs::V;

// A "regular" group: kLanes cells of a colour along one row (ids c, c+2, c+4, ...) whose
// corner nodes also advance by 2 per cell, with each dx = 1 corner the node right after its
// dx = 0 corner. Before any split that is every group (core/solver.cpp hands out whole rows
// and add_rows_with never lets a group straddle a row end). Then the 2 kLanes nodes of a
// corner pair (dy, dz) are contiguous: two vector loads and an even/odd permute fetch them
// for all cells, and the forces go back the same way. Each lane still sees exactly the
// values the general loader would give it, and each node still gets one addition, so the
// bits match.
template <class P>
struct RegularGroup {
  using V = typename P::V;
  static constexpr int L = P::kLanes;

  // The first node of each corner pair (dy, dz), or false when the group is not regular.
  // `owned` is the or of the lanes' FineSprings::owned: without kSplitCorner every corner is
  // its vertex's original node, whose id is the vertex id, so the nodes advance with the
  // cells unless the group crosses a row end, which adds one vertex (seen at the last lane).
  static bool bases(const std::uint32_t* cells, const std::uint32_t* cell_nodes, std::uint32_t owned,
                    std::uint32_t (&base)[4]) {
    if ((owned & kSplitCorner) != 0 || !P::stride_two(cells)) return false;
    const std::uint32_t* row0 = cell_nodes + std::size_t(cells[0]) * 8;
    if (cell_nodes[std::size_t(cells[L - 1]) * 8] != row0[0] + 2 * (L - 1)) return false;
    for (int p = 0; p < 4; ++p) base[p] = row0[2 * p];
    return true;
  }

  // The lanes' counts of one slot (kernels/fine_springs.hpp), from the slot's row of bytes.
  struct RowCounts {
    const std::uint8_t* first;  // the slot-0 count of cells[0]
    std::size_t stride;         // cells per slot row
    V operator()(int slot) const { return P::even_bytes(first + std::size_t(slot) * stride); }
  };

  // Loads the corners, runs the springs in kSlots and adds the forces back. One function per
  // slot set, each compiled on its own: inlined side by side into one dispatcher, the rare
  // sets' code made the common one's register allocation worse (the kernel ran ~20 % slower).
  // kPatched: the corners in g.patch are split copies, fetched and returned one lane at a
  // time on top of the pair loads and stores, which leave them out (~10 of a group's 128
  // corners: single-lane inserts measured cheaper than 16-lane gathers and scatters).
  template <std::uint32_t kSlots, bool kUnitScale, bool kPatched>
  [[gnu::noinline]] static void evaluate(const CellGroup& g, const CellForceInputs& in, const ForceOutputs& out,
                                         int skip) {
    V x[8], y[8], z[8], u[8], v[8], w[8];
    const float* src[6] = {in.px, in.py, in.pz, in.vx, in.vy, in.vz};
    V* dst[6] = {x, y, z, u, v, w};
    const int lanes = int(g.lanes);
    for (int p = 0; p < 4; ++p)
      for (int f = 0; f < 6; ++f) P::load(src[f] + g.base[p], dst[f][2 * p], dst[f][2 * p + 1], lanes);
    if constexpr (kPatched)
      for (int q = 0; q < 8; ++q)
        for (unsigned left = g.patch[q]; left != 0; left &= left - 1) {
          const int l = std::countr_zero(left);
          const std::uint32_t node = patched_node(g, in.cell_nodes, l, q);
          for (int f = 0; f < 6; ++f) dst[f][q] = P::insert(dst[f][q], l, src[f][node]);
        }
    alignas(64) float scale[L];
    for (int l = 0; l < L; ++l)
      scale[l] = kUnitScale || l >= lanes ? 1.0f : in.cell_scale[g.first_cell + 2 * std::uint32_t(l)];
    const RowCounts count{in.fine->count.data() + g.first_cell, in.fine->cells};
    V fx[8], fy[8], fz[8];
    CellSprings<V>::template run<kSlots, kUnitScale>(x, y, z, u, v, w, V::load_aligned(scale), *in.table, count, fx,
                                                     fy, fz);
    float* dst_f[3] = {out.fx, out.fy, out.fz};
    const V* force[3] = {fx, fy, fz};
    for (int p = 0; p < 4; ++p)
      for (int f = 0; f < 3; ++f)
        P::add(dst_f[f] + g.base[p], force[f][2 * p], force[f][2 * p + 1], skip, kPatched ? g.patch[2 * p] : 0u,
               kPatched ? g.patch[2 * p + 1] : 0u, lanes);
    if constexpr (kPatched)
      for (int q = 0; q < 8; ++q) {
        for (unsigned left = g.patch[q] & (~0u << skip); left != 0; left &= left - 1) {
          const int l = std::countr_zero(left);
          const std::uint32_t node = patched_node(g, in.cell_nodes, l, q);
          for (int f = 0; f < 3; ++f) dst_f[f][node] += P::lane(force[f][q], l);
        }
      }
  }

  // The node at corner q of lane l's cell (a patched corner's split copy).
  static std::uint32_t patched_node(const CellGroup& g, const std::uint32_t* cell_nodes, int l, int q) {
    return cell_nodes[(std::size_t(g.first_cell) + 2 * std::size_t(l)) * 8 + std::size_t(q)];
  }

  // The smallest slot set that covers the springs the group's cells own (a slot no lane owns
  // would only add zeros): the 13 low slots for most groups, those plus the high-x or high-z
  // side at the sheet's edges, all 28 near cracks or with stiffness factors. Also the corner
  // pairs' first nodes; kIrregular when the group needs the general loader. With the lattice
  // dimensions a group with split copies among its corners is still planned as regular, its
  // corner pairs' first nodes those of the lattice vertices, and patched where a corner's node
  // is not its vertex's: after a tear most groups have a few such corners (~10 of 128 in the
  // default scene's damage zone), and the general loader made them ~3x a regular group.
  // `lanes` < L: a row of that many cells, shorter than a vector; its group leaves the other
  // lanes' nodes alone (masked loads and stores).
  static CellGroup plan(const std::uint32_t* cells, const CellForceInputs& in, const LatticeDims* dims, int lanes = L) {
    CellGroup g{{0, 0, 0, 0}, cells[0], kIrregular, {}, std::uint32_t(lanes)};
    std::uint32_t owned = 0;
    if (lanes == L) owned = P::or_even(in.fine->owned.data() + cells[0]);
    else
      for (int l = 0; l < lanes; ++l) owned |= in.fine->owned[cells[l]];
    bool patched = false;
    if (lanes == L && (owned & kSplitCorner) == 0) {
      if (!bases(cells, in.cell_nodes, owned, g.base)) return g;
    } else {
      if (dims == nullptr) return g;
      for (int l = 1; l < lanes; ++l)
        if (cells[l] != cells[0] + 2u * unsigned(l)) return g;
      const std::array<int, 3> ijk = dims->cell_ijk(cells[0]);
      if (ijk[0] + 2 * (lanes - 1) >= dims->nx) return g;  // not within one row
      for (int p = 0; p < 4; ++p) g.base[p] = dims->vertex_index(ijk[0], ijk[1] + (p & 1), ijk[2] + (p >> 1));
      for (int l = 0; l < lanes; ++l)
        for (int q = 0; q < 8; ++q)
          if (in.cell_nodes[std::size_t(cells[l]) * 8 + std::size_t(q)] != g.base[q >> 1] + 2u * unsigned(l) + unsigned(q & 1))
            g.patch[q] = std::uint16_t(g.patch[q] | (1u << l));
      patched = std::any_of(std::begin(g.patch), std::end(g.patch), [](std::uint16_t m) { return m != 0; });
    }
    auto within = [owned](std::uint32_t slots) { return (owned & ~slots) == 0; };
    constexpr std::uint32_t kLowX = kLowSlots | kHighXSlots, kLowZ = kLowSlots | kHighZSlots;
    constexpr std::uint32_t kLowXZ = kLowSlots | kHighXSlots | kHighZSlots | kHighXZSlots;
    if ((owned & kScaledCell) != 0) g.kind = kScaled;
    else if (within(kLowSlots)) g.kind = kLow;
    else if (within(kLowX)) g.kind = kLowXSide;
    else if (within(kLowZ)) g.kind = kLowZSide;
    else if (within(kLowXZ)) g.kind = kLowXZSide;
    else g.kind = kAll;
    if (patched) g.kind |= kPatchedGroup;
    return g;
  }

  template <std::uint32_t kSlots, bool kUnitScale>
  static void evaluate_as_planned(const CellGroup& g, const CellForceInputs& in, const ForceOutputs& out, int skip) {
    if ((g.kind & kPatchedGroup) != 0) evaluate<kSlots, kUnitScale, true>(g, in, out, skip);
    else evaluate<kSlots, kUnitScale, false>(g, in, out, skip);
  }

  // Runs a regular group as planned; false for an irregular one.
  static bool run(const CellGroup& g, const CellForceInputs& in, const ForceOutputs& out, std::size_t skip) {
    constexpr std::uint32_t kLowX = kLowSlots | kHighXSlots, kLowZ = kLowSlots | kHighZSlots;
    constexpr std::uint32_t kLowXZ = kLowSlots | kHighXSlots | kHighZSlots | kHighXZSlots;
    const int sk = int(skip);
    switch (g.kind & ~kPatchedGroup) {
      case kScaled: evaluate_as_planned<kAllSlots, false>(g, in, out, sk); return true;
      case kLow: evaluate_as_planned<kLowSlots, true>(g, in, out, sk); return true;
      case kLowXSide: evaluate_as_planned<kLowX, true>(g, in, out, sk); return true;
      case kLowZSide: evaluate_as_planned<kLowZ, true>(g, in, out, sk); return true;
      case kLowXZSide: evaluate_as_planned<kLowXZ, true>(g, in, out, sk); return true;
      case kAll: evaluate_as_planned<kAllSlots, true>(g, in, out, sk); return true;
      default: return false;
    }
  }
};
#else
using CellLane = lanes::Wide;
#endif

// How a group of W cells is run: planned from its cells (regular groups only with the
// regular lane type; every other group takes the general loader).
template <class V>
CellGroup plan_group(const std::uint32_t* cells, const CellForceInputs& in, const LatticeDims* dims = nullptr,
                     std::size_t lanes = CellLanes<V>::W) {
#ifdef PAPERTEAR_CELL_REGULAR
  if constexpr (std::is_same_v<V, CellLane>) return RegularGroup<CellPairs>::plan(cells, in, dims, int(lanes));
#endif
  (void)dims;
  return {{0, 0, 0, 0}, cells[0], kIrregular, {}, std::uint32_t(lanes)};
}

// Runs W cells from `cells` as planned, adding only lanes >= skip.
template <class V>
void run_group(const CellGroup& plan, const std::uint32_t* cells, const CellForceInputs& in, const ForceOutputs& out,
               std::size_t skip) {
#ifdef PAPERTEAR_CELL_REGULAR
  if constexpr (std::is_same_v<V, CellLane>)
    if (RegularGroup<CellPairs>::run(plan, in, out, skip)) return;
#endif
  CellLanes<V>::run(cells, in, out, skip);
}

// A planned group if it is regular; false (nothing done) otherwise.
template <class V>
bool run_regular(const CellGroup& plan, const CellForceInputs& in, const ForceOutputs& out) {
#ifdef PAPERTEAR_CELL_REGULAR
  if constexpr (std::is_same_v<V, CellLane>) return RegularGroup<CellPairs>::run(plan, in, out, 0);
#endif
  (void)plan, (void)in, (void)out;
  return false;
}

template <class V>
void add_group(const std::uint32_t* cells, const CellForceInputs& in, const ForceOutputs& out, std::size_t skip) {
  run_group<V>(plan_group<V>(cells, in), cells, in, out, skip);
}

// Groups of W from `begin`; the n < W cells left at the end go in one more vector group
// whose first W - n lanes are computed but not added: the last W cells of the range (lanes
// the group before already added), or, in a range shorter than W, copies of its first cell.
// Why not scalar: unplanned, a row of a sheet narrower than 32 cells holds fewer than 16
// cells of a colour, and one lane at a time made such rows ~10x slower per cell. A lane gets
// the same operations whatever its group, so the bits are the same.
template <class V>
void add_forces_with(std::size_t begin, std::size_t end, const std::uint32_t* cells,
                     const CellForceInputs& in, const ForceOutputs& out) {
  constexpr std::size_t W = CellLanes<V>::W;
  std::size_t i = begin;
  for (; i + W <= end; i += W) add_group<V>(cells + i, in, out, 0);
  if (i == end) return;
  const std::size_t skip = W - (end - i);
  if (end - begin >= W) {
    add_group<V>(cells + end - W, in, out, skip);
    return;
  }
  std::uint32_t padded[W];
  for (std::size_t l = 0; l < W; ++l) padded[l] = cells[l < skip ? begin : begin + l - skip];
  add_group<V>(padded, in, out, skip);
}

// Group g of a row of per_row cells: groups of W from the row's start, and a row whose
// length is not a multiple of W ends with a group overlapping the one before it, whose
// already-done lanes are computed but not added; a row shorter than W is one group of its
// own cells. So no group straddles a row end and every group can be regular.
struct RowGroup {
  std::size_t offset, skip;
};
RowGroup row_group(std::size_t per_row, std::size_t g, std::size_t W) {
  if (per_row < W) return {0, 0};  // the row's one (short) group
  const std::size_t start = g * W;
  return start + W <= per_row ? RowGroup{start, 0} : RowGroup{per_row - W, start + W - per_row};
}

template <class V>
void add_rows_with(std::size_t begin, std::size_t end, std::size_t per_row, const std::uint32_t* cells,
                   const CellForceInputs& in, const ForceOutputs& out, const CellGroup* plan) {
  constexpr std::size_t W = CellLanes<V>::W;
  if (per_row < W) {  // rows shorter than a vector: planned regular groups with masked lanes
    if (plan == nullptr) {
      add_forces_with<V>(begin, end, cells, in, out);
      return;
    }
    for (std::size_t row = begin; row < end; row += per_row)
      if (!run_regular<V>(plan[row / per_row], in, out)) add_forces_with<V>(row, row + per_row, cells, in, out);
    return;
  }
  const std::size_t groups = cell_groups_per_row(per_row);
  for (std::size_t row = begin; row < end; row += per_row)
    for (std::size_t g = 0; g < groups; ++g) {
      const RowGroup at = row_group(per_row, g, W);
      const std::uint32_t* group = cells + row + at.offset;
      if (plan != nullptr) run_group<V>(plan[row / per_row * groups + g], group, in, out, at.skip);
      else add_group<V>(group, in, out, at.skip);
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

void add_cell_forces(std::size_t begin, std::size_t end, const std::uint32_t* cells,
                     const CellForceInputs& in, const ForceOutputs& out) {
  const FlushSubnormals flush;
  add_forces_with<CellLane>(begin, end, cells, in, out);
}

void add_cell_row_forces(std::size_t begin, std::size_t end, std::size_t per_row, const std::uint32_t* cells,
                         const CellForceInputs& in, const ForceOutputs& out, const CellGroup* plan) {
  const FlushSubnormals flush;
  add_rows_with<CellLane>(begin, end, per_row, cells, in, out, plan);
}

std::size_t cell_groups_per_row(std::size_t per_row) {
  constexpr std::size_t W = CellLanes<CellLane>::W;
  return (per_row + W - 1) / W;
}

void plan_cell_rows(std::size_t row_begin, std::size_t row_end, std::size_t per_row, const std::uint32_t* cells,
                    const LatticeDims& dims, const CellForceInputs& in, CellGroup* plan) {
  constexpr std::size_t W = CellLanes<CellLane>::W;
  const std::size_t groups = cell_groups_per_row(per_row);
  for (std::size_t row = row_begin; row < row_end; ++row)
    for (std::size_t g = 0; g < groups; ++g)
      plan[row * groups + g] =
          plan_group<CellLane>(cells + row * per_row + row_group(per_row, g, W).offset, in, &dims, std::min(per_row, W));
}

void add_cell_forces_scalar(std::size_t begin, std::size_t end, const std::uint32_t* cells,
                            const CellForceInputs& in, const ForceOutputs& out) {
  const FlushSubnormals flush;
  add_forces_with<float>(begin, end, cells, in, out);
}

}  // namespace papertear
