// Spring forces of the fine lattice, swept slot by slot along rows of cells (MODEL.md §4).
//
// Data flow: reads node positions and velocities (stage state), the cell→corner→node table,
// the per-cell stiffness factor, the 28-slot spring table and the merged-spring table
// (kernels/fine_springs.hpp: which cell evaluates which slot, for how many coincident
// springs, and each row's plan); adds each spring's force into its two end nodes.
//
// How: a row of cells (j, k) is taken slot by slot. For slot s, cell i's spring joins the
// vertices (i + ax, j + ay, k + az) and (i + bx, j + by, k + bz) of its corners a and b, so
// along the row both ends run over consecutive vertices, whose original nodes have those
// vertices' ids: W consecutive cells are one vector of W springs whose 12 end values are 12
// unaligned vector loads, and whose forces go back as 6 vector read-modify-writes. Nothing is
// held across springs, so the kernel needs few registers (the cell-centric kernel it
// replaced kept a cell's 8 corners and 8 force sums, 72 vectors, and spilled heavily with
// AVX2's 16 registers). Only the slots some cell of the row owns are swept, over the cells
// between their first and last owner. Cells with a split copy among their corners (after
// fracture) take count 0 there and are evaluated after the row's slots, cell by cell with
// their corners fetched one by one ("dirty" cells, kernels/cell_forces.cpp).
//
// Why the bits never depend on the vector width or the thread count: each node's force is a
// sum in one fixed order. Within a row, slot s's pass gives a node at most one term, since
// the a ends of the row's cells are distinct vertices, and so are the b ends, and a node sits
// at one vertex; so the order of lanes within a pass does not matter, only the order of the
// passes: rows (in the order the solver runs them), chunks of kRowChunk cells along the row,
// slots 0..27, and for the four edges along x (both ends on one row of vertices, where a node
// is the a end of one cell and the b end of the next) the a ends' pass, then the b ends';
// then the chunk's dirty cells in order, each adding one sum per corner. The vector body, the
// overlapping last vector of a range (its lanes already done add exact zeros), short ranges
// one lane at a time and the SIMD-off build all follow that order with the same operations
// per lane.
//
// Force of one spring (a → b), Hooke plus damping along the spring, times the number n of
// springs it stands for, with L^2 = d · d:
//   d = x_b - x_a,  f_a = (k n (L - L0) (L / L^2) + c n (Δv · d) / L^2) d,  f_b = -f_a.
// (L and 1 / L^2 both come straight from L^2, so the square root and the division overlap.)
// A lane with n = 0 adds exact zeros, which leave a sum that started at +0 bit for bit as it
// was: so sweeping cells that do not own a slot, or skipping a slot no cell owns, gives the
// same bits as evaluating only the owners.
#pragma once
#include <cstddef>
#include <cstdint>

#include "core/world.hpp"
#include "kernels/fine_springs.hpp"

namespace papertear {

// Flushes subnormal floats to zero (x86 MXCSR FTZ and DAZ) while it lives, then restores the
// caller's mode. Why: ahead of the wave from the grips, a sheet at rest holds velocities and
// forces that decay through the subnormal range, and every operation on a subnormal costs a
// microcode assist (~100 cycles): on a 300 x 300 x 5 sheet the spring kernel ran 10x slower
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
  const FineSprings* fine;  // which cell evaluates which slot, for how many springs; row plans
  const LatticeDims* dims;
};

struct ForceOutputs {
  float *fx, *fy, *fz;
};

// Adds the forces of the springs that the cells of rows (j, k), j in [j_begin, j_end) and
// every k, own into out, row by row (j, then k). Calls whose rows share no row of vertices
// may run in parallel; a node's terms come in the order of the calls, then of the rows.
void add_cell_row_forces(int j_begin, int j_end, const CellForceInputs& in, const ForceOutputs& out);
// The same one lane at a time (tests, and the check that vector width does not matter).
void add_cell_row_forces_scalar(int j_begin, int j_end, const CellForceInputs& in, const ForceOutputs& out);

}  // namespace papertear
