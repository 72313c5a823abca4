#include "fracture/fracture_pass.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>

#include "core/elasticity.hpp"
#include "core/solver.hpp"
#include "fracture/connectivity.hpp"
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

// Marks the vertex of every node made since the last call: a vertex with one node (the
// lattice's first node there has the vertex's index) cannot be cracked. Rebuilt from the
// nodes when the scratch is new (or the world is another's), so it is state, not history.
void mark_split_vertices(const World& w, FractureScratch& scratch) {
  const std::size_t vertices = std::size_t(w.topo.dims.vertices()), count = w.nodes.count;
  if (scratch.split_vertex.size() != vertices || scratch.marked_nodes > count) {
    scratch.split_vertex.assign(vertices, 0);
    scratch.marked_nodes = vertices;
  }
  for (std::size_t n = scratch.marked_nodes; n < count; ++n) scratch.split_vertex[w.nodes.vertex[n]] = 1;
  scratch.marked_nodes = count;
}

// Whether the cells around lattice vertex (i, j, k) on the two sides of the plane normal to
// `axis` use different nodes there: the sheet is cracked across that plane at the vertex.
bool cracked_across(const World& w, const SplitVertices& split, int i, int j, int k, int axis) {
  const LatticeDims& d = w.topo.dims;
  if (i < 0 || j < 0 || i > d.nx || j > d.ny) return false;
  if (split[std::size_t(d.vertex_index(i, j, k))] == 0) return false;  // one node: nothing to crack
  for (int q = 0; q < kCornersPerCell; ++q) {
    if (corner_bit(q, axis) != 0) continue;  // q: a cell on the low side; q | bit: its partner
    int lo[3] = {i - 1 + corner_bit(q, 0), j - 1 + corner_bit(q, 1), k - 1 + corner_bit(q, 2)};
    int hi[3] = {lo[0], lo[1], lo[2]};
    hi[axis] += 1;
    const int lim[3] = {d.nx, d.ny, d.nl};
    bool inside = true;
    for (int a = 0; a < 3; ++a) inside = inside && lo[a] >= 0 && hi[a] < lim[a];
    if (!inside) continue;
    // The vertex is corner (1 - bit) of a cell along each axis.
    const int corner_lo = corner_of(1 - corner_bit(q, 0), 1 - corner_bit(q, 1), 1 - corner_bit(q, 2));
    const int corner_hi = corner_lo & ~(1 << axis);
    if (w.topo.node(d.cell_index(lo[0], lo[1], lo[2]), corner_lo) != w.topo.node(d.cell_index(hi[0], hi[1], hi[2]), corner_hi))
      return true;
  }
  return false;
}

// A node is at the tip of a crack across `axis` (in plane) when the sheet is not cracked
// across that plane at its vertex yet but is at a vertex next to it along the crack's path
// (the other in-plane axis): the crack is about to reach it, and the bond there is judged at
// tip_strength of the intact material's (fracture_pass.hpp). A crack's flanks are not tips,
// and neither is a vertex one cell beside a crack of the same plane: the face next to it is
// free, so the material there is shielded, not concentrated, and a second crack starting
// beside the first would otherwise run along with it at the tip's strength and cut out a
// strip one cell wide.
bool at_crack_tip(const World& w, const SplitVertices& split, std::uint32_t node, int axis) {
  const auto v = w.topo.dims.vertex_ijk(w.nodes.vertex[node]);
  if (cracked_across(w, split, v[0], v[1], v[2], axis)) return false;
  const int si = axis == 0 ? 1 : 0, sj = axis == 1 ? 1 : 0;  // beside: along the axis
  if (cracked_across(w, split, v[0] + si, v[1] + sj, v[2], axis) ||
      cracked_across(w, split, v[0] - si, v[1] - sj, v[2], axis))
    return false;
  const int di = axis == 1 ? 1 : 0, dj = axis == 0 ? 1 : 0;
  return cracked_across(w, split, v[0] + di, v[1] + dj, v[2], axis) ||
         cracked_across(w, split, v[0] - di, v[1] - dj, v[2], axis);
}

