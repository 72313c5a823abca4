#include "core/invariants.hpp"

#include <cmath>

#include "core/elasticity.hpp"

namespace papertear {
namespace {

struct Report {
  std::vector<std::string> problems;
  std::size_t limit;
  bool full() const { return problems.size() >= limit; }
  void add(std::string s) {
    if (!full()) problems.push_back(std::move(s));
  }
};

// Every corner names a live node that sits at the lattice vertex of that corner.
void check_cells(const World& w, Report& r, std::vector<double>& mass) {
  const LatticeDims& d = w.topo.dims;
  const double one_cell = cell_mass(w.scene.material, d);
  for (std::uint32_t c = 0; c < std::uint32_t(d.cells()) && !r.full(); ++c) {
    auto ijk = d.cell_ijk(c);
    for (int q = 0; q < 8; ++q) {
      const std::uint32_t n = w.topo.node(c, q);
      if (n >= w.nodes.count) {
        r.add("cell " + std::to_string(c) + " corner " + std::to_string(q) + " names node " +
              std::to_string(n) + " beyond the node count " + std::to_string(w.nodes.count));
        continue;
      }
      const std::uint32_t v = d.corner_vertex(ijk, q);
      if (w.nodes.vertex[n] != v)
        r.add("node " + std::to_string(n) + " used by cell " + std::to_string(c) + " at vertex " +
              std::to_string(v) + " but recorded at vertex " + std::to_string(w.nodes.vertex[n]));
      mass[n] += one_cell / 8.0;
    }
  }
}

void check_nodes(const World& w, Report& r, const std::vector<double>& mass) {
  for (std::size_t n = 0; n < w.nodes.count && !r.full(); ++n) {
    if (mass[n] == 0.0) {
      r.add("node " + std::to_string(n) + " has no cell");
      continue;
    }
    if (std::fabs(double(w.nodes.mass[n]) - mass[n]) > 1e-6 * mass[n])
      r.add("node " + std::to_string(n) + " has mass " + std::to_string(w.nodes.mass[n]) +
            " but its cells give " + std::to_string(mass[n]));
    const bool gripped = w.nodes.grip[n] != 0;
    if ((w.nodes.free_mask[n] == 0.0f) != gripped)
      r.add("node " + std::to_string(n) + " has a free mask that disagrees with its grip");
    const float vals[3] = {w.nodes.px[n], w.nodes.py[n], w.nodes.pz[n]};
    for (float x : vals)
      if (!std::isfinite(x)) r.add("node " + std::to_string(n) + " has a non-finite position");
  }
}

void check_coarse(const World& w, Report& r) {
  const CoarseSprings& s = w.coarse;
  const std::size_t cells = std::size_t(w.topo.dims.cells());
  for (std::size_t i = 0; i < s.size() && !r.full(); ++i) {
    if (s.cell_a[i] >= cells || s.cell_b[i] >= cells || s.corner_a[i] > 7 || s.corner_b[i] > 7)
      r.add("block spring " + std::to_string(i) + " names a cell or corner outside the lattice");
    else if (s.block[i] >= w.blocks.size())
      r.add("block spring " + std::to_string(i) + " names a block that does not exist");
    else if (!w.blocks[s.block[i]].intact && s.stiffness[i] != 0.0f)
      r.add("block spring " + std::to_string(i) + " of a cracked block still has stiffness");
  }
}

}  // namespace

std::vector<std::string> check_invariants(const World& w, std::size_t limit) {
  Report r{{}, limit};
  if (w.topo.cell_nodes.size() != std::size_t(w.topo.dims.cells()) * 8)
    r.add("the cell table has " + std::to_string(w.topo.cell_nodes.size()) + " entries for " +
          std::to_string(w.topo.dims.cells()) + " cells");
  if (!r.problems.empty()) return r.problems;
  std::vector<double> mass(w.nodes.count, 0.0);
  check_cells(w, r, mass);
  check_nodes(w, r, mass);
  check_coarse(w, r);
  return r.problems;
}

}  // namespace papertear
