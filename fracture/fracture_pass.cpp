#include "fracture/fracture_pass.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>

#include "core/solver.hpp"
#include "fracture/node_cells.hpp"
#include "kernels/parallel.hpp"
#include "kernels/spring.hpp"

#if defined(__AVX512F__)
// GCC 12 warns inside its own avx512fintrin.h where an _mm512_undefined_* is inlined
// (uninitialised by design), as in kernels/lanes.hpp.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <immintrin.h>
#endif

namespace papertear {
namespace {


float edge_strain(const World& w, std::uint32_t cell, int slot) {
  const SpringSlot& s = kSpringSlots[std::size_t(slot)];
  const std::uint32_t a = w.topo.node(cell, s.a), b = w.topo.node(cell, s.b);
  const float dx = w.nodes.px[b] - w.nodes.px[a], dy = w.nodes.py[b] - w.nodes.py[a],
              dz = w.nodes.pz[b] - w.nodes.pz[a];
  const float rest = w.springs.rest[std::size_t(slot)];
  return (std::sqrt(dx * dx + dy * dy + dz * dz) - rest) / rest;
}

float face_strength(const World& w, std::uint32_t cell, int axis, int side) {
  return w.topo.face_strain[std::size_t(cell) * kFacesPerCell + std::size_t(2 * axis + side)];
}

// The largest squared length d2 for which an edge of this slot cannot be a candidate when
// every bond it could open has strength >= `weakest`. Strain is (sqrt(d2) - L0) / L0 in
// float, and correctly rounded sqrt, subtraction and division by L0 > 0 are each
// monotonic, so strain is monotonic in d2: if d2 <= bound then strain(d2) <= strain(bound)
// <= weakest. The bound is found in double and then stepped down until the float formula
// itself confirms it, so the filter never drops a candidate that the exact test would keep.
float safe_squared_length(float rest, float weakest) {
  if (!(weakest < INFINITY)) return INFINITY;  // unbreakable: no strain exceeds it
  auto strain = [rest](float d2) { return (std::sqrt(d2) - rest) / rest; };
  const double len = (1.0 + double(weakest)) * double(rest);
  float bound = float(len * len * (1.0 - 1e-6));
  for (int tries = 0; tries < 64 && bound > 0.0f; ++tries) {
    if (strain(bound) <= weakest) return bound;
    bound = std::nextafter(bound, 0.0f) * (1.0f - 1e-6f);
  }
  return -INFINITY;  // no safe bound found: check every edge exactly
}

// Bit s set when edge s of the cell (corners x, y, z) has squared length above bound[s]
// (false for NaN, like the exact test). Candidates are ascending in s either way.
constexpr std::array<int, 16> kEdgeEnd(int which) {
  std::array<int, 16> out{};
  for (int s = 0; s < kEdgesPerCell; ++s) out[std::size_t(s)] = which ? kSpringSlots[std::size_t(s)].b : kSpringSlots[std::size_t(s)].a;
  return out;
}
alignas(64) constexpr std::array<int, 16> kEdgeA = kEdgeEnd(0), kEdgeB = kEdgeEnd(1);

#if defined(__AVX512F__)
unsigned edges_over_bound(const float (&x)[8], const float (&y)[8], const float (&z)[8], const float (&bound)[16]) {
  const __m512i ia = _mm512_load_si512(kEdgeA.data()), ib = _mm512_load_si512(kEdgeB.data());
  auto diff = [&](const float (&v)[8]) {
    const __m512 all = _mm512_zextps256_ps512(_mm256_load_ps(v));
    return _mm512_sub_ps(_mm512_permutexvar_ps(ib, all), _mm512_permutexvar_ps(ia, all));
  };
  const __m512 dx = diff(x), dy = diff(y), dz = diff(z);
  const __m512 d2 = _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(dx, dx), _mm512_mul_ps(dy, dy)), _mm512_mul_ps(dz, dz));
  return unsigned(_mm512_cmp_ps_mask(d2, _mm512_loadu_ps(bound), _CMP_GT_OQ)) & 0xfffu;
}
#else
unsigned edges_over_bound(const float (&x)[8], const float (&y)[8], const float (&z)[8], const float (&bound)[16]) {
  unsigned over = 0;
  for (int s = 0; s < kEdgesPerCell; ++s) {
    const SpringSlot& slot = kSpringSlots[std::size_t(s)];
    const float dx = x[slot.b] - x[slot.a], dy = y[slot.b] - y[slot.a], dz = z[slot.b] - z[slot.a];
    if (dx * dx + dy * dy + dz * dz > bound[s]) over |= 1u << s;
  }
  return over;
}
#endif

