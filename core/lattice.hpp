// The lattice: nx × ny × nl box cells (MODEL.md §2) and the fixed numbering every module
// shares.
//
//   corner q of a cell = dx | dy << 1 | dz << 2       (dx, dy, dz ∈ {0, 1})
//   face f of a cell   = 2 * axis + side             (side 0: low face, 1: high face)
//   vertex (I, J, K)   = I + (nx+1) * (J + (ny+1) * K)
//   cell (i, j, k)     = i + nx * (j + ny * k)        (k = layer, 0 at the bottom)
//
// Each cell owns 28 springs between its corners (MODEL.md §4): 12 edges, 12 face diagonals
// and 4 body diagonals. The table below names them once; kernels, fracture and the
// reference model all read it.
#pragma once
#include <array>
#include <cstdint>

namespace papertear {

enum class SpringFamily : std::uint8_t { Edge = 0, Face = 1, Body = 2 };

struct SpringSlot {
  std::uint8_t a, b;      // corners, a < b
  SpringFamily family;
  std::uint8_t axis;      // Edge: the axis it runs along; Face: the face's normal axis; Body: 3
};

inline constexpr int kCornersPerCell = 8;
inline constexpr int kSpringsPerCell = 28;
inline constexpr int kEdgesPerCell = 12;  // slots 0..11 are the edges
inline constexpr int kFacesPerCell = 6;

inline constexpr std::array<SpringSlot, kSpringsPerCell> kSpringSlots = {{
    // edges along x (axis 0)
    {0, 1, SpringFamily::Edge, 0}, {2, 3, SpringFamily::Edge, 0},
    {4, 5, SpringFamily::Edge, 0}, {6, 7, SpringFamily::Edge, 0},
    // edges along y (axis 1)
    {0, 2, SpringFamily::Edge, 1}, {1, 3, SpringFamily::Edge, 1},
    {4, 6, SpringFamily::Edge, 1}, {5, 7, SpringFamily::Edge, 1},
    // edges along z (axis 2)
    {0, 4, SpringFamily::Edge, 2}, {1, 5, SpringFamily::Edge, 2},
    {2, 6, SpringFamily::Edge, 2}, {3, 7, SpringFamily::Edge, 2},
    // face diagonals on faces normal to z (bottom, top)
    {0, 3, SpringFamily::Face, 2}, {1, 2, SpringFamily::Face, 2},
    {4, 7, SpringFamily::Face, 2}, {5, 6, SpringFamily::Face, 2},
    // face diagonals on faces normal to y
    {0, 5, SpringFamily::Face, 1}, {1, 4, SpringFamily::Face, 1},
    {2, 7, SpringFamily::Face, 1}, {3, 6, SpringFamily::Face, 1},
    // face diagonals on faces normal to x
    {0, 6, SpringFamily::Face, 0}, {2, 4, SpringFamily::Face, 0},
    {1, 7, SpringFamily::Face, 0}, {3, 5, SpringFamily::Face, 0},
    // body diagonals
    {0, 7, SpringFamily::Body, 3}, {1, 6, SpringFamily::Body, 3},
    {2, 5, SpringFamily::Body, 3}, {3, 4, SpringFamily::Body, 3},
}};

constexpr int corner_bit(int corner, int axis) { return (corner >> axis) & 1; }
constexpr int corner_of(int dx, int dy, int dz) { return dx | (dy << 1) | (dz << 2); }
// The four corners on face f = 2*axis + side.
constexpr std::array<int, 4> face_corners(int face) {
  std::array<int, 4> out{};
  int axis = face >> 1, side = face & 1, n = 0;
  for (int q = 0; q < kCornersPerCell; ++q)
    if (corner_bit(q, axis) == side) out[static_cast<std::size_t>(n++)] = q;
  return out;
}

struct LatticeDims {
  int nx = 0, ny = 0, nl = 0;           // cells along x, y and through the thickness
  double hx = 1.0, hy = 1.0, hz = 1.0;  // cell size

  std::int64_t cells() const { return std::int64_t(nx) * ny * nl; }
  std::int64_t vertices() const { return std::int64_t(nx + 1) * (ny + 1) * (nl + 1); }
  std::uint32_t cell_index(int i, int j, int k) const {
    return std::uint32_t(i + nx * (j + ny * k));
  }
  std::uint32_t vertex_index(int i, int j, int k) const {
    return std::uint32_t(i + (nx + 1) * (j + (ny + 1) * k));
  }
  std::array<int, 3> cell_ijk(std::uint32_t c) const {
    int i = int(c % std::uint32_t(nx));
    int j = int((c / std::uint32_t(nx)) % std::uint32_t(ny));
    int k = int(c / (std::uint32_t(nx) * std::uint32_t(ny)));
    return {i, j, k};
  }
  // The lattice vertex at corner q of the cell at ijk (corner numbering above).
  std::uint32_t corner_vertex(const std::array<int, 3>& ijk, int q) const {
    return vertex_index(ijk[0] + corner_bit(q, 0), ijk[1] + corner_bit(q, 1), ijk[2] + corner_bit(q, 2));
  }
  std::uint32_t corner_vertex(std::uint32_t c, int q) const { return corner_vertex(cell_ijk(c), q); }
  std::array<int, 3> vertex_ijk(std::uint32_t v) const {
    std::uint32_t sx = std::uint32_t(nx + 1), sy = std::uint32_t(ny + 1);
    return {int(v % sx), int((v / sx) % sy), int(v / (sx * sy))};
  }
  // Rest position of a lattice vertex (the sheet's lower corner at the origin).
  std::array<double, 3> vertex_position(int i, int j, int k) const {
    return {i * hx, j * hy, k * hz};
  }
  // The cell across face f of cell (i, j, k), or -1 outside the lattice.
  std::int64_t neighbour(int i, int j, int k, int face) const {
    int ijk[3] = {i, j, k};
    int axis = face >> 1;
    ijk[axis] += (face & 1) ? 1 : -1;
    int lim[3] = {nx, ny, nl};
    if (ijk[axis] < 0 || ijk[axis] >= lim[axis]) return -1;
    return cell_index(ijk[0], ijk[1], ijk[2]);
  }
  // Colour (i%2, j%2, k%2): cells of one colour never share a lattice vertex, so a kernel
  // may scatter into their corner nodes in parallel without conflicts.
  static int colour(int i, int j, int k) { return (i & 1) | ((j & 1) << 1) | ((k & 1) << 2); }
};

}  // namespace papertear