// In-plane bonds only: a delamination is judged by its own, full strength.
float strength_factor(const World& w, const SplitVertices& split, std::uint32_t node, int axis) {
  return axis < 2 && at_crack_tip(w, split, node, axis) ? float(w.scene.material.tip_strength) : 1.0f;
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

// Whether edge `slot` of `cell`, at `strain`, exceeds the bond at either end, judged at the
// strength factor of that end (tip_strength at a crack tip).
bool exceeds_either_end(const World& w, const SplitVertices& split, std::uint32_t cell, int slot, float strain) {
  const SpringSlot& sl = kSpringSlots[std::size_t(slot)];
  const std::uint32_t end_node[2] = {w.topo.node(cell, sl.a), w.topo.node(cell, sl.b)};
  for (int side = 0; side < 2; ++side)
    if (strain > strength_factor(w, split, end_node[side], sl.axis) * face_strength(w, cell, sl.axis, side)) return true;
  return false;
}

// The exact test for the edges of `cell` flagged in `over` (ascending slots): only it decides.
void confirm(const World& w, const SplitVertices& split, std::uint32_t cell, unsigned over,
             std::vector<FractureCandidate>& out) {
  const float tip = float(w.scene.material.tip_strength);
  for (; over != 0; over &= over - 1) {
    const int s = std::countr_zero(over);
    const int axis = kSpringSlots[std::size_t(s)].axis;
    const float weaker = std::min(face_strength(w, cell, axis, 0), face_strength(w, cell, axis, 1));
    const float strain = edge_strain(w, cell, s);
    // Between tip_strength and the full strength, only an edge ending at a crack tip counts.
    if (strain > weaker || (strain > tip * weaker && exceeds_either_end(w, split, cell, s, strain)))
      out.push_back({strain / weaker, cell * kSpringsPerCell + std::uint32_t(s)});
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
void detect(std::size_t begin, std::size_t end, const World& w, const SplitVertices& split,
            std::vector<FractureCandidate>& out) {
  out.clear();
  // A bond at a crack tip opens at tip_strength of its strength: the chunk's bound uses that.
  const float weakest = float(w.scene.material.tip_strength) * weakest_strength(w.topo.face_strain.data(), begin, end);
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
        if (over[l] != 0) confirm(w, split, std::uint32_t(c) + l, over[l], out);
      c += 8;
      continue;
    }
#endif
    confirm(w, split, std::uint32_t(c), cell_edges_over_bound(w, c, bound), out);
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
  const double m = cell_mass(w.scene.material, d) / 8.0 * cells;
  w.nodes.mass[node] = float(m);
  w.nodes.inv_mass[node] = float(1.0 / m);
}

// The edge slot of a cell that runs from corner q along axis a.
constexpr std::array<std::array<int, 3>, 8> kEdgeSlotAt = [] {
  std::array<std::array<int, 3>, 8> out{};
  for (int q = 0; q < kCornersPerCell; ++q)
    for (int a = 0; a < 3; ++a)
      for (int s = 0; s < kEdgesPerCell; ++s) {
        const SpringSlot& slot = kSpringSlots[std::size_t(s)];
        if (slot.axis == a && (slot.a == q || slot.b == q)) out[std::size_t(q)][std::size_t(a)] = s;
      }
  return out;
}();

// How overloaded a node is along each axis: over the cells that use it, the mean of
// (strain of the cell's edge along that axis at the node) / (the strength of the bond there).
// Averaged over the node's cells, one spring's spike does not decide, and the axis with the
// largest load is the direction in which the material around the node pulls apart.
std::array<float, 3> node_overload(const World& w, std::uint32_t node) {
  std::array<float, 3> sum{};
  const NodeCells cells = cells_of_node(w, node);
  for (int i = 0; i < cells.count; ++i) {
    const CellCorner& cc = cells.items[std::size_t(i)];
    for (int a = 0; a < 3; ++a) {
      const float strength = face_strength(w, cc.cell, a, corner_bit(cc.corner, a));
      if (strength < INFINITY) sum[std::size_t(a)] += edge_strain(w, cc.cell, kEdgeSlotAt[cc.corner][std::size_t(a)]) / strength;
    }
  }
  for (float& v : sum) v /= float(std::max(cells.count, 1));
  return sum;
}

// A node may open across `axis` only where that is its most overloaded axis and its mean
// overload there exceeds its strength factor (1, or tip_strength at a crack tip): the split plane is then normal to the
// direction in which the material around it pulls apart, so a crack tip opens ahead of
// itself instead of splitting parallel to its own path, where the stress is lower.
bool opens_across(const World& w, const SplitVertices& split, std::uint32_t node, int axis) {
  const std::array<float, 3> load = node_overload(w, node);
  const float mine = load[std::size_t(axis)];
  return mine > strength_factor(w, split, node, axis) && mine >= load[0] && mine >= load[1] && mine >= load[2];
}

bool face_failed(const World& w, std::uint32_t cell, int axis, int side) {
  return w.topo.face_damage[std::size_t(cell) * kFacesPerCell + std::size_t(2 * axis + side)] >= 1.0f;
}

// Step 2 of the header: every face over its strength gains dt / τ of damage, once.
void accumulate_damage(World& w, FractureScratch& scratch) {
  scratch.faces.clear();
  for (const FractureCandidate& cand : scratch.all) {
    const std::uint32_t cell = cand.id / kSpringsPerCell;
    const int slot = int(cand.id % kSpringsPerCell), axis = kSpringSlots[std::size_t(slot)].axis;
    const float strain = edge_strain(w, cell, slot);
    const SpringSlot& sl = kSpringSlots[std::size_t(slot)];
    const std::uint32_t end_node[2] = {w.topo.node(cell, sl.a), w.topo.node(cell, sl.b)};
    for (int side = 0; side < 2; ++side)
      if (strain > strength_factor(w, scratch.split_vertex, end_node[side], axis) * face_strength(w, cell, axis, side))
        scratch.faces.push_back(cell * kFacesPerCell + std::uint32_t(2 * axis + side));
  }
  std::sort(scratch.faces.begin(), scratch.faces.end());
  scratch.faces.erase(std::unique(scratch.faces.begin(), scratch.faces.end()), scratch.faces.end());
  for (std::uint32_t f : scratch.faces) {
    float& damage = w.topo.face_damage[f];
    damage = std::min(1.0f, damage + float(w.dt / scratch.failure_time[(f % kFacesPerCell) / 2]));
  }
}

// The cells using `node` that are joined to the lowest of them through faces still bonded
// (faces_connected), as a mask over cells_of_node's order.
unsigned bonded_group(const World& w, const NodeCells& cells) {
  unsigned group = 1u, grown = 1u;
  while (grown != 0) {
    grown = 0;
    for (int i = 0; i < cells.count; ++i) {
      if ((group >> i) & 1u) continue;
      for (int j = 0; j < cells.count; ++j) {
        if (!((group >> j) & 1u)) continue;
        const int diff = cells.items[std::size_t(i)].corner ^ cells.items[std::size_t(j)].corner;
        if (std::popcount(unsigned(diff)) != 1) continue;  // not face neighbours around the node
        const int axis = std::countr_zero(unsigned(diff));
        // Cell j's face toward cell i: the node is on j's high face along axis when its corner bit is 1.
        const int face = 2 * axis + corner_bit(cells.items[std::size_t(j)].corner, axis);
        if (faces_connected(w, cells.items[std::size_t(j)].cell, face)) {
          group |= 1u << i;
          grown = 1;
          break;
        }
      }
    }
  }
  return group;
}

// A node that joins groups of cells with no bonded face between them is a point contact, not
// a bond (MODEL.md §5: bonds are faces): each group that is not the lowest cell's gets a node
// of its own. Without this, cells hinged at one corner form strands that bridge a tear and
// whip about when it opens. No bond opens, so no split event is recorded.
void separate_point_contacts(World& w, std::uint32_t node) {
  for (;;) {
    const NodeCells cells = cells_of_node(w, node);
    const unsigned all = (1u << cells.count) - 1u;
    const unsigned group = bonded_group(w, cells);
    if (cells.count == 0 || group == all) return;
    if (!separate_node(w, NodeId(node), all & ~group).valid()) return;
  }
}

// After a split at `node`: point contacts may appear at any corner of the cells around it.
void separate_point_contacts_near(World& w, std::uint32_t node) {
  std::array<std::uint32_t, 64> seen{};
  int n = 0;
  for (const CellCorner& cc : cells_of_node(w, node))
    for (int q = 0; q < kCornersPerCell; ++q) seen[std::size_t(n++)] = w.topo.node(cc.cell, q);
  std::sort(seen.begin(), seen.begin() + n);
  for (int i = 0; i < n; ++i)
    if (i == 0 || seen[std::size_t(i)] != seen[std::size_t(i - 1)]) separate_point_contacts(w, seen[std::size_t(i)]);
}

// Tries to split the end of edge spring (cell, slot) chosen by the paper's rule; returns
// whether a split happened.
bool break_spring(World& w, FractureScratch& scratch, std::uint32_t cell, int slot) {
  const SplitVertices& split = scratch.split_vertex;
  const SpringSlot& s = kSpringSlots[std::size_t(slot)];
  const int axis = s.axis;
  const float strain = edge_strain(w, cell, slot);
  std::uint32_t end_node[2] = {w.topo.node(cell, s.a), w.topo.node(cell, s.b)};
  bool eligible[2];
  for (int side = 0; side < 2; ++side)
    eligible[side] = strain > strength_factor(w, split, end_node[side], axis) * face_strength(w, cell, axis, side) &&
                     face_failed(w, cell, axis, side) && shared_across(w, end_node[side], axis, side) &&
                     opens_across(w, split, end_node[side], axis);
  int side;
  if (eligible[0] && eligible[1]) side = force_sum(w, end_node[1]) > force_sum(w, end_node[0]) ? 1 : 0;
  else if (eligible[0]) side = 0;
  else if (eligible[1]) side = 1;
  else return false;
  const NodeId fresh = split_node(w, NodeId(end_node[side]), axis, side);
  if (!fresh.valid()) return false;
  w.events.push_back({w.step + 1, end_node[side], fresh.value, std::uint8_t(axis), axis == 2, cell, std::uint8_t(slot)});
  separate_point_contacts_near(w, end_node[side]);
  separate_point_contacts_near(w, fresh.value);
  mark_split_vertices(w, scratch);
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

// Fibre bridging (step 0 of the header): for bridge_time bond failure times after a split,
// the two nodes it made are joined by a dashpot, as fibres pulled out of the opening faces
// are. Each pair's relative velocity relaxes by exp(-dt / τ) per step, exchanging equal and
// opposite momentum, so momentum is kept and the energy the opened bond's springs release
// is dissipated there instead of radiating as the wave that breaks its neighbours.
void bridge_fresh_cracks(World& w, const FractureScratch& scratch) {
  const double window = w.scene.material.bridge_time;
  if (window <= 0.0 || w.events.empty()) return;
  NodeStore& n = w.nodes;
  const auto& tau_of = scratch.failure_time;
  const double longest = window * std::max({tau_of[0], tau_of[1], tau_of[2]});
  // Events are in step order: walk back from the newest until they are all too old.
  for (auto e = w.events.rbegin(); e != w.events.rend(); ++e) {
    const double age = double(w.step + 1 - e->step) * w.dt, tau = tau_of[e->axis];
    if (age > longest) break;
    if (age > window * tau) continue;
    const std::uint32_t a = e->node, b = e->new_node;
    if (n.grip[a] != 0 || n.grip[b] != 0) continue;
    const double keep = std::exp(-w.dt / tau);
    const double ma = n.mass[a], mb = n.mass[b], reduced = ma * mb / (ma + mb);
    IntegratorScratch& st = w.scratch;  // the next step's first stage reads these copies
    float* v[3][4] = {{&n.vx[a], &n.vx[b], &st.svx[a], &st.svx[b]},
                      {&n.vy[a], &n.vy[b], &st.svy[a], &st.svy[b]},
                      {&n.vz[a], &n.vz[b], &st.svz[a], &st.svz[b]}};
    for (auto& axis : v) {
      const double impulse = reduced * (1.0 - keep) * (double(*axis[0]) - double(*axis[1]));
      *axis[2] = *axis[0] = float(*axis[0] - impulse / ma);
      *axis[3] = *axis[1] = float(*axis[1] + impulse / mb);
    }
  }
}

std::size_t fracture_pass(World& w, FractureScratch& scratch) {
  if (scratch.failure_time[0] <= 0.0) scratch.failure_time = bond_failure_time(w.scene.material, w.topo.dims);
  bridge_fresh_cracks(w, scratch);
  mark_split_vertices(w, scratch);
  const std::size_t cells = std::size_t(w.topo.dims.cells());
  scratch.per_chunk.resize(chunk_count(cells, kCellChunk));
  parallel_chunks(cells, kCellChunk, [&](std::size_t b, std::size_t e, std::size_t c) {
    detect(b, e, w, scratch.split_vertex, scratch.per_chunk[c]);
  });
  scratch.all.clear();
  for (const auto& part : scratch.per_chunk) scratch.all.insert(scratch.all.end(), part.begin(), part.end());
  if (scratch.all.empty()) return 0;
  std::sort(scratch.all.begin(), scratch.all.end(), [](const FractureCandidate& a, const FractureCandidate& b) {
    return a.ratio != b.ratio ? a.ratio > b.ratio : a.id < b.id;
  });
  accumulate_damage(w, scratch);
  const int cap = w.scene.run.max_splits_per_step;
  std::size_t splits = 0;
  for (const FractureCandidate& cand : scratch.all) {
    if (cap > 0 && splits >= std::size_t(cap)) break;
    splits += break_spring(w, scratch, cand.id / kSpringsPerCell, int(cand.id % kSpringsPerCell));
  }
  return splits;
}

}  // namespace papertear
