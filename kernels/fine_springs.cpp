#include "kernels/fine_springs.hpp"

#include <algorithm>
#include <array>

namespace papertear {
namespace {

// slot_of[a][b]: the slot joining corners a and b (either order).
constexpr std::array<std::array<std::int8_t, 8>, 8> make_slot_of() {
  std::array<std::array<std::int8_t, 8>, 8> t{};
  for (auto& row : t) row.fill(-1);
  for (int s = 0; s < kSpringsPerCell; ++s) {
    const SpringSlot& sl = kSpringSlots[std::size_t(s)];
    t[sl.a][sl.b] = t[sl.b][sl.a] = std::int8_t(s);
  }
  return t;
}
constexpr auto kSlotOf = make_slot_of();

bool same_parameters(const SpringTable& t, int s, int u) {
  return t.rest[std::size_t(s)] == t.rest[std::size_t(u)] && t.stiffness[std::size_t(s)] == t.stiffness[std::size_t(u)] &&
         t.damping[std::size_t(s)] == t.damping[std::size_t(u)];
}

// How many springs coincide with slot s of cell c (same two nodes and parameters), if c
// owns them (the largest id among them); 0 when another cell does. The candidates are the
// cells that contain both of the spring's lattice vertices: 2 choices along each axis the
// spring does not span, 1 along each it does.
std::uint8_t coincident_count(const Topology& topo, const SpringTable& table, std::uint32_t c, int s) {
  const LatticeDims& d = topo.dims;
  const SpringSlot& sl = kSpringSlots[std::size_t(s)];
  const auto ijk = d.cell_ijk(c);
  const int lim[3] = {d.nx, d.ny, d.nl};
  int lo[3], hi[3];
  for (int ax = 0; ax < 3; ++ax) {
    const int va = ijk[std::size_t(ax)] + corner_bit(sl.a, ax), vb = ijk[std::size_t(ax)] + corner_bit(sl.b, ax);
    lo[ax] = va == vb ? std::max(va - 1, 0) : ijk[std::size_t(ax)];
    hi[ax] = va == vb ? std::min(va, lim[ax] - 1) : ijk[std::size_t(ax)];
  }
  const std::uint32_t node_a = topo.node(c, sl.a), node_b = topo.node(c, sl.b);
  const float scale = topo.cell_scale[c];
  int count = 0;
  std::uint32_t owner = c;
  for (int k = lo[2]; k <= hi[2]; ++k)
    for (int j = lo[1]; j <= hi[1]; ++j)
      for (int i = lo[0]; i <= hi[0]; ++i) {
        const std::uint32_t other = d.cell_index(i, j, k);
        const int delta[3] = {ijk[0] - i, ijk[1] - j, ijk[2] - k};
        auto corner_in_other = [&](int q) {
          return corner_of(corner_bit(q, 0) + delta[0], corner_bit(q, 1) + delta[1], corner_bit(q, 2) + delta[2]);
        };
        const int qa = corner_in_other(sl.a), qb = corner_in_other(sl.b);
        const int u = kSlotOf[std::size_t(qa)][std::size_t(qb)];
        if (topo.node(other, qa) == node_a && topo.node(other, qb) == node_b && same_parameters(table, s, u) &&
            topo.cell_scale[other] == scale) {
          ++count;
          owner = std::max(owner, other);
        }
      }
  return owner == c ? std::uint8_t(count) : std::uint8_t(0);
}

// Slot s of a cell none of whose corners has been split, in a sheet of uniform springs and
// stiffness factors: every candidate cell then has the same nodes and parameters, so the
// count is the number of candidates and the owner the one with the largest (i, j, k).
// Along an axis the spring does not span, its end sits at coordinate i + bit: the candidates
// are i + bit - 1 and i + bit where they exist, and the cell owns the spring when i + bit is
// past the last cell or bit = 0.
std::uint8_t whole_sheet_count(const LatticeDims& d, const std::array<int, 3>& ijk, int s) {
  const SpringSlot& sl = kSpringSlots[std::size_t(s)];
  const int lim[3] = {d.nx, d.ny, d.nl};
  int count = 1;
  for (int ax = 0; ax < 3; ++ax) {
    const int bit = corner_bit(sl.a, ax);
    if (bit != corner_bit(sl.b, ax)) continue;  // spans this axis: one candidate
    const int i = ijk[std::size_t(ax)];
    if (bit == 1 && i + 1 < lim[ax]) return 0;  // the cell above along ax owns it
    if (bit == 0 && i > 0) count *= 2;
  }
  return std::uint8_t(count);
}

bool corners_whole(const Topology& topo, const FineSpringsBuild& build, std::uint32_t c) {
  const LatticeDims& d = topo.dims;
  const auto ijk = d.cell_ijk(c);
  for (int q = 0; q < kCornersPerCell; ++q)
    if (!build.whole_vertex[d.corner_vertex(ijk, q)])
      return false;
  return true;
}

// Bit q set when corner q's node of cell c is not its vertex's original node.
std::uint8_t copy_corners(const Topology& topo, std::uint32_t c) {
  const LatticeDims& d = topo.dims;
  const auto ijk = d.cell_ijk(c);
  std::uint8_t bits = 0;
  for (int q = 0; q < kCornersPerCell; ++q)
    if (topo.node(c, q) != d.corner_vertex(ijk, q))
      bits = std::uint8_t(bits | (1u << q));
  return bits;
}

void assign_cell(const Topology& topo, const SpringTable& table, std::uint32_t c, bool whole, FineSprings& out) {
  const auto ijk = topo.dims.cell_ijk(c);
  std::uint32_t owned = 0;
  for (int s = 0; s < kSpringsPerCell; ++s) {
    const std::uint8_t n = whole ? whole_sheet_count(topo.dims, ijk, s) : coincident_count(topo, table, c, s);
    out.set(c, s, n);
    if (n != 0) owned |= 1u << s;
  }
  out.copies[c] = whole ? 0 : copy_corners(topo, c);  // a whole cell's corners are its vertices' own nodes
  if (out.copies[c] != 0) owned |= kSplitCorner;
  out.owned[c] = owned | (topo.cell_scale[c] != 1.0f ? kScaledCell : 0u);
}

// Widens cell c's row so that it covers c's owned slots and flags.
void widen_row(const Topology& topo, std::uint32_t c, FineSprings& out) {
  const LatticeDims& d = topo.dims;
  const auto ijk = d.cell_ijk(c);
  FineRow& row = out.rows[std::size_t(ijk[2]) * std::size_t(d.ny) + std::size_t(ijk[1])];
  const std::uint32_t i = std::uint32_t(ijk[0]), owned = out.owned[c];
  for (int s = 0; s < kSpringsPerCell; ++s)
    if ((owned >> s) & 1u) {
      if (row.lo[s] == row.hi[s]) row.lo[s] = row.hi[s] = i;
      row.lo[s] = std::min(row.lo[s], i);
      row.hi[s] = std::max(row.hi[s], i + 1);
    }
  row.scaled = row.scaled || (owned & kScaledCell) != 0;
  row.copies = row.copies || out.copies[c] != 0;
}

// True when slots that can coincide (same family and axis) have the same parameters and all
// cells the same stiffness factor: then coincidence is a matter of nodes alone.
bool uniform_springs(const Topology& topo, const SpringTable& table) {
  for (int s = 0; s < kSpringsPerCell; ++s)
    for (int u = 0; u < kSpringsPerCell; ++u)
      if (kSpringSlots[std::size_t(s)].family == kSpringSlots[std::size_t(u)].family &&
          kSpringSlots[std::size_t(s)].axis == kSpringSlots[std::size_t(u)].axis && !same_parameters(table, s, u))
        return false;
  for (float f : topo.cell_scale)
    if (f != topo.cell_scale.front()) return false;
  return true;
}

// Which of FineSprings::shared_counts' rows a whole sheet's row (j, k) has: its counts
// depend only on whether it lies on the sheet's low or high side in y and in z.
int whole_row_kind(const LatticeDims& d, int j, int k) {
  const int y = (j == 0 ? 1 : 0) | (j + 1 == d.ny ? 2 : 0), z = (k == 0 ? 1 : 0) | (k + 1 == d.nl ? 2 : 0);
  return y * 4 + z;
}

// FineSprings::shared_counts for the kinds of row the sheet has, from whole_sheet_count.
void fill_shared_counts(const LatticeDims& d, FineSprings& out) {
  const std::size_t nx = std::size_t(d.nx), run = kSpringsPerCell * nx;
  out.shared_counts.resize(FineSprings::kRowKinds * run + 32);
  std::fill(out.shared_counts.begin(), out.shared_counts.end(), std::uint8_t(0));
  bool filled[FineSprings::kRowKinds] = {};
  for (int k = 0; k < d.nl; ++k)
    for (int j = 0; j < d.ny; ++j) {
      const int kind = whole_row_kind(d, j, k);
      if (filled[kind]) continue;
      filled[kind] = true;
      std::uint8_t* dst = out.shared_counts.data() + std::size_t(kind) * run;
      for (int s = 0; s < kSpringsPerCell; ++s)
        for (int i = 0; i < d.nx; ++i) dst[std::size_t(s) * nx + std::size_t(i)] = whole_sheet_count(d, {i, j, k}, s);
    }
}

// Row r's shared row: its kind's, if the row's counts are that kind's, else -1.
std::int8_t shared_row_of(const LatticeDims& d, std::size_t r, const FineSprings& out) {
  const int j = int(r % std::size_t(d.ny)), k = int(r / std::size_t(d.ny)), kind = whole_row_kind(d, j, k);
  const std::size_t run = kSpringsPerCell * std::size_t(d.nx);
  const bool same = std::equal(out.count.data() + r * run, out.count.data() + (r + 1) * run,
                               out.shared_counts.data() + std::size_t(kind) * run);
  return same ? std::int8_t(kind) : std::int8_t(-1);
}

// Row r's dirty groups, from the cells' copies, counts and corners (assigned already).
void plan_dirty_cells(const Topology& topo, std::size_t r, FineSprings& out) {
  std::vector<DirtyGroup>& groups = out.dirty[r];
  groups.clear();
  if (!out.rows[r].copies) return;  // rows are widened only, so this flag is never missing
  const std::size_t nx = std::size_t(topo.dims.nx), first = r * nx;
  constexpr int kLanes = DirtyGroup::kLanes;
  for (std::size_t c0 = 0; c0 < nx; c0 += kRowChunk) {
    std::size_t cells[kLanes];
    int n = 0;
    auto flush = [&] {
      DirtyGroup& g = groups.emplace_back();
      g.chunk = std::uint32_t(c0 / kRowChunk);
      g.valid = std::uint32_t(n);
      for (int l = 0; l < kLanes; ++l) {
        const std::size_t c = first + cells[l < n ? l : 0];
        g.scale[l] = topo.cell_scale[c];
        for (int q = 0; q < kCornersPerCell; ++q) g.node[q][l] = topo.cell_nodes[c * kCornersPerCell + std::size_t(q)];
        for (int k = 0; k < kSpringsPerCell; ++k) g.count[k][l] = out.at(c, k);
      }
      n = 0;
    };
    for (std::size_t i = c0; i < std::min(nx, c0 + kRowChunk); ++i) {
      if (out.copies[first + i] == 0) continue;
      cells[n++] = i;
      if (n == kLanes) flush();
    }
    if (n > 0) flush();
  }
}

// Every row of cells unplanned (no ranges, flags or dirty groups; none stale), and the whole
// sheet's shared counts filled, before the rows are planned.
void reset_row_plans(const LatticeDims& d, FineSprings& out) {
  out.rows.assign(std::size_t(d.ny) * std::size_t(d.nl), FineRow{});
  out.dirty.assign(out.rows.size(), {});
  out.stale_rows.clear();
  fill_shared_counts(d, out);
}

}  // namespace

FineSpringsBuild prepare_fine_springs(const Topology& topo, const SpringTable& table, FineSprings& out) {
  const LatticeDims& d = topo.dims;
  out.resize_counts(std::size_t(d.cells()), std::size_t(d.nx), 0);
  out.owned.assign(out.cells + 32, 0);
  out.copies.assign(out.cells + 32, 0);
  reset_row_plans(d, out);
  // A vertex is whole while every cell around it still uses the vertex's own node.
  FineSpringsBuild build;
  build.whole_vertex.assign(std::size_t(d.vertices()), uniform_springs(topo, table) ? 1 : 0);
  for (std::uint32_t c = 0; c < out.cells; ++c) {
    const auto ijk = d.cell_ijk(c);
    for (int q = 0; q < kCornersPerCell; ++q) {
      const std::uint32_t v = d.corner_vertex(ijk, q);
      if (topo.node(c, q) != v) build.whole_vertex[v] = 0;
    }
  }
  return build;
}

void assign_fine_springs(std::size_t begin, std::size_t end, const Topology& topo, const SpringTable& table,
                         const FineSpringsBuild& build, FineSprings& out) {
  for (std::size_t c = begin; c < end; ++c)
    assign_cell(topo, table, std::uint32_t(c), corners_whole(topo, build, std::uint32_t(c)), out);
}

void build_fine_springs(const Topology& topo, const SpringTable& table, FineSprings& out) {
  const FineSpringsBuild build = prepare_fine_springs(topo, table, out);
  assign_fine_springs(0, out.cells, topo, table, build, out);
  plan_fine_rows(0, out.rows.size(), topo, out);
}

void plan_fine_rows(std::size_t row_begin, std::size_t row_end, const Topology& topo, FineSprings& out) {
  const std::uint32_t nx = std::uint32_t(topo.dims.nx);
  for (std::size_t r = row_begin; r < row_end; ++r) {
    out.rows[r] = FineRow{};
    const std::uint32_t first = std::uint32_t(r) * nx;  // cell (0, j, k) with r = k * ny + j
    for (std::uint32_t c = first; c < first + nx; ++c) widen_row(topo, c, out);
    out.rows[r].shared = shared_row_of(topo.dims, r, out);
    plan_dirty_cells(topo, r, out);
  }
}

void plan_all_fine_rows(const Topology& topo, FineSprings& out) {
  out.copies.assign(out.cells + 32, 0);
  for (std::uint32_t c = 0; c < out.cells; ++c) out.copies[c] = copy_corners(topo, c);
  reset_row_plans(topo.dims, out);
  plan_fine_rows(0, out.rows.size(), topo, out);
}

void plan_stale_dirty_cells(const Topology& topo, FineSprings& out) {
  std::sort(out.stale_rows.begin(), out.stale_rows.end());
  out.stale_rows.erase(std::unique(out.stale_rows.begin(), out.stale_rows.end()), out.stale_rows.end());
  for (std::uint32_t r : out.stale_rows) plan_dirty_cells(topo, r, out);
  out.stale_rows.clear();
}

void update_fine_springs_at(const Topology& topo, const SpringTable& table, std::uint32_t vertex, FineSprings& out) {
  const LatticeDims& d = topo.dims;
  const auto v = d.vertex_ijk(vertex);
  const int lim[3] = {d.nx, d.ny, d.nl};
  for (int dk = -1; dk <= 0; ++dk)
    for (int dj = -1; dj <= 0; ++dj)
      for (int di = -1; di <= 0; ++di) {
        const int i = v[0] + di, j = v[1] + dj, k = v[2] + dk;
        if (i < 0 || j < 0 || k < 0 || i >= lim[0] || j >= lim[1] || k >= lim[2]) continue;
        const std::uint32_t c = d.cell_index(i, j, k);
        assign_cell(topo, table, c, false, out);
        widen_row(topo, c, out);
        const std::size_t r = std::size_t(k) * std::size_t(d.ny) + std::size_t(j);
        out.rows[r].shared = -1;  // its counts may differ now
        out.stale_rows.push_back(std::uint32_t(r));
      }
}

}  // namespace papertear
