#include "fracture/metrics.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <numeric>
#include <queue>
#include <utility>
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

struct Piece {
  std::uint32_t label;  // its lowest cell
  std::int64_t cells;
};

// The pieces, largest first (ties: lower label first).
std::vector<Piece> pieces_by_size(const std::vector<std::uint32_t>& label) {
  std::vector<std::int64_t> size(label.size(), 0);
  for (std::uint32_t l : label) ++size[l];
  std::vector<Piece> pieces;
  for (std::uint32_t l = 0; l < size.size(); ++l)
    if (size[l] > 0) pieces.push_back({l, size[l]});
  std::stable_sort(pieces.begin(), pieces.end(), [](const Piece& a, const Piece& b) { return a.cells > b.cells; });
  return pieces;
}

// Counts and sizes; a piece under 1 % of the cells is a fragment, not a part of the sheet.
void measure_pieces(const std::vector<Piece>& pieces, std::size_t cells, Metrics& m) {
  m.pieces = std::int64_t(pieces.size());
  std::int64_t fragment_cells = 0;
  for (const Piece& p : pieces) {
    m.piece_cells.push_back(p.cells);
    if (std::size_t(p.cells) * 100 >= cells) continue;
    ++m.fragments;
    fragment_cells += p.cells;
  }
  m.fragment_fraction = double(fragment_cells) / double(cells);
}

// The two pieces a tear has separated: the two largest, when each holds at least a tenth of
// the cells; UINT32_MAX when the sheet is not in two (smaller pieces are torn-off bits).
std::array<std::uint32_t, 2> halves(const std::vector<Piece>& pieces, std::size_t cells) {
  if (pieces.size() < 2 || std::size_t(pieces[1].cells) * 10 < cells) return {UINT32_MAX, UINT32_MAX};
  return {pieces[0].label, pieces[1].label};
}

// The torn in-plane faces of the top layer as edges of its grid of vertices (I, J), numbered
// v = I + (nx + 1) J: the face between cells (i, j) and (i + 1, j) is the edge from (i + 1, j)
// to (i + 1, j + 1), the face between (i, j) and (i, j + 1) the edge from (i, j + 1) to
// (i + 1, j + 1). Paths along a crack then run on grid lines, so none is shorter than the
// straight line between its ends.
constexpr std::uint8_t kTorn = 1, kSeparates = 2;  // kSeparates: between the two halves
struct TearGraph {
  std::uint32_t row = 0;  // vertices per grid row: nx + 1
  double hx = 1.0, hy = 1.0;
  std::vector<std::uint8_t> east, north;  // flags of the edge v -> v + 1 (length hx), v -> v + row (hy)
};

TearGraph tear_graph(const World& w, const std::vector<std::uint32_t>& label,
                     const std::array<std::uint32_t, 2>& half) {
  const LatticeDims& d = w.topo.dims;
  const int k = d.nl - 1;
  TearGraph g{std::uint32_t(d.nx + 1), d.hx, d.hy, {}, {}};
  g.east.assign(std::size_t(d.nx + 1) * std::size_t(d.ny + 1), 0);
  g.north.assign(g.east.size(), 0);
  for (int j = 0; j < d.ny; ++j)
    for (int i = 0; i < d.nx; ++i)
      for (int axis = 0; axis < 2; ++axis) {
        if ((axis == 0 ? i + 1 : j + 1) >= (axis == 0 ? d.nx : d.ny)) continue;
        const std::uint32_t c = d.cell_index(i, j, k);
        if (faces_connected(w, c, 2 * axis + 1)) continue;
        const std::uint32_t n = axis == 0 ? d.cell_index(i + 1, j, k) : d.cell_index(i, j + 1, k);
        const bool separates = half[1] != UINT32_MAX && label[c] != label[n] &&
                               (label[c] == half[0] || label[c] == half[1]) &&
                               (label[n] == half[0] || label[n] == half[1]);
        const std::uint8_t flags = kTorn | (separates ? kSeparates : 0);
        if (axis == 0) g.north[std::size_t(i + 1) + g.row * std::size_t(j)] = flags;
        else g.east[std::size_t(i) + g.row * std::size_t(j + 1)] = flags;
      }
  return g;
}

// Calls fn(u, length, flags) for every torn edge from vertex v to u. East edges exist only for
// I < nx and north ones for J < ny, so u is always on the grid.
template <class Fn>
void for_each_torn_edge(const TearGraph& g, std::uint32_t v, Fn&& fn) {
  if (g.east[v]) fn(v + 1, g.hx, g.east[v]);
  if (v % g.row > 0 && g.east[v - 1]) fn(v - 1, g.hx, g.east[v - 1]);
  if (g.north[v]) fn(v + g.row, g.hy, g.north[v]);
  if (v >= g.row && g.north[v - g.row]) fn(v - g.row, g.hy, g.north[v - g.row]);
}