// The weakest bond strength among cells [begin, end): a lower bound is all the filter below
// needs, and 8 lanes of min cut the serial dependency chain of a scalar min eightfold.
float weakest_strength(const float* strength, std::size_t begin, std::size_t end) {
  std::size_t i = begin * kFacesPerCell;
  const std::size_t stop = end * kFacesPerCell;
  float weakest = INFINITY;
#if defined(__AVX2__)
  __m256 lanes = _mm256_set1_ps(INFINITY);
  for (; i + 8 <= stop; i += 8) lanes = _mm256_min_ps(lanes, _mm256_loadu_ps(strength + i));
  alignas(32) float part[8];
  _mm256_store_ps(part, lanes);
  for (float v : part) weakest = std::min(weakest, v);
#endif
  for (; i < stop; ++i) weakest = std::min(weakest, strength[i]);
  return weakest;
}

// The exact test for the edges of `cell` flagged in `over` (ascending slots): only it decides.
void confirm(const World& w, std::uint32_t cell, unsigned over, std::vector<FractureCandidate>& out) {
  for (; over != 0; over &= over - 1) {
    const int s = std::countr_zero(over);
    const int axis = kSpringSlots[std::size_t(s)].axis;
    const float weaker = std::min(face_strength(w, cell, axis, 0), face_strength(w, cell, axis, 1));
    const float strain = edge_strain(w, cell, s);
    if (strain > weaker) out.push_back({strain / weaker, cell * kSpringsPerCell + std::uint32_t(s)});
  }
}

unsigned cell_edges_over_bound(const World& w, std::size_t c, const float (&bound)[16]) {
  const NodeStore& n = w.nodes;
  const std::uint32_t* corner = w.topo.cell_nodes.data() + c * 8;
  alignas(32) float x[8], y[8], z[8];
  for (int q = 0; q < 8; ++q) {
    x[q] = n.px[corner[q]];
    y[q] = n.py[corner[q]];
    z[q] = n.pz[corner[q]];
  }
  return edges_over_bound(x, y, z, bound);
}

#if defined(__AVX2__)
// Eight consecutive cells c..c+7 whose corner nodes also advance by one per cell: cells
// along one lattice row before any split touched them (most of the sheet on most steps).
// Then corner q of the 8 cells is 8 consecutive nodes, fetched with one vector load per
// coordinate instead of 8 scalar loads per cell.
bool regular_run(const std::uint32_t* corners) {
  const __m256i first = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(corners));
  __m256i same = _mm256_set1_epi32(-1);
  for (int l = 1; l < 8; ++l) {
    const __m256i row = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(corners + 8 * l));
    same = _mm256_and_si256(same, _mm256_cmpeq_epi32(row, _mm256_add_epi32(first, _mm256_set1_epi32(l))));
  }
  return _mm256_movemask_epi8(same) == -1;
}

// over[l]: bit s set when edge s of cell c + l has squared length above bound[s] (false for
// NaN). The same filter as edges_over_bound, eight cells per vector.
void run_edges_over_bound(const NodeStore& n, const std::uint32_t* corners, const float (&bound)[16],
                          std::uint32_t (&over)[8]) {
  __m256 x[8], y[8], z[8];
  for (int q = 0; q < 8; ++q) {
    x[q] = _mm256_loadu_ps(n.px.data() + corners[q]);
    y[q] = _mm256_loadu_ps(n.py.data() + corners[q]);
    z[q] = _mm256_loadu_ps(n.pz.data() + corners[q]);
  }
  __m256i bits = _mm256_setzero_si256();
  for (int s = 0; s < kEdgesPerCell; ++s) {
    const int a = kSpringSlots[std::size_t(s)].a, b = kSpringSlots[std::size_t(s)].b;
    const __m256 dx = _mm256_sub_ps(x[b], x[a]), dy = _mm256_sub_ps(y[b], y[a]), dz = _mm256_sub_ps(z[b], z[a]);
    const __m256 d2 = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)), _mm256_mul_ps(dz, dz));
    const __m256 above = _mm256_cmp_ps(d2, _mm256_set1_ps(bound[s]), _CMP_GT_OQ);
    bits = _mm256_or_si256(bits, _mm256_and_si256(_mm256_castps_si256(above), _mm256_set1_epi32(1 << s)));
  }
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(over), bits);
}
#endif

