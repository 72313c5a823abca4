#include "fracture/lines.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

#include "fracture/fracture_pass.hpp"
#include "fracture/node_cells.hpp"

namespace papertear {
namespace {

using Point = std::array<double, 2>;

// The side of cell centre c relative to the segment p -> q shifted by (ε, ε²): the sign of
// cross(q - p, c - p - shift). When c lies exactly on the segment's line, the shift's
// leading term decides: -cross(q - p, (ε, ε²)) = dy ε - dx ε².
bool centre_on_left(const Point& p, const Point& q, const Point& c) {
  const double dx = q[0] - p[0], dy = q[1] - p[1];
  const double o = dx * (c[1] - p[1]) - dy * (c[0] - p[0]);
  if (o != 0.0) return o > 0.0;
  return dy > 0.0 || (dy == 0.0 && dx < 0.0);
}

// Whether the shifted segment p -> q crosses the bond between centres a and b = a + unit
// vector along `axis`. The shifted end points never lie on the bond's line: a coordinate
// equal to the line's counts as beyond it.
bool crosses(const Point& p, const Point& q, const Point& a, const Point& b, int axis) {
  const int across = 1 - axis;  // the bond's line is {x[across] = a[across]}
  if ((p[std::size_t(across)] >= a[std::size_t(across)]) == (q[std::size_t(across)] >= a[std::size_t(across)]))
    return false;
  return centre_on_left(p, q, a) != centre_on_left(p, q, b);
}

// Crossings of segment p -> q (starting at arc length `arc0`) with the bonds along `axis`:
// row by row of the bonds' lines, testing the few bonds around where the segment meets it.
void segment_crossings(const Point& p, const Point& q, double arc0, int axis, int nx, int ny,
                       std::vector<BondCrossing>& out) {
  const std::size_t al = std::size_t(axis), ac = std::size_t(1 - axis);
  const int n_along = axis == 0 ? nx : ny, n_across = axis == 0 ? ny : nx;
  const double lo = std::min(p[ac], q[ac]), hi = std::max(p[ac], q[ac]);
  const double length = std::hypot(q[0] - p[0], q[1] - p[1]);
  const int first = std::max(0, int(std::floor(lo - 0.5))), last = std::min(n_across - 1, int(std::ceil(hi - 0.5)));
  for (int r = first; r <= last; ++r) {
    const double line = r + 0.5;  // the centres' coordinate across the bonds
    if ((p[ac] >= line) == (q[ac] >= line)) continue;
    const double t = (line - p[ac]) / (q[ac] - p[ac]);
    const double meet = p[al] + t * (q[al] - p[al]);
    const int near = int(std::floor(meet));
    for (int s = std::max(0, near - 2); s <= std::min(n_along - 2, near + 1); ++s) {
      Point a{}, b{};
      a[al] = s + 0.5;
      b[al] = s + 1.5;
      a[ac] = b[ac] = line;
      if (!crosses(p, q, a, b, axis)) continue;
      BondCrossing c;
      c.i = axis == 0 ? s : r;
      c.j = axis == 0 ? r : s;
      c.axis = axis;
      c.arc = arc0 + std::clamp(t, 0.0, 1.0) * length;
      out.push_back(c);
    }
  }
}

bool is_hole(const LineParams& line, double arc) {
  if (line.kind == "cut") return true;
  if (line.kind != "perforation") return false;
  return std::fmod(arc, line.pitch) < line.duty * line.pitch;
}

// One bond a line acts on, and whether it is cut (else weakened).
struct BondAction {
  int i, j, axis;
  bool cut;
};

// The line's crossings, one per bond: a bond crossed twice is cut if either crossing is.
std::vector<BondAction> bond_actions(const LineParams& line, int nx, int ny) {
  std::vector<BondAction> out;
  for (const BondCrossing& c : line_crossings(line.points, nx, ny)) out.push_back({c.i, c.j, c.axis, is_hole(line, c.arc)});
  std::sort(out.begin(), out.end(), [](const BondAction& a, const BondAction& b) {
    if (a.axis != b.axis) return a.axis < b.axis;
    if (a.j != b.j) return a.j < b.j;
    if (a.i != b.i) return a.i < b.i;
    return a.cut > b.cut;  // the cut one first: unique() keeps it
  });
  out.erase(std::unique(out.begin(), out.end(), [](const BondAction& a, const BondAction& b) {
              return a.axis == b.axis && a.j == b.j && a.i == b.i;
            }), out.end());
  return out;
}

// Scores the bond's faces or marks them open (`opened`: per cell, bit f for face f), in
// the layers the line reaches.
void apply_line(World& w, const LineParams& line, std::vector<std::uint8_t>& opened) {
  const LatticeDims& d = w.topo.dims;
  const int top = line.depth == 0 ? 0 : d.nl - line.depth;
  for (const BondAction& b : bond_actions(line, d.nx, d.ny))
    for (int k = top; k < d.nl; ++k) {
      const std::uint32_t low = d.cell_index(b.i, b.j, k);
      const auto high = std::uint32_t(d.neighbour(b.i, b.j, k, 2 * b.axis + 1));
      const std::size_t f_low = std::size_t(2 * b.axis + 1), f_high = std::size_t(2 * b.axis);
      if (b.cut) {
        opened[low] = std::uint8_t(opened[low] | (1u << f_low));
        opened[high] = std::uint8_t(opened[high] | (1u << f_high));
        continue;
      }
      for (auto [cell, face] : {std::pair{low, f_low}, std::pair{high, f_high}}) {
        float& strain = w.topo.face_strain[std::size_t(cell) * kFacesPerCell + face];
        strain = float(double(strain) * line.strength);
      }
    }
}

// Gives each group of the node's cells still joined through closed faces its own node
// (the group of its lowest cell keeps it). Two cells around a vertex touch through a face
// when their corners differ along one axis; the lower one along it owns face 2·axis + 1.
void regroup_node(World& w, std::uint32_t node, const std::vector<std::uint8_t>& opened) {
  const NodeCells cells = cells_of_node(w, node);
  std::array<int, 8> group{};
  for (int i = 0; i < cells.count; ++i) group[std::size_t(i)] = i;
  for (bool changed = true; changed;) {
    changed = false;
    for (int a = 0; a < cells.count; ++a)
      for (int b = 0; b < cells.count; ++b) {
        const CellCorner &ca = cells.items[std::size_t(a)], &cb = cells.items[std::size_t(b)];
        const unsigned diff = unsigned(ca.corner ^ cb.corner);
        if (std::popcount(diff) != 1 || group[std::size_t(b)] <= group[std::size_t(a)]) continue;
        const int axis = std::countr_zero(diff);
        const std::uint32_t lower = corner_bit(ca.corner, axis) ? ca.cell : cb.cell;
        if (opened[lower] & (1u << (2 * axis + 1))) continue;
        group[std::size_t(b)] = group[std::size_t(a)];
        changed = true;
      }
  }
  for (int g = 1; g < cells.count; ++g) {
    // The cells of group g, found again among the node's cells left after earlier moves.
    const NodeCells now = cells_of_node(w, node);
    unsigned mask = 0;
    for (int i = 0; i < now.count; ++i)
      for (int k = 0; k < cells.count; ++k)
        if (group[std::size_t(k)] == g && cells.items[std::size_t(k)].cell == now.items[std::size_t(i)].cell)
          mask |= 1u << i;
    if (mask != 0) separate_node(w, NodeId(node), mask);
  }
}

// Opens the marked faces: regroups every node at a vertex of an opened face, in ascending
// vertex order and, at a vertex, ascending node order.
void open_faces(World& w, const std::vector<std::uint8_t>& opened) {
  const LatticeDims& d = w.topo.dims;
  std::vector<std::uint32_t> vertices;
  for (std::uint32_t c = 0; c < opened.size(); ++c)
    for (int axis = 0; axis < 2; ++axis) {
      const int face = 2 * axis + 1;
      if (!(opened[c] & (1u << face))) continue;
      const auto ijk = d.cell_ijk(c);
      for (int q : face_corners(face))
        vertices.push_back(d.corner_vertex(ijk, q));
    }
  std::sort(vertices.begin(), vertices.end());
  vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
  for (std::uint32_t v : vertices) {
    const auto [vi, vj, vk] = d.vertex_ijk(v);
    std::vector<std::uint32_t> nodes;
    for (int q = 0; q < kCornersPerCell; ++q) {
      const int i = vi - corner_bit(q, 0), j = vj - corner_bit(q, 1), k = vk - corner_bit(q, 2);
      if (i < 0 || j < 0 || k < 0 || i >= d.nx || j >= d.ny || k >= d.nl) continue;
      nodes.push_back(w.topo.node(d.cell_index(i, j, k), q));
    }
    std::sort(nodes.begin(), nodes.end());
    nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
    for (std::uint32_t n : nodes) regroup_node(w, n, opened);
  }
}

}  // namespace

std::vector<BondCrossing> line_crossings(std::span<const std::array<double, 2>> points, int nx, int ny) {
  std::vector<BondCrossing> out;
  double arc = 0.0;
  for (std::size_t s = 0; s + 1 < points.size(); ++s) {
    const Point &p = points[s], &q = points[s + 1];
    if (p == q) continue;  // no direction: it crosses nothing
    for (int axis = 0; axis < 2; ++axis) segment_crossings(p, q, arc, axis, nx, ny, out);
    arc += std::hypot(q[0] - p[0], q[1] - p[1]);
  }
  std::stable_sort(out.begin(), out.end(), [](const BondCrossing& a, const BondCrossing& b) {
    if (a.arc != b.arc) return a.arc < b.arc;
    if (a.axis != b.axis) return a.axis < b.axis;
    return a.j != b.j ? a.j < b.j : a.i < b.i;
  });
  return out;
}

void apply_lines(World& w) {
  if (w.scene.lines.empty()) return;
  std::vector<std::uint8_t> opened(std::size_t(w.topo.dims.cells()), 0);
  for (const LineParams& line : w.scene.lines) apply_line(w, line, opened);
  open_faces(w, opened);
}

}  // namespace papertear