bool torn_at(const TearGraph& g, std::uint32_t v) {
  bool any = false;
  for_each_torn_edge(g, v, [&](std::uint32_t, double, std::uint8_t) { any = true; });
  return any;
}

// A crack: a connected set of torn edges. Lengths are kept as edge counts, so that a path's
// length and its chord are computed from the same integers (see measure_tear).
struct Crack {
  std::vector<std::uint32_t> vertices;  // in breadth-first order from its lowest vertex
  std::int64_t along_x = 0, along_y = 0;
  bool separates = false;  // holds an edge between the two halves
  double length(const TearGraph& g) const { return double(along_x) * g.hx + double(along_y) * g.hy; }
};

std::vector<Crack> find_cracks(const TearGraph& g) {
  std::vector<std::uint8_t> seen(g.east.size(), 0);
  std::vector<Crack> cracks;
  for (std::uint32_t s = 0; s < seen.size(); ++s) {
    if (seen[s] || !torn_at(g, s)) continue;
    Crack c;
    c.vertices.push_back(s);
    seen[s] = 1;
    for (std::size_t q = 0; q < c.vertices.size(); ++q) {
      const std::uint32_t v = c.vertices[q];
      for_each_torn_edge(g, v, [&](std::uint32_t u, double, std::uint8_t flags) {
        if (u > v) ++(u == v + 1 ? c.along_x : c.along_y);  // each edge once, from its lower end
        c.separates |= (flags & kSeparates) != 0;
        if (!seen[u]) c.vertices.push_back(u), seen[u] = 1;
      });
    }
    cracks.push_back(std::move(c));
  }
  return cracks;
}

// The crack's vertex farthest from `from` along it (ties: the lowest), by Dijkstra; `dist`
// is infinite on the crack before and after.
std::uint32_t farthest(const TearGraph& g, const Crack& c, std::uint32_t from, std::vector<double>& dist) {
  using Item = std::pair<double, std::uint32_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
  dist[from] = 0.0;
  queue.push({0.0, from});
  std::uint32_t best = from;
  while (!queue.empty()) {
    const double d = queue.top().first;  // not a structured binding: clang 14 cannot capture one
    const std::uint32_t v = queue.top().second;
    queue.pop();
    if (d > dist[v]) continue;
    if (d > dist[best] || (d == dist[best] && v < best)) best = v;
    for_each_torn_edge(g, v, [&](std::uint32_t u, double length, std::uint8_t) {
      if (d + length < dist[u]) queue.push({dist[u] = d + length, u});
    });
  }
  for (std::uint32_t v : c.vertices) dist[v] = INFINITY;
  return best;
}

// The straight distance between the crack's far ends: the farthest vertex from any one, then
// the farthest from that (exact for a chain or a tree of torn edges).
double chord(const TearGraph& g, const Crack& c, std::vector<double>& dist) {
  const std::uint32_t a = farthest(g, c, c.vertices.front(), dist);
  const std::uint32_t b = farthest(g, c, a, dist);
  const double dx = std::abs(double(a % g.row) - double(b % g.row)) * g.hx;
  const double dy = std::abs(double(a / g.row) - double(b / g.row)) * g.hy;
  return std::hypot(dx, dy);
}

// Torn length, roughness, tear length. The cracks measured are the ones that separate the two
// halves once the sheet is in two (cracks that did not go through, and fragments' outlines,
// are left out), every crack before that; the main crack is the longest measured one.
void measure_tear(const TearGraph& g, std::int64_t splits_inplane, Metrics& m) {
  const std::vector<Crack> cracks = find_cracks(g);
  const bool separated = std::any_of(cracks.begin(), cracks.end(), [](const Crack& c) { return c.separates; });
  std::vector<double> dist(g.east.size(), INFINITY);
  std::int64_t along_x = 0, along_y = 0;
  double weighted = 0.0, total = 0.0, main_length = 0.0;
  for (const Crack& c : cracks) {
    along_x += c.along_x, along_y += c.along_y;
    if (separated && !c.separates) continue;
    // length / chord >= 1: a path between the far ends takes at least |dI| edges along x and
    // |dJ| along y, so length >= |dI| hx + |dJ| hy >= the chord (rounding is monotonic in both).
    const double length = c.length(g), chord_length = chord(g, c, dist);
    weighted += length * (length / chord_length);
    total += length;
    if (length > main_length) main_length = length, m.tear_length = chord_length;
  }
  m.torn_edge_length = double(along_x) * g.hx + double(along_y) * g.hy;
  if (total == 0.0) return;
  m.edge_roughness = weighted / total;
  m.splits_per_tear_length = double(splits_inplane) / m.tear_length;
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
  const std::vector<Piece> pieces = pieces_by_size(label);
  measure_pieces(pieces, label.size(), m);
  measure_tear(tear_graph(w, label, halves(pieces, label.size())), m.splits_inplane, m);
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