// Candidates among cells [begin, end). Most edges are far from breaking, so each is first
// compared by squared length against a bound valid for the whole chunk (no sqrt, no
// division); only edges above it take the exact test, which alone decides. The filter is
// conservative whichever path computes it, so the candidates never depend on the path.
void detect(std::size_t begin, std::size_t end, const World& w, std::vector<FractureCandidate>& out) {
  out.clear();
  const float weakest = weakest_strength(w.topo.face_strain.data(), begin, end);
  float bound[16] = {};
  for (int s = 0; s < kEdgesPerCell; ++s) bound[s] = safe_squared_length(w.springs.rest[std::size_t(s)], weakest);
  std::size_t c = begin;
  while (c < end) {
#if defined(__AVX2__)
    const std::uint32_t* corners = w.topo.cell_nodes.data() + c * 8;
    if (c + 8 <= end && regular_run(corners)) {
      std::uint32_t over[8];
      run_edges_over_bound(w.nodes, corners, bound, over);
      for (std::uint32_t l = 0; l < 8; ++l)
        if (over[l] != 0) confirm(w, std::uint32_t(c) + l, over[l], out);
      c += 8;
      continue;
    }
#endif
    confirm(w, std::uint32_t(c), cell_edges_over_bound(w, c, bound), out);
    ++c;
  }
}

// Σ|f| over the springs attached to a node: its cells' fine springs and intact block springs.
double force_sum(const World& w, std::uint32_t node) {
  const NodeStore& n = w.nodes;
  auto magnitude = [&](std::uint32_t a, std::uint32_t b, float rest, float k, float c) {
    return double(eval_spring(n.px[a], n.py[a], n.pz[a], n.px[b], n.py[b], n.pz[b], n.vx[a], n.vy[a],
                              n.vz[a], n.vx[b], n.vy[b], n.vz[b], rest, k, c).magnitude);
  };
  double sum = 0.0;
  for (const CellCorner& cc : cells_of_node(w, node)) {
    const float scale = w.topo.cell_scale[cc.cell];
    for (int s = 0; s < kSpringsPerCell; ++s) {
      const SpringSlot& slot = kSpringSlots[std::size_t(s)];
      if (slot.a != cc.corner && slot.b != cc.corner) continue;
      sum += magnitude(w.topo.node(cc.cell, slot.a), w.topo.node(cc.cell, slot.b), w.springs.rest[std::size_t(s)],
                       scale * w.springs.stiffness[std::size_t(s)], scale * w.springs.damping[std::size_t(s)]);
    }
    const Block& blk = w.blocks[w.topo.cell_block[cc.cell]];
    if (!blk.intact) continue;
    const CoarseSprings& cs = w.coarse;
    for (std::uint32_t i = blk.first_spring; i < blk.first_spring + blk.spring_count; ++i)
      if ((cs.cell_a[i] == cc.cell && cs.corner_a[i] == cc.corner) ||
          (cs.cell_b[i] == cc.cell && cs.corner_b[i] == cc.corner))
        sum += magnitude(w.topo.node(cs.cell_a[i], cs.corner_a[i]), w.topo.node(cs.cell_b[i], cs.corner_b[i]),
                         cs.rest[i], cs.stiffness[i], cs.damping[i]);
  }
  return sum;
}

// True when some cell using `node` lies on the other side of the plane than `side`.
bool shared_across(const World& w, std::uint32_t node, int axis, int side) {
  for (const CellCorner& cc : cells_of_node(w, node))
    if (corner_bit(cc.corner, axis) != side) return true;
  return false;
}

void enter_block(World& w, std::uint32_t b) {
  Block& blk = w.blocks[b];
  if (!blk.intact) return;
  blk.intact = false;
  for (std::uint32_t i = blk.first_spring; i < blk.first_spring + blk.spring_count; ++i)
    w.coarse.stiffness[i] = w.coarse.damping[i] = 0.0f;
}

void copy_node(World& w, std::uint32_t from, std::uint32_t to) {
  NodeStore& n = w.nodes;
  n.px[to] = n.px[from]; n.py[to] = n.py[from]; n.pz[to] = n.pz[from];
  n.vx[to] = n.vx[from]; n.vy[to] = n.vy[from]; n.vz[to] = n.vz[from];
  n.vertex[to] = n.vertex[from];
  n.grip[to] = n.grip[from];
  n.free_mask[to] = n.free_mask[from];
  IntegratorScratch& s = w.scratch;
  s.sx[to] = n.px[to]; s.sy[to] = n.py[to]; s.sz[to] = n.pz[to];
  s.svx[to] = n.vx[to]; s.svy[to] = n.vy[to]; s.svz[to] = n.vz[to];
  if (n.grip[to] != 0) w.gripped_nodes.push_back(to);  // the newest id: the list stays ascending
}

