// Spring forces of the fine lattice, computed cell by cell (MODEL.md §4).
//
// Data flow: reads node positions and velocities (stage state), the cell→corner→node table,
// the per-cell stiffness factor and the 28-slot spring table; adds each cell's corner forces
// into the node force columns.
//
// Why it is race-free and deterministic: a call only ever gets cells of ONE colour
// (i%2, j%2, k%2), and cells of one colour share no node (core/world.hpp), so the scatter
// never writes a node twice, from any thread. The caller runs the 8 colours one after
// another in a fixed order, so each node's force is the sum of its cells' contributions in
// colour order: the same bits on every thread count.
//
// Why cell-centric: a cell's 28 springs touch only its 8 corners, so the corners are loaded
// once and the springs are evaluated in registers (the spring loop is fully unrolled),
// sixteen cells per AVX-512 vector (eight with AVX2). Coincident springs of neighbouring
// cells are evaluated once, by one of the cells, weighted by their number
// (kernels/fine_springs.hpp): a group whose cells own only the 13 low slots (most groups)
// runs 13 springs instead of 28. Groups of cells along a lattice row ("regular": every
// group the solver plans, see CellGroup) load each corner pair with two vector loads and a
// permute from the nodes of the lattice vertices, and add their forces back the same way;
// corners whose node is a split copy are patched in and added one lane at a time, and a row
// shorter than a vector masks the lanes past its end. Other groups (unplanned calls, runs of
// cells that are not a row's) fetch corners with scalar loads into a small aligned buffer (on
// the development machine hardware gathers were slower). All paths give each lane the same
// values and each node one addition, so the bits are the same.
//
// Force of one spring (a → b), Hooke plus damping along the spring, times the number n of
// springs it stands for:
//   d = x_b - x_a,  L = |d|,  f_a = n ((k (L - L0) + c (Δv · d) / L) / L) d,  f_b = -f_a.
// A slot with n = 0 in some lanes adds exact zeros there, which leaves a sum that started at
// +0 bit for bit as it was: so skipping a slot no lane owns, as the fast groups do, gives
// the same bits as evaluating it.
#pragma once
#include <cstddef>
#include <cstdint>

#include "core/world.hpp"
#include "kernels/fine_springs.hpp"

namespace papertear {

// Flushes subnormal floats to zero (x86 MXCSR FTZ and DAZ) while it lives, then restores the
// caller's mode. Why: ahead of the wave from the grips, a sheet at rest holds velocities and
// forces that decay through the subnormal range, and every operation on a subnormal costs a
// microcode assist (~100 cycles): on a 300 x 300 x 5 sheet the cell kernel ran 10x slower
// per cell than on 90 x 90 x 5. Every force and integration kernel sets it on entry, on
// whichever thread runs the chunk, for its vector body and scalar tail alike, so results
// are still the same on any thread count and vector width. The values it changes are below
// 1.2e-38, far under the model's tolerances. A no-op off x86 (ARM flushes by FPCR).
class FlushSubnormals {
 public:
  FlushSubnormals();
  ~FlushSubnormals();
  FlushSubnormals(const FlushSubnormals&) = delete;
  FlushSubnormals& operator=(const FlushSubnormals&) = delete;

 private:
  unsigned saved_ = 0;
};

struct CellForceInputs {
  const float *px, *py, *pz;  // stage positions
  const float *vx, *vy, *vz;  // stage velocities
  const std::uint32_t* cell_nodes;
  const float* cell_scale;
  const SpringTable* table;
  const FineSprings* fine;  // which cell evaluates which slot, and for how many springs
};

struct ForceOutputs {
  float *fx, *fy, *fz;
};

// How the kernel runs one vector group of cells: which loader and which slot set, and for a
// regular group its corner pairs' first nodes. Deciding it reads the cells' merged-spring
// masks and corner rows, about 5 cache lines per group; a plan made once while the topology
// holds still (core/solver.cpp replans after each step that split nodes) saves that in
// every stage. A plan is valid only for the cell table and merged-spring table it was made
// from.
struct CellGroup {
  std::uint32_t base[4];      // regular groups: the first node of each corner pair (dy, dz)
  std::uint32_t first_cell;
  std::uint32_t kind;         // kernels/cell_forces.cpp
  std::uint16_t patch[8];     // per corner: the lanes whose node there is a split copy
  std::uint32_t lanes;        // cells in the group: the vector width, or a shorter row's length
};

// Adds the spring forces of cells[begin, end) into out. All cells must share a colour.
void add_cell_forces(std::size_t begin, std::size_t end, const std::uint32_t* cells,
                     const CellForceInputs& in, const ForceOutputs& out);
// The same for cells[begin, end) that are whole rows of per_row cells each (begin and end
// multiples of per_row), with no vector group straddling a row end: the same bits, faster.
// With a plan (plan_cell_rows over the same list, from group 0) the groups run as planned.
void add_cell_row_forces(std::size_t begin, std::size_t end, std::size_t per_row, const std::uint32_t* cells,
                         const CellForceInputs& in, const ForceOutputs& out, const CellGroup* plan = nullptr);
// Vector groups per row of per_row cells in add_cell_row_forces (a row shorter than a vector
// is one group).
std::size_t cell_groups_per_row(std::size_t per_row);
// Plans the groups of list rows [row_begin, row_end) of `cells` (rows of per_row cells) into
// plan[row * cell_groups_per_row(per_row) + g].
void plan_cell_rows(std::size_t row_begin, std::size_t row_end, std::size_t per_row, const std::uint32_t* cells,
                    const LatticeDims& dims, const CellForceInputs& in, CellGroup* plan);
// The same as add_cell_forces with the scalar lane type only (for tests and the SIMD-off comparison).
void add_cell_forces_scalar(std::size_t begin, std::size_t end, const std::uint32_t* cells,
                            const CellForceInputs& in, const ForceOutputs& out);

}  // namespace papertear
