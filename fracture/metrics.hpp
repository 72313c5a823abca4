// What a run measured (issue "paper model", MODEL.md §7): per frame and at the end.
#pragma once
#include <cstdint>
#include <vector>

#include "core/world.hpp"

namespace papertear {

struct Metrics {
  std::int64_t step = 0;
  double time = 0.0;
  std::int64_t splits_inplane = 0;     // splits that opened an in-plane bond (axis x or y)
  std::int64_t splits_interlayer = 0;  // splits that opened a bond between layers (axis z)
  std::int64_t pieces = 0;             // connected components of cells through shared nodes
  std::vector<std::int64_t> piece_cells;  // each piece's cell count, largest first
  std::int64_t fragments = 0;          // pieces holding less than 1 % of the cells
  double fragment_fraction = 0.0;      // the fraction of all cells the fragments hold
  double torn_edge_length = 0.0;       // total length of torn in-plane cell faces, top layer
  // The tear in the top layer as cracks: chains of torn faces along the grid lines. The cracks
  // measured are all of them, or once the sheet is in two, those that separate the two
  // largest pieces; the main crack is the longest of them (docs/summary-schema.md).
  double edge_roughness = 0.0;         // length-weighted mean of path length / chord (>= 1; 0: no tear)
  double tear_length = 0.0;            // the main crack's chord (0: no tear)
  double splits_per_tear_length = 0.0; // splits_inplane / tear_length (0: no tear)
  double peeled_area = 0.0;            // area of separated faces between layers
  double grip_force = 0.0;             // spring force along the pull axis on the +axis grip
                                       // (tear: along -z on the grip that moves down)
  double indenter_force = 0.0;         // pierce: contact force resisting the indenter (+z)
  double kinetic_energy = 0.0;
  double elastic_energy = 0.0;
  std::int64_t intact_blocks = 0;      // blocks no crack has entered
};

// Calls f(name, field) for every field of a Metrics (const or not), in declaration order:
// the one list of the metrics' names that writers and readers (JSON summaries, run state)
// share. Fields are integers, doubles and piece_cells, a vector of integers (a JSON array).
template <class M, class F>
void visit_metrics(M& m, F&& f) {
  f("step", m.step);
  f("time", m.time);
  f("splits_inplane", m.splits_inplane);
  f("splits_interlayer", m.splits_interlayer);
  f("pieces", m.pieces);
  f("piece_cells", m.piece_cells);
  f("fragments", m.fragments);
  f("fragment_fraction", m.fragment_fraction);
  f("torn_edge_length", m.torn_edge_length);
  f("edge_roughness", m.edge_roughness);
  f("tear_length", m.tear_length);
  f("splits_per_tear_length", m.splits_per_tear_length);
  f("peeled_area", m.peeled_area);
  f("grip_force", m.grip_force);
  f("indenter_force", m.indenter_force);
  f("kinetic_energy", m.kinetic_energy);
  f("elastic_energy", m.elastic_energy);
  f("intact_blocks", m.intact_blocks);
}

// Measures a world. Deterministic (serial or fixed-order reductions).
Metrics measure(const World& world);

// The pull the sheet exerts on the +axis grip along the pull axis (Metrics::grip_force).
double grip_force(const World& world);
// The rate at which the grips do work on the sheet: the sum over springs with one end held of
// -f·v at that end. Integrated over a run it is the work spent deforming and tearing it
// (the quantity an Elmendorf tester measures).
double grip_power(const World& world);

}  // namespace papertear
