// Fibre blocks (MODEL.md §3): the sheet's cells grouped into staggered bricks elongated along
// the grain, each with a random strength factor; the bond strengths of every cell face that
// follow from them; and the block lattice (coarse springs between each block's corners).
// The layout is a pure function of the scene (sizes, material, run.seed).
#pragma once
#include "core/world.hpp"

namespace papertear {

// Fills world.blocks, topo.cell_block, topo.face_strain and world.coarse for an intact
// lattice built by build_lattice.
void lay_fibre_blocks(World& world);
// Recomputes every face's bond strength (topo.face_strain) from topo.cell_block and the
// blocks' strength factors, e.g. after a test lays out blocks by hand.
void assign_bond_strengths(World& world);

}  // namespace papertear
