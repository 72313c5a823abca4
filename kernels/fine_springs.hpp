// Coincident fine springs merged (MODEL.md §4: "an implementation may merge coincident
// springs for speed, as long as the result is the same").
//
// Every cell has its own 28 springs, so an interior edge carries four coincident springs
// (one per cell around it) and an interior face diagonal two: of a cell's 28 springs only 13
// are distinct. Coincident springs join the same two nodes with the same rest length,
// stiffness and damping (slots of one family and axis, cells of equal stiffness factor), so
// together they pull with `count` times one spring's force. The fine-spring kernel evaluates
// each such set once, in its owner (the cell of the set with the largest id), scaled by
// `count`; the other cells skip it (count 0).
//
// In a whole sheet the owner is the cell on whose low faces (dx, dy or dz = 0) the spring
// lies, so every cell owns the same 13 slots (kLowSlots) and only cells on the sheet's high
// sides (i = nx - 1, j = ny - 1, k = nl - 1) own more. When fracture splits a node, the
// springs of the cells that moved to the copy no longer coincide with the others': each
// side then has an owner of its own, which may own slots outside kLowSlots.
//
// Which cell owns a set depends on the topology only, never on the thread count, and the
// kernel adds each node's terms in a fixed order (kernels/cell_forces.hpp), so the solver's
// bits stay independent of threads and vector width. The kernel also needs, per row of
// cells, which slots have owners where (FineRow) and which cells' corners are split copies.
#pragma once
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <vector>

#include "core/aligned_array.hpp"
#include "core/world.hpp"

namespace papertear {

// Slots by where they lie in the cell (kSpringSlots order, core/lattice.hpp).
inline constexpr std::uint32_t slot_bits(std::initializer_list<int> slots) {
  std::uint32_t m = 0;
  for (int s : slots) m |= 1u << s;
  return m;
}
// Owned by every cell of a whole sheet: the edges and face diagonals on its low faces, and
// the 4 body diagonals.
inline constexpr std::uint32_t kLowSlots = slot_bits({0, 4, 8, 12, 13, 16, 17, 20, 21, 24, 25, 26, 27});
inline constexpr std::uint32_t kHighXSlots = slot_bits({5, 9, 22, 23});  // extra at i = nx - 1
inline constexpr std::uint32_t kHighZSlots = slot_bits({2, 6, 14, 15});  // extra at k = nl - 1
inline constexpr std::uint32_t kHighXZSlots = slot_bits({7});           // extra at both
inline constexpr std::uint32_t kAllSlots = (1u << kSpringsPerCell) - 1u;
inline constexpr std::uint32_t kScaledCell = 1u << 31;  // in FineSprings::owned
inline constexpr std::uint32_t kSplitCorner = 1u << 30; // ditto: a corner's node is a split copy

// Cells per chunk of a row, for the spring kernel (kernels/cell_forces.hpp): a fixed number
// (a multiple of every vector width), so that the order of a node's terms depends on the
// lattice alone.
inline constexpr std::size_t kRowChunk = 256;

// Up to 8 cells of one chunk of a row that have split copies among their corners ("dirty"
// cells, which the kernel evaluates cell by cell after the chunk's slot passes), laid out as
// the kernel loads them: lane l is the group's l-th cell. What it holds changes only with
// splits, so it is planned with the row, not fetched cell by cell in every evaluation (each
// dirty cell's corners and 28 counts lay in 36 places of the tables). Lanes from `valid` on
// repeat lane 0: computed, not added.
struct DirtyGroup {
  static constexpr int kLanes = 8;
  alignas(32) std::uint32_t node[kCornersPerCell][kLanes] = {};  // corner q's node
  alignas(32) float scale[kLanes] = {};                          // the cell's stiffness factor
  alignas(32) std::uint8_t count[kSpringsPerCell][kLanes] = {};  // as FineSprings::count
  std::uint32_t chunk = 0;  // the row's chunk: cells [chunk * kRowChunk, (chunk + 1) * kRowChunk)
  std::uint32_t valid = 0;
  bool operator==(const DirtyGroup&) const = default;
};

// What the kernel (kernels/cell_forces.hpp) needs to know of one row of cells (j, k):
// per slot, the cells [lo, hi) of the row (by i) among which that slot's owners lie (lo ==
// hi: none), and whether any cell of the row has a stiffness factor other than 1 or a corner
// whose node is a split copy. A range may be wider than its owners (update_fine_springs_at
// only widens ranges): a cell that does not own the slot adds exact zeros.
//
// A row whose counts are those of a whole sheet (most rows, until fracture reaches them) names
// the row of FineSprings::shared_counts with the same counts (shared >= 0), and the kernel
// reads that instead of the row's own: the few shared rows stay in cache, whereas each row's
// own counts are another 28 bytes per cell to fetch from memory in every evaluation.
struct FineRow {
  std::uint32_t lo[kSpringsPerCell] = {};
  std::uint32_t hi[kSpringsPerCell] = {};
  bool scaled = false;
  bool copies = false;
  std::int8_t shared = -1;
};

struct FineSprings {
  std::size_t cells = 0;
  std::size_t row_cells = 0;  // cells per row (nx)
  // How many coincident springs a cell evaluates as one, 0 where another cell does: per row
  // of cells, its 28 slots' runs of row_cells counts one after the other (count_index). The
  // kernel reads a row's slots in order, so this is one stream; kept as 28 arrays of every
  // cell, the slots' runs were 28 streams, which the prefetchers lost, and the sweep waited
  // on the counts' cache misses. 32 bytes of padding at the end: kernels load 32 bytes at a
  // time.
  AlignedArray<std::uint8_t> count{11};
  // Per cell: bit s set when the count of slot s is > 0, kScaledCell when the cell's
  // stiffness factor is not 1, kSplitCorner when one of its corners is not its vertex's
  // original node (node id = vertex id). 32 entries of padding (0) at the end, for vector
  // loads.
  std::vector<std::uint32_t> owned;
  // Per cell: bit q set when corner q's node is a split copy, not its vertex's original
  // node. 32 bytes of padding (0) at the end, for vector loads.
  std::vector<std::uint8_t> copies;
  // Per row of cells, index k * ny + j (plan_fine_rows).
  std::vector<FineRow> rows;
  // The counts of a whole sheet's rows, which depend only on whether the row lies on the
  // sheet's low or high side in y and in z: per such kind of row (whole_row_kind in
  // kernels/fine_springs.cpp), laid out as one row of `count`. Kinds no row of the sheet has
  // are left 0.
  static constexpr int kRowKinds = 16;
  AlignedArray<std::uint8_t> shared_counts{12};
  // Per row of cells (as `rows`): its dirty cells in order, in groups of up to 8 within a
  // chunk; empty for a row without split copies. update_fine_springs_at lists the rows it
  // touched in stale_rows, and plan_stale_dirty_cells plans them again: the kernel must not
  // run while stale_rows is not empty.
  std::vector<std::vector<DirtyGroup>> dirty;
  std::vector<std::uint32_t> stale_rows;