void set_mass(World& w, std::uint32_t node, int cells) {
  const LatticeDims& d = w.topo.dims;
  const double m = w.scene.sheet.density * d.hx * d.hy * d.hz / 8.0 * cells;
  w.nodes.mass[node] = float(m);
  w.nodes.inv_mass[node] = float(1.0 / m);
}

// Tries to split the end of edge spring (cell, slot) chosen by the paper's rule; returns
// whether a split happened.
bool break_spring(World& w, std::uint32_t cell, int slot) {
  const SpringSlot& s = kSpringSlots[std::size_t(slot)];
  const int axis = s.axis;
  const float strain = edge_strain(w, cell, slot);
  std::uint32_t end_node[2] = {w.topo.node(cell, s.a), w.topo.node(cell, s.b)};
  bool eligible[2];
  for (int side = 0; side < 2; ++side)
    eligible[side] = strain > face_strength(w, cell, axis, side) && shared_across(w, end_node[side], axis, side);
  int side;
  if (eligible[0] && eligible[1]) side = force_sum(w, end_node[1]) > force_sum(w, end_node[0]) ? 1 : 0;
  else if (eligible[0]) side = 0;
  else if (eligible[1]) side = 1;
  else return false;
  const NodeId fresh = split_node(w, NodeId(end_node[side]), axis, side);
  if (!fresh.valid()) return false;
  w.events.push_back({w.step + 1, end_node[side], fresh.value, std::uint8_t(axis), axis == 2, cell, std::uint8_t(slot)});
  return true;
}

}  // namespace

NodeId split_node(World& w, NodeId split, int axis, int side) {
  const NodeCells cells = cells_of_node(w, split.value);
  unsigned moving = 0;
  for (int i = 0; i < cells.count; ++i)
    if (corner_bit(cells.items[std::size_t(i)].corner, axis) == side) moving |= 1u << i;
  return separate_node(w, split, moving);
}

NodeId separate_node(World& w, NodeId split, unsigned moving_mask) {
  const std::uint32_t node = split.value;
  const NodeCells cells = cells_of_node(w, node);
  auto moves = [&](int i) { return ((moving_mask >> i) & 1u) != 0; };
  int moving = 0;
  for (int i = 0; i < cells.count; ++i) moving += moves(i);
  if (moving == 0 || moving == cells.count) return NodeId{};
  const auto fresh = std::uint32_t(w.nodes.count);
  w.nodes.resize(w.nodes.count + 1);
  w.scratch.resize(w.nodes.count);
  copy_node(w, node, fresh);
  for (int i = 0; i < cells.count; ++i)
    if (moves(i)) {
      const CellCorner& cc = cells.items[std::size_t(i)];
      w.topo.cell_nodes[std::size_t(cc.cell) * 8 + cc.corner] = fresh;
    }
  set_mass(w, node, cells.count - moving);
  set_mass(w, fresh, moving);
  // A block with cells on both sides has been entered by the crack.
  for (int a = 0; a < cells.count; ++a)
    for (int b = 0; b < cells.count; ++b) {
      const std::uint32_t block = w.topo.cell_block[cells.items[std::size_t(a)].cell];
      if (moves(a) && !moves(b) && block == w.topo.cell_block[cells.items[std::size_t(b)].cell])
        enter_block(w, block);
    }
  return NodeId(fresh);
}

std::size_t fracture_pass(World& w, FractureScratch& scratch) {
  const std::size_t cells = std::size_t(w.topo.dims.cells());
  scratch.per_chunk.resize(chunk_count(cells, kCellChunk));
  parallel_chunks(cells, kCellChunk, [&](std::size_t b, std::size_t e, std::size_t c) {
    detect(b, e, w, scratch.per_chunk[c]);
  });
  scratch.all.clear();
  for (const auto& part : scratch.per_chunk) scratch.all.insert(scratch.all.end(), part.begin(), part.end());
  if (scratch.all.empty()) return 0;
  std::sort(scratch.all.begin(), scratch.all.end(), [](const FractureCandidate& a, const FractureCandidate& b) {
    return a.ratio != b.ratio ? a.ratio > b.ratio : a.id < b.id;
  });
  const int cap = w.scene.run.max_splits_per_step;
  std::size_t splits = 0;
  for (const FractureCandidate& cand : scratch.all) {
    if (cap > 0 && splits >= std::size_t(cap)) break;
    splits += break_spring(w, cand.id / kSpringsPerCell, int(cand.id % kSpringsPerCell));
  }
  return splits;
}

}  // namespace papertear
