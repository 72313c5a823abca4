// Lines drawn on the sheet to steer a tear (scene `[[line]]`, core/scene.hpp LineParams):
// cuts, scores and perforations given as polylines.
//
// Which bonds a line acts on. An in-plane bond joins two cells side by side; it stands for
// the segment between their centres. A line acts on the bond when one of its segments
// crosses that segment. The test is done as if the whole polyline were shifted by an
// infinitesimal (ε, ε²), so that no tie is left: a polyline point exactly on a row (column)
// of cell centres counts as just above (right of) it, and a cell centre exactly on a segment
// counts as on the side the shift leaves it. Hence a line along a grid line of the lattice
// (x or y an integer) opens exactly the faces under it, a line through a row of centres
// opens the faces just above that row, and a polyline stays connected through its corners.
// Orientations are evaluated in double in a fixed order: exact for coordinates with few
// binary digits (halves, quarters, ...), deterministic for any.
//
// What a line does, in the top `depth` layers (all when 0), in scene order after the notch:
//  * score: multiplies the opening strain of each bond it crosses by `strength`;
//  * cut: opens each bond it crosses before the first step;
//  * perforation: cuts the bonds it crosses at arc length s along the line with
//    s mod pitch < duty * pitch (holes, starting with one at its first point) and scores
//    the others (lands) with `strength`.
// Opening regroups the cells at each vertex of an opened face by the faces still closed,
// and gives each group after the first its own node (the split machinery of
// fracture_pass.hpp, so masses, grips, blocks and the invariants follow). Blocks a cut
// crosses lose their block springs. A cut records no split events: like the notch, it is
// part of the initial sheet. A cut `depth` layers deep ends like the notch in a sharp tip:
// the faces of its deepest layer stay joined along their lower edge.
#pragma once
#include <array>
#include <span>
#include <vector>

#include "core/world.hpp"

namespace papertear {

// An in-plane bond crossed by a line: between cell column (i, j) and (i + 1, j) when axis is
// 0, (i, j + 1) when axis is 1; `arc` is the arc length along the polyline, in cells, at the
// crossing.
struct BondCrossing {
  int i = 0, j = 0, axis = 0;
  double arc = 0.0;
};

// Every crossing of the polyline with the bonds of an nx × ny sheet, ordered by arc length
// (then axis, j, i). A bond crossed more than once appears once per crossing.
std::vector<BondCrossing> line_crossings(std::span<const std::array<double, 2>> points, int nx, int ny);

// Applies the scene's lines to a world whose bond strengths are assigned (and notch cut).
void apply_lines(World& world);

}  // namespace papertear
