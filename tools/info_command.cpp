// `papertear info`: what a scene will cost before running it: sizes, memory, the time step
// and an estimate of the run time from a few timed steps.
#include <sys/resource.h>

#include <chrono>
#include <cstdio>

#include "tools/commands.hpp"
#include "tools/progress.hpp"

namespace papertear::cli {
namespace {

template <class Array>
std::size_t bytes_of(const Array& a) {
  return a.capacity() * sizeof(*a.data());
}

// The bytes held by the world's arrays. The solver's own scratch (per-spring forces, ...)
// is not in World, so this is a lower bound; the peak resident size printed next to it
// includes everything.
std::size_t world_bytes(const World& w) {
  const NodeStore& n = w.nodes;
  const IntegratorScratch& s = w.scratch;
  std::size_t total = 0;
  for (const auto* a : {&n.px, &n.py, &n.pz, &n.vx, &n.vy, &n.vz, &n.inv_mass, &n.free_mask,
                        &n.mass, &s.sx, &s.sy, &s.sz, &s.svx, &s.svy, &s.svz, &s.ax, &s.ay,
                        &s.az, &s.avx, &s.avy, &s.avz, &s.fx, &s.fy, &s.fz})
    total += bytes_of(*a);
  total += bytes_of(n.vertex) + bytes_of(n.grip);
  const Topology& t = w.topo;
  total += bytes_of(t.cell_nodes) + bytes_of(t.cell_scale) + bytes_of(t.cell_block) +
           bytes_of(t.face_strain);
  for (const auto& colour : t.colour_cells) total += bytes_of(colour);
  const CoarseSprings& c = w.coarse;
  total += bytes_of(c.cell_a) + bytes_of(c.cell_b) + bytes_of(c.corner_a) + bytes_of(c.corner_b) +
           bytes_of(c.rest) + bytes_of(c.stiffness) + bytes_of(c.damping) + bytes_of(c.block);
  total += bytes_of(w.blocks) + bytes_of(w.gripped_nodes) + bytes_of(w.events);
  return total;
}

double peak_rss_mib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return double(usage.ru_maxrss) / 1024.0;  // Linux reports KiB
}

struct StepTiming {
  int steps = 0;
  double seconds_per_step = 0.0;
};

// Times the first steps after one warm-up step: at least 3, at most 50, about half a
// second. Early steps tear little, so a tearing run takes somewhat longer than this says.
StepTiming time_steps(Simulation& sim) {
  using Clock = std::chrono::steady_clock;
  sim.step(1);
  StepTiming t;
  auto start = Clock::now();
  double elapsed = 0.0;
  while (t.steps < 3 || (t.steps < 50 && elapsed < 0.5)) {
    sim.step(1);
    ++t.steps;
    elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  }
  t.seconds_per_step = elapsed / t.steps;
  return t;
}

void print_sizes(const io::SceneFile& file, const Simulation& sim) {
  const Scene& s = file.scene;
  const World& w = sim.world();
  const LatticeDims& d = w.topo.dims;
  std::printf("scene:          %s\n", file.path.empty() ? "built-in default" : file.path.c_str());
  std::printf("lattice:        %d x %d x %d cells of %g x %g x %g (material %s, grain %c)\n",
              d.nx, d.ny, d.nl, d.hx, d.hy, d.hz, s.material.preset.c_str(), s.material.grain);
  std::printf("nodes:          %zu\n", w.nodes.count);
  std::printf("springs:        %lld per-cell (%d per cell), %zu block-lattice, %zu blocks\n",
              static_cast<long long>(d.cells() * kSpringsPerCell), kSpringsPerCell,
              w.coarse.size(), w.blocks.size());
  std::printf("memory:         %.1f MiB of state arrays, %.1f MiB peak resident\n",
              double(world_bytes(w)) / (1024.0 * 1024.0), peak_rss_mib());
}

void print_timing(const Scene& s, const Simulation& sim, double stable, int threads,
                  const StepTiming& timing) {
  std::printf("stable dt:      %.6g\n", stable);
  if (s.run.dt == 0.0)
    std::printf("dt used:        %.6g (auto: %g x stable limit)\n", sim.dt(), s.run.dt_safety);
  else
    std::printf("dt used:        %.6g (run.dt)\n", sim.dt());
  std::printf("run:            %d steps in %d frames, simulated time %.6g\n", s.run.steps,
              s.run.frames, s.run.steps * sim.dt());
  std::printf("threads:        %d\n", threads);
  std::printf("step time:      %.3g ms (timed over %d steps)\n", timing.seconds_per_step * 1e3,
              timing.steps);
  std::printf("estimated run:  %s\n",
              io::format_duration(timing.seconds_per_step * s.run.steps).c_str());
}

}  // namespace

int info_command(const SceneOptions& options) {
  try {
    io::SceneFile file = resolve_scene(options);
    Simulation sim = make_simulation(file, options.threads);
    print_sizes(file, sim);
    double stable = Simulation::stable_dt_limit(file.scene);
    StepTiming timing = time_steps(sim);
    print_timing(file.scene, sim, stable, resolved_threads(options.threads), timing);
    return kExitOk;
  } catch (const BlowUpError& e) {
    print_error("the simulation blew up while timing steps (step " + std::to_string(e.step) +
                ", node " + std::to_string(e.node) + "): " + e.what());
    return kExitBlowUp;
  } catch (const std::exception& e) {
    print_error(e.what());
    return kExitBadInput;
  }
}

}  // namespace papertear::cli
