#include "core/lattice_builder.hpp"

#include <algorithm>
#include <cmath>

#include "core/elasticity.hpp"

namespace papertear {

SpringTable make_spring_table(const MaterialParams& m, const LatticeDims& d) {
  const SpringFit fit = fit_springs(target_moduli(m), d);
  SpringTable t;
  const double h[3] = {d.hx, d.hy, d.hz};
  for (int s = 0; s < kSpringsPerCell; ++s) {
    const SpringSlot& slot = kSpringSlots[std::size_t(s)];
    double len2 = 0.0;
    for (int axis = 0; axis < 3; ++axis)
      if (corner_bit(slot.a, axis) != corner_bit(slot.b, axis)) len2 += h[axis] * h[axis];
    double k = 0.0;
    switch (slot.family) {
      // The block lattice (fracture/blocks.cpp) carries block_stiffness of the edges' share.
      case SpringFamily::Edge: k = fit.edge[slot.axis] * (1.0 - m.block_stiffness); break;
      case SpringFamily::Face: k = fit.face[slot.axis]; break;
      case SpringFamily::Body: k = fit.body; break;
    }
    t.rest[std::size_t(s)] = float(std::sqrt(len2));
    t.stiffness[std::size_t(s)] = float(k);
    t.damping[std::size_t(s)] = float(k * m.damping);
  }
  return t;
}

double stiffest_edge(const SpringTable& t) {
  double k = 0.0;
  for (int s = 0; s < kEdgesPerCell; ++s) k = std::max(k, double(t.stiffness[std::size_t(s)]));
  return k;
}

TearGrips tear_grips(const LoadParams& load, const LatticeDims& dims) {
  const int n_axis = load.axis == 'y' ? dims.ny : dims.nx;
  const int mid = n_axis / 2, g = load.grip_cells, gap = load.grip_margin;
  return {{mid - gap - g, mid - gap}, {mid + gap, mid + gap + g}, g};
}

float grip_ramp(const LoadParams& load, double t) {
  if (load.ramp_time <= 0.0 || t >= load.ramp_time) return 1.0f;
  return float(std::max(0.0, t) / load.ramp_time);
}

double ramped_travel(double speed, double ramp_time, double t) {
  t = std::max(0.0, t);
  if (ramp_time <= 0.0) return speed * t;
  if (t < ramp_time) return speed * t * t / (2.0 * ramp_time);
  return speed * (t - 0.5 * ramp_time);
}

namespace {

void place_nodes(World& w) {
  const LatticeDims& d = w.topo.dims;
  w.nodes.resize(std::size_t(d.vertices()));
  std::uint32_t n = 0;
  for (int k = 0; k <= d.nl; ++k)
    for (int j = 0; j <= d.ny; ++j)
      for (int i = 0; i <= d.nx; ++i, ++n) {
        auto p = d.vertex_position(i, j, k);
        w.nodes.px[n] = float(p[0]);
        w.nodes.py[n] = float(p[1]);
        w.nodes.pz[n] = float(p[2]);
        w.nodes.vx[n] = w.nodes.vy[n] = w.nodes.vz[n] = 0.0f;
        w.nodes.vertex[n] = n;
        w.nodes.grip[n] = 0;
        w.nodes.free_mask[n] = 1.0f;
      }
}

void connect_cells(World& w) {
  Topology& t = w.topo;
  const LatticeDims& d = t.dims;
  t.cell_nodes.resize(std::size_t(d.cells()) * 8);
  for (auto& list : t.colour_cells) list.clear();
  for (int k = 0; k < d.nl; ++k)
    for (int j = 0; j < d.ny; ++j)
      for (int i = 0; i < d.nx; ++i) {
        std::uint32_t c = d.cell_index(i, j, k);
        for (int q = 0; q < 8; ++q)
          t.cell_nodes[std::size_t(c) * 8 + std::size_t(q)] = d.vertex_index(
              i + corner_bit(q, 0), j + corner_bit(q, 1), k + corner_bit(q, 2));
        t.colour_cells[std::size_t(LatticeDims::colour(i, j, k))].push_back(c);
      }
  t.cell_scale.assign(std::size_t(d.cells()), 1.0f);
  t.cell_block.assign(std::size_t(d.cells()), 0u);
  t.face_strain.assign(std::size_t(d.cells()) * kFacesPerCell, INFINITY);
  t.face_damage.assign(std::size_t(d.cells()) * kFacesPerCell, 0.0f);
}

// Puts every node whose lattice vertex `which_grip` assigns to grip g > 0 in that grip.
template <class WhichGrip>
void grip_nodes(World& w, const WhichGrip& which_grip) {
  const LatticeDims& d = w.topo.dims;
  for (std::uint32_t n = 0; n < w.nodes.count; ++n) {
    const int which = which_grip(d.vertex_ijk(w.nodes.vertex[n]));
    if (which == 0) continue;
    w.nodes.grip[n] = std::uint8_t(which);
    w.nodes.free_mask[n] = 0.0f;
    w.gripped_nodes.push_back(n);
  }
}

// Pull: grips hold the first and last `grip_cells` columns of vertices along the load axis,
// over the whole width and thickness, and move them apart along that axis.
void attach_pull_grips(World& w) {
  const LoadParams& l = w.scene.load;
  const LatticeDims& d = w.topo.dims;
  const int axis = l.axis == 'y' ? 1 : 0;
  const int n_axis = axis == 0 ? d.nx : d.ny;
  const int g = std::min(l.grip_cells, n_axis / 2);
  w.grips.assign(2, Grip{});
  w.grips[0].velocity[std::size_t(axis)] = -float(l.speed);
  w.grips[1].velocity[std::size_t(axis)] = float(l.speed);
  grip_nodes(w, [&](const std::array<int, 3>& v) {
    const int a = v[std::size_t(axis)];
    return a <= g ? 1 : (a >= n_axis - g ? 2 : 0);
  });
}

// Pierce: a fixed clamp holds a ring `grip_cells` wide along the whole border, like a
// burst tester's clamping rings; the indenter (core/contact.hpp) does the loading.
void attach_pierce_clamp(World& w) {
  const LatticeDims& d = w.topo.dims;
  const int g = w.scene.load.grip_cells;
  w.grips.assign(1, Grip{});
  grip_nodes(w, [&](const std::array<int, 3>& v) {
    const bool border = v[0] <= g || v[0] >= d.nx - g || v[1] <= g || v[1] >= d.ny - g;
    return border ? 1 : 0;
  });
}

void attach_tear_grips(World& w) {
  const LoadParams& l = w.scene.load;
  const LatticeDims& d = w.topo.dims;
  const int axis = l.axis == 'y' ? 1 : 0;
  const TearGrips t = tear_grips(l, d);
  w.grips.assign(2, Grip{});
  w.grips[0].velocity[std::size_t(axis)] = -float(kTearSpread * l.speed);
  w.grips[0].velocity[2] = float(l.speed);
  w.grips[1].velocity[std::size_t(axis)] = float(kTearSpread * l.speed);
  w.grips[1].velocity[2] = -float(l.speed);
  grip_nodes(w, [&](const std::array<int, 3>& v) {
    const int a = v[std::size_t(axis)], b = v[std::size_t(1 - axis)];
    if (b > t.depth) return 0;
    if (a >= t.left[0] && a <= t.left[1]) return 1;
    if (a >= t.right[0] && a <= t.right[1]) return 2;
    return 0;
  });
}

void attach_grips(World& w) {
  w.grips.clear();
  w.gripped_nodes.clear();
  const std::string& kind = w.scene.load.kind;
  if (kind == "pull") attach_pull_grips(w);
  else if (kind == "pierce") attach_pierce_clamp(w);
  else if (kind == "tear") attach_tear_grips(w);
  // "none": a free sheet
}

}  // namespace

void recompute_masses(World& w) {
  const LatticeDims& d = w.topo.dims;
  const double mass = cell_mass(w.scene.material, d);
  std::vector<double> m(w.nodes.count, 0.0);
  for (std::size_t i = 0; i < w.topo.cell_nodes.size(); ++i) m[w.topo.cell_nodes[i]] += mass / 8.0;
  for (std::size_t n = 0; n < w.nodes.count; ++n) {
    w.nodes.mass[n] = float(m[n]);
    w.nodes.inv_mass[n] = m[n] > 0.0 ? float(1.0 / m[n]) : 0.0f;
  }
}

void build_lattice(const Scene& scene, World& w) {
  w.scene = scene;
  w.topo.dims = LatticeDims{scene.sheet.cells[0], scene.sheet.cells[1], scene.sheet.cells[2],
                            scene.sheet.cell_size[0], scene.sheet.cell_size[1],
                            scene.sheet.cell_size[2]};
  w.springs = make_spring_table(scene.material, w.topo.dims);
  place_nodes(w);
  connect_cells(w);
  recompute_masses(w);
  attach_grips(w);
  reset_stage_state(w);
  w.step = 0;
  w.time = 0.0;
  w.events.clear();
}

void reset_stage_state(World& w) {
  const std::size_t n = w.nodes.count;
  w.scratch.resize(n);
  IntegratorScratch& s = w.scratch;
  std::copy_n(w.nodes.px.data(), n, s.sx.data());
  std::copy_n(w.nodes.py.data(), n, s.sy.data());
  std::copy_n(w.nodes.pz.data(), n, s.sz.data());
  std::copy_n(w.nodes.vx.data(), n, s.svx.data());
  std::copy_n(w.nodes.vy.data(), n, s.svy.data());
  std::copy_n(w.nodes.vz.data(), n, s.svz.data());
  for (auto* f : {&s.fx, &s.fy, &s.fz}) std::fill_n(f->data(), n, 0.0f);
}

void NodeStore::resize(std::size_t n) {
  count = n;
  px.resize(n); py.resize(n); pz.resize(n);
  vx.resize(n); vy.resize(n); vz.resize(n);
  inv_mass.resize(n); free_mask.resize(n, 1.0f); mass.resize(n);
  vertex.resize(n); grip.resize(n);
}

void IntegratorScratch::resize(std::size_t n) {
  for (auto* a : {&sx, &sy, &sz, &svx, &svy, &svz, &ax, &ay, &az, &avx, &avy, &avz, &fx, &fy, &fz})
    a->resize(n, 0.0f);
}

}  // namespace papertear
