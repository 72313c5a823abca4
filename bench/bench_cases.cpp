#include "bench_cases.hpp"

#include <bit>
#include <map>

#include "core/simulation.hpp"
#include "core/world.hpp"
#include "fracture/metrics.hpp"
#include "kernels/cell_forces.hpp"
#include "kernels/coarse_forces.hpp"
#include "kernels/fine_springs.hpp"

namespace papertear::bench {

std::vector<Case> papertear_cases() {
  std::vector<Case> cases;
  for (Size size : {Size{30, 30, 5}, Size{90, 90, 5}, Size{300, 300, 5}, Size{1000, 1000, 5}})
    for (int threads : {1, 2}) cases.push_back({size, threads});
  return cases;
}

std::string case_name(const char* family, const char* impl, const Case& c) {
  return std::string(family) + "/" + impl + "/" + std::to_string(c.size.nx) + "x" +
         std::to_string(c.size.ny) + "x" + std::to_string(c.size.nl) + "/threads:" +
         std::to_string(c.threads);
}

std::string default_scene_size() {
  const auto& cells = Scene{}.sheet.cells;
  return std::to_string(cells[0]) + "x" + std::to_string(cells[1]) + "x" + std::to_string(cells[2]);
}

const World& default_scene_at(int step) {
  static std::map<int, World> worlds;  // std::map: references stay valid as it grows
  auto it = worlds.find(step);
  if (it == worlds.end()) {
    Simulation sim(Scene{}, {.threads = 2});
    sim.step(step);
    it = worlds.emplace(step, sim.world()).first;
  }
  return it->second;
}

const World& torn_render_sheet() {
  static const World world = [] {
    Scene scene;
    scene.load.speed *= 4.0;
    Simulation sim(scene);
    for (int i = 0; i < 3000 && measure(sim.world()).pieces < 2; i += 50) sim.step(50);
    sim.step(50);
    return sim.world();
  }();
  return world;
}

Scene quiet_pull_scene(const Size& size) {
  Scene scene;
  scene.sheet.cells = {size.nx, size.ny, size.nl};
  scene.load.kind = "pull";
  // Far below the strain at which the weakest bond opens over any benchmark's duration.
  scene.load.speed = 1e-4;
  return scene;
}

SolverFootprint solver_footprint(const World& w) {
  const double nodes = double(w.nodes.count);
  const double node_bytes = nodes * (9 * 4 + 4 + 1) + nodes * 15 * 4;  // NodeStore + IntegratorScratch
  const double cell_bytes = double(w.topo.cell_nodes.size()) * 4 + double(w.topo.cell_scale.size()) * 4 +
                            double(w.topo.cell_block.size()) * 4 + double(w.topo.face_strain.size()) * 4;
  const double coarse_bytes = double(w.coarse.size()) * (4 * 2 + 1 * 2 + 4 * 3 + 4);
  // The solver's derived tables, built here as the solver builds them.
  FineSprings fine;
  build_fine_springs(w.topo, w.springs, fine);
  double fine_bytes = double(fine.count.size()) + double(fine.shared_counts.size()) +
                      double(fine.owned.size()) * 4 + double(fine.copies.size()) +
                      double(fine.rows.size() * (sizeof(FineRow) + sizeof(fine.dirty[0])));
  for (const auto& groups : fine.dirty) fine_bytes += double(groups.size() * sizeof(DirtyGroup));
  BlockLattice lattice;
  build_block_lattice(w.coarse, w.blocks, w.topo.dims, lattice);
  const double lattice_bytes =
      double(lattice.block.size() + lattice.corner_slot.size() + lattice.corner_node.size() + lattice.first.size() +
             lattice.entry.size() + lattice.entry_node.size() + lattice.pack_node.size()) * 4 +
      double(lattice.pack_rows.size() + lattice.corner_row.size()) * 2 +
      double(lattice.live.size() + lattice.rest.size() + lattice.stiffness.size() + lattice.damping.size() +
             lattice.fx.size() + lattice.fy.size() + lattice.fz.size()) * 4;
  const double cells = double(w.topo.dims.cells());
  SolverFootprint f;
  f.bytes_per_cell =
      cells > 0 ? (node_bytes + cell_bytes + coarse_bytes + fine_bytes + lattice_bytes) / cells : 0.0;
  // Distinct fine springs (one bit per owned slot; the flag bits are not slots) and block springs.
  for (std::size_t c = 0; c < fine.cells; ++c) f.evaluated_springs += double(std::popcount(fine.owned[c] & kAllSlots));
  f.evaluated_springs += double(w.coarse.size());
  return f;
}

void set_throughput_counters(benchmark::State& state, const Size& size, double springs_per_iteration,
                             double total_seconds, const char* per_cell_counter) {
  using benchmark::Counter;
  state.counters["springs_per_s"] = Counter(springs_per_iteration, Counter::kIsIterationInvariantRate);
  const double cell_iterations = double(size.cells()) * double(state.iterations());
  state.counters[per_cell_counter] = cell_iterations > 0 ? total_seconds * 1e9 / cell_iterations : 0.0;
}

}  // namespace papertear::bench
