#include "fracture/metrics.hpp"

#include <algorithm>
#include <array>
#include <numeric>
#include <vector>

#include "core/contact.hpp"
#include "fracture/connectivity.hpp"
#include "kernels/energy.hpp"
#include "kernels/spring.hpp"

namespace papertear {
namespace {

struct DisjointSets {
  std::vector<std::uint32_t> parent;
  explicit DisjointSets(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  std::uint32_t find(std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(std::uint32_t a, std::uint32_t b) {
    a = find(a), b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

// Pieces: cells joined through any shared node. Returns each cell's piece (its lowest cell).
std::vector<std::uint32_t> label_pieces(const World& w) {
  const std::size_t cells = std::size_t(w.topo.dims.cells());
  DisjointSets sets(cells);
  std::vector<std::uint32_t> first_cell(w.nodes.count, UINT32_MAX);
  for (std::uint32_t c = 0; c < cells; ++c)
    for (int q = 0; q < 8; ++q) {
      const std::uint32_t n = w.topo.node(c, q);
      if (first_cell[n] == UINT32_MAX) first_cell[n] = c;
      else sets.unite(c, first_cell[n]);
    }
  std::vector<std::uint32_t> label(cells);
  for (std::uint32_t c = 0; c < cells; ++c) label[c] = sets.find(c);
  return label;
}

// The two largest pieces that hold at least a tenth of the cells each (ties: lower label
// first); UINT32_MAX where there is none. Smaller pieces are fragments, not halves of a tear.
std::array<std::uint32_t, 2> two_largest(const std::vector<std::uint32_t>& label, std::int64_t& pieces) {
  std::vector<std::uint32_t> size(label.size(), 0);
  for (std::uint32_t l : label) ++size[l];
  std::array<std::uint32_t, 2> best{UINT32_MAX, UINT32_MAX};
  pieces = 0;
  for (std::uint32_t l = 0; l < size.size(); ++l) {
    if (size[l] == 0) continue;
    ++pieces;
    if (best[0] == UINT32_MAX || size[l] > size[best[0]]) best = {l, best[0]};
    else if (best[1] == UINT32_MAX || size[l] > size[best[1]]) best[1] = l;
  }
  for (std::uint32_t& b : best)
    if (b != UINT32_MAX && size[b] * 10 < label.size()) b = UINT32_MAX;
  return best;
}

// Torn faces of the top layer: their total length and the path's roughness. Once the sheet
// is in pieces, the tear is the boundary between the two largest pieces (fragments and
// cracks that did not go through are left out); before that, every torn face counts.
void measure_top_edges(const World& w, const std::vector<std::uint32_t>& label,
                       const std::array<std::uint32_t, 2>& main, Metrics& m) {
  const LatticeDims& d = w.topo.dims;
  const int k = d.nl - 1;
  const bool separated = main[1] != UINT32_MAX;
  double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
  double length = 0.0, path = 0.0;
  for (int j = 0; j < d.ny; ++j)
    for (int i = 0; i < d.nx; ++i)
      for (int axis = 0; axis < 2; ++axis) {
        if ((axis == 0 ? i + 1 : j + 1) >= (axis == 0 ? d.nx : d.ny)) continue;
        const std::uint32_t c = d.cell_index(i, j, k);
        if (faces_connected(w, c, 2 * axis + 1)) continue;
        const double face = axis == 0 ? d.hy : d.hx;
        length += face;
        const std::uint32_t n = axis == 0 ? d.cell_index(i + 1, j, k) : d.cell_index(i, j + 1, k);
        const bool on_tear = !separated || (label[c] != label[n] && (label[c] == main[0] || label[c] == main[1]) &&
                                            (label[n] == main[0] || label[n] == main[1]));
        if (!on_tear) continue;
        path += face;
        const double centre[2] = {(i + (axis == 0 ? 1.0 : 0.5)) * d.hx, (j + (axis == 1 ? 1.0 : 0.5)) * d.hy};
        for (int a = 0; a < 2; ++a) {
          lo[a] = std::min(lo[a], centre[a]);
          hi[a] = std::max(hi[a], centre[a]);
        }
      }
  m.torn_edge_length = length;
  if (path == 0.0) return;
  const double extent = std::max(hi[0] - lo[0] + d.hx, hi[1] - lo[1] + d.hy);
  m.edge_roughness = path / extent;
}

double peeled_area(const World& w) {
  const LatticeDims& d = w.topo.dims;
  double area = 0.0;
  for (int k = 0; k + 1 < d.nl; ++k)
    for (int j = 0; j < d.ny; ++j)
      for (int i = 0; i < d.nx; ++i)
        if (!faces_connected(w, d.cell_index(i, j, k), 5)) area += d.hx * d.hy;
  return area;
}

// Calls fn(node, f) for every spring (fine and coarse) with exactly one end held by a grip:
// `node` is that end and f the spring's force on it. Springs inside a grip cancel.
template <class Fn>
void for_each_grip_spring(const World& w, Fn&& fn) {
  const NodeStore& n = w.nodes;
  auto visit = [&](std::uint32_t a, std::uint32_t b, float rest, float k, float c) {
    if ((n.grip[a] != 0) == (n.grip[b] != 0)) return;
    const SpringEval e = eval_spring(n.px[a], n.py[a], n.pz[a], n.px[b], n.py[b], n.pz[b], n.vx[a], n.vy[a], n.vz[a],
                                     n.vx[b], n.vy[b], n.vz[b], rest, k, c);
    if (n.grip[a] != 0) fn(a, std::array<double, 3>{e.fx, e.fy, e.fz});
    else fn(b, std::array<double, 3>{-double(e.fx), -double(e.fy), -double(e.fz)});
  };
  for (std::uint32_t c = 0; c < std::uint32_t(w.topo.dims.cells()); ++c) {
    const float s = w.topo.cell_scale[c];
    for (int i = 0; i < kSpringsPerCell; ++i) {
      const SpringSlot& slot = kSpringSlots[std::size_t(i)];
      visit(w.topo.node(c, slot.a), w.topo.node(c, slot.b), w.springs.rest[std::size_t(i)],
            s * w.springs.stiffness[std::size_t(i)], s * w.springs.damping[std::size_t(i)]);
    }
  }
  const CoarseSprings& cs = w.coarse;
  for (std::size_t i = 0; i < cs.size(); ++i)
    visit(w.topo.node(cs.cell_a[i], cs.corner_a[i]), w.topo.node(cs.cell_b[i], cs.corner_b[i]), cs.rest[i],
          cs.stiffness[i], cs.damping[i]);
}

}  // namespace

// The pull the sheet exerts on the +axis grip (grip 2), along the pull axis (positive:
// tension, i.e. the sheet pulls the grip back towards -axis). Tear: the same along z on the
// second grip, which moves down (positive: the sheet holds it back, pulling it up).
double grip_force(const World& w) {
  if (w.grips.size() < 2) return 0.0;
  const bool tear = w.scene.load.kind == "tear";
  const int axis = tear ? 2 : (w.scene.load.axis == 'y' ? 1 : 0);
  const double sign = tear ? -1.0 : 1.0;
  double total = 0.0;
  for_each_grip_spring(w, [&](std::uint32_t node, const std::array<double, 3>& f) {
    if (w.nodes.grip[node] == 2) total -= f[std::size_t(axis)];
  });
  return sign * total;
}

// The grips push against the springs' pull: their power is -f·v at every held end.
double grip_power(const World& w) {
  double total = 0.0;
  for_each_grip_spring(w, [&](std::uint32_t node, const std::array<double, 3>& f) {
    total -= f[0] * w.nodes.vx[node] + f[1] * w.nodes.vy[node] + f[2] * w.nodes.vz[node];
  });
  return total;
}

Metrics measure(const World& w) {
  Metrics m;
  m.step = w.step;
  m.time = w.time;
  for (const SplitEvent& e : w.events) (e.interlayer ? m.splits_interlayer : m.splits_inplane) += 1;
  const std::vector<std::uint32_t> label = label_pieces(w);
  measure_top_edges(w, label, two_largest(label, m.pieces), m);
  m.peeled_area = peeled_area(w);
  m.grip_force = grip_force(w);
  m.indenter_force = indenter_force(w);
  m.kinetic_energy = kinetic_energy(0, w.nodes.count, w.nodes);
  m.elastic_energy = cell_elastic_energy(0, std::size_t(w.topo.dims.cells()), w) +
                     coarse_elastic_energy(0, w.coarse.size(), w);
  m.intact_blocks = std::count_if(w.blocks.begin(), w.blocks.end(), [](const Block& b) { return b.intact; });
  return m;
}

}  // namespace papertear
