#include "core/simulation.hpp"

#include <oneapi/tbb/info.h>

#include "core/digest.hpp"
#include "core/lattice_builder.hpp"
#include "core/solver.hpp"
#include "core/timestep.hpp"
#include "fracture/blocks.hpp"
#include "fracture/fracture_pass.hpp"
#include "fracture/lines.hpp"
#include "fracture/notch.hpp"
#include "kernels/energy.hpp"
#include "kernels/parallel.hpp"

namespace papertear {

struct Simulation::Impl {
  World world;
  SolverScratch solver;
  FractureScratch fracture;
  std::unique_ptr<tbb::task_arena> own_arena;
  tbb::task_arena* arena = nullptr;

  Impl(World w, SimulationOptions opt) : world(std::move(w)) {
    if (opt.threads < 0 || opt.threads > limits::kMaxThreads)
      throw SceneError("threads: must be 0 (all hardware threads) to " + std::to_string(limits::kMaxThreads) +
                       " (got " + std::to_string(opt.threads) + ")");
    if (opt.arena) {
      arena = opt.arena;
    } else {
      const int threads = opt.threads > 0 ? opt.threads : tbb::info::default_concurrency();
      own_arena = std::make_unique<tbb::task_arena>(threads);
      arena = own_arena.get();
    }
  }
};

namespace {

World build_world(const Scene& scene) {
  validate(scene);
  World w;
  build_lattice(scene, w);
  lay_fibre_blocks(w);
  cut_notch(w);
  apply_lines(w);
  w.dt = choose_dt(w);
  return w;
}

}  // namespace

Simulation::Simulation(const Scene& scene, SimulationOptions options)
    : impl_(std::make_unique<Impl>(build_world(scene), options)) {}

Simulation::Simulation(World world, SimulationOptions options)
    : impl_(std::make_unique<Impl>(std::move(world), options)) {
  if (!(impl_->world.dt > 0.0)) impl_->world.dt = choose_dt(impl_->world);
  reset_stage_state(impl_->world);
}

Simulation::~Simulation() = default;
Simulation::Simulation(Simulation&&) noexcept = default;
Simulation& Simulation::operator=(Simulation&&) noexcept = default;

void Simulation::step(int n) {
  Impl& s = *impl_;
  s.arena->execute([&] {
    for (int i = 0; i < n; ++i) {
      integrate_step(s.world, s.solver);
      fracture_pass(s.world, s.fracture);
      ++s.world.step;
    }
  });
}

std::int64_t Simulation::steps_done() const { return impl_->world.step; }
double Simulation::time() const { return impl_->world.time; }
double Simulation::dt() const { return impl_->world.dt; }
const Scene& Simulation::scene() const { return impl_->world.scene; }
const World& Simulation::world() const { return impl_->world; }

NodeView Simulation::nodes() const {
  const NodeStore& n = impl_->world.nodes;
  const std::size_t c = n.count;
  return {c, {n.px.data(), c}, {n.py.data(), c}, {n.pz.data(), c}, {n.vx.data(), c},
          {n.vy.data(), c}, {n.vz.data(), c}, {n.mass.data(), c}, {n.vertex.data(), c}};
}

TopologyView Simulation::topology() const {
  return {impl_->world.topo.dims, impl_->world.topo.cell_nodes.span()};
}

std::uint64_t Simulation::digest() const { return state_digest(impl_->world); }

Energies Simulation::energies() const {
  const World& w = impl_->world;
  Energies e;
  impl_->arena->execute([&] {
    e.kinetic = deterministic_sum<double>(w.nodes.count, kNodeChunk, [&](std::size_t b, std::size_t en) {
      return kinetic_energy(b, en, w.nodes);
    });
    e.elastic = deterministic_sum<double>(std::size_t(w.topo.dims.cells()), kCellChunk,
                                          [&](std::size_t b, std::size_t en) { return cell_elastic_energy(b, en, w); });
    e.elastic += coarse_elastic_energy(0, w.coarse.size(), w);
  });
  return e;
}

double Simulation::stable_dt_limit(const Scene& scene) {
  validate(scene);
  World w;
  build_lattice(scene, w);
  lay_fibre_blocks(w);
  return papertear::stable_dt_limit(w);
}

}  // namespace papertear