  // Sizes `count` for `cells` cells in rows of `row_cells`, every count `value`.
  void resize_counts(std::size_t cell_count, std::size_t cells_per_row, std::uint8_t value) {
    cells = cell_count;
    row_cells = cells_per_row;
    count.resize(kSpringsPerCell * cells + 32);
    std::fill(count.begin(), count.end(), value);
  }
  std::size_t count_index(std::size_t cell, int slot) const {
    const std::size_t i = cell % row_cells;
    return (cell - i) * kSpringsPerCell + std::size_t(slot) * row_cells + i;
  }
  // The counts of slot `slot` for the row of cells that starts at cell `row_start`.
  const std::uint8_t* row_counts(std::size_t row_start, int slot) const {
    return count.data() + row_start * kSpringsPerCell + std::size_t(slot) * row_cells;
  }
  // The same counts as the kernel reads them: from shared_counts when the row has a shared row.
  const std::uint8_t* kernel_counts(const FineRow& row, std::size_t row_start, int slot) const {
    if (row.shared < 0) return row_counts(row_start, slot);
    return shared_counts.data() + (std::size_t(row.shared) * kSpringsPerCell + std::size_t(slot)) * row_cells;
  }
  std::uint8_t at(std::size_t cell, int slot) const { return count[count_index(cell, slot)]; }
  void set(std::size_t cell, int slot, std::uint8_t n) { count[count_index(cell, slot)] = n; }
};

// What a build needs besides the table, per lattice vertex: 1 when no node there has been
// split (and springs and stiffness factors are uniform), so the cells around it need no node
// comparisons. Valid for the topology it was prepared from only.
struct FineSpringsBuild {
  std::vector<std::uint8_t> whole_vertex;
};

// Ownership and counts of every cell's slots, from the current topology: prepare, then
// assign every cell (assign_fine_springs may run on disjoint cell ranges in parallel).
void build_fine_springs(const Topology& topo, const SpringTable& table, FineSprings& out);
FineSpringsBuild prepare_fine_springs(const Topology& topo, const SpringTable& table, FineSprings& out);
void assign_fine_springs(std::size_t begin, std::size_t end, const Topology& topo, const SpringTable& table,
                         const FineSpringsBuild& build, FineSprings& out);
// The same for the cells around lattice vertex `vertex` only: enough after a node there
// was split, since every spring whose coincidence the split can change ends at that vertex.
// Their rows' ranges and flags are widened to cover them, and the rows listed as stale
// (their dirty groups are planned by plan_stale_dirty_cells).
void update_fine_springs_at(const Topology& topo, const SpringTable& table, std::uint32_t vertex, FineSprings& out);
// Plans the dirty groups of the rows update_fine_springs_at has touched since the last call.
void plan_stale_dirty_cells(const Topology& topo, FineSprings& out);
// The rows [row_begin, row_end) of `out.rows` and `out.dirty`, from the cells' owned slots,
// copies and corners, once every cell has been assigned (rows may be planned in parallel).
// build_fine_springs plans every row.
void plan_fine_rows(std::size_t row_begin, std::size_t row_end, const Topology& topo, FineSprings& out);
// Every cell's `copies`, from the topology, and every row: what a table made by hand (counts
// and owned slots only) needs before the kernel can use it.
void plan_all_fine_rows(const Topology& topo, FineSprings& out);

}  // namespace papertear
