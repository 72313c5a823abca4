// `papertear info`: what a scene will cost before running it: sizes, memory, the time step
// and an estimate of the run time from a few timed steps.
#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/elasticity.hpp"
#include "core/input_file.hpp"
#include "core/timestep.hpp"
#include "tools/commands.hpp"
#include "tools/progress.hpp"
#include "tools/render/settings.hpp"
#include "tools/sweep_file.hpp"

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
           bytes_of(t.face_strain) + bytes_of(t.face_damage);
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

// The continuum moduli the springs give against the material's, in MPa (core/elasticity.hpp).
void print_moduli(const World& w) {
  const Moduli target = target_moduli(w.scene.material);
  const SpringFit fit = fit_springs(target, w.topo.dims);
  const char* young[3] = {"E_x", "E_y", "E_z"};
  const char* shear[3] = {"G_yz", "G_xz", "G_xy"};
  std::printf("moduli (MPa):  ");
  for (int a = 0; a < 3; ++a)
    std::printf(" %s %.4g,", young[a], fit.achieved.young[std::size_t(a)] * kMpaPerStressUnit);
  for (int c = 2; c >= 0; --c)
    std::printf("%s %s %.4g%s%s", c == 2 ? "" : ",", shear[c], fit.achieved.shear[std::size_t(c)] * kMpaPerStressUnit,
                fit.shear_limited[std::size_t(c)] ? " (lattice limit; target " : "",
                fit.shear_limited[std::size_t(c)]
                    ? (std::to_string(int(std::lround(target.shear[std::size_t(c)] * kMpaPerStressUnit))) + ")").c_str()
                    : "");
  std::printf("\n");
}

// The stable step of cubes with the same in-plane size: what flat cells are measured against.
double cube_stable_dt(const Scene& s) {
  Scene cubes = s;
  cubes.sheet.cell_size[2] = std::sqrt(s.sheet.cell_size[0] * s.sheet.cell_size[1]);
  return Simulation::stable_dt_limit(cubes);
}

void print_timing(const Scene& s, const Simulation& sim, double stable, int threads,
                  const StepTiming& timing) {
  std::printf("stable dt:      %.6g (cubes of the same in-plane size: %.6g)\n", stable, cube_stable_dt(s));
  const double wave_speed = in_plane_wave_speed(s.material);
  std::printf("wave speed:     %.4g mm/us in-plane (load.speed %.3g is %.2g %% of it)\n", wave_speed, s.load.speed,
              100.0 * std::abs(s.load.speed) / wave_speed);
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

// The bounds every count, size and input file is checked against before a run starts.
void print_limits() {
  std::printf("limits:\n");
  for (const SceneLimit& l : scene_limits()) std::printf("  %-34s %.10g %s\n", l.key, l.bound, l.what);
  std::printf("  %-34s %d pixels\n", "render.width, render.height", render::kMaxImageSide);
  std::printf("  %-34s %d\n", "render.samples", render::kMaxSamples);
  std::printf("  %-34s %d characters of [A-Za-z0-9._-]\n", "output.prefix", render::kMaxPrefixLength);
  std::printf("  %-34s %zu\n", "sweep points (grid x seeds)", io::kMaxSweepPoints);
  for (const InputKind* k : {&kSceneFileKind, &kSweepFileKind, &kCheckpointKind, &kPrintImageKind})
    std::printf("  %-34s %llu MiB (regular files only; %s overrides)\n", k->name,
                static_cast<unsigned long long>(input_cap_bytes(*k) >> 20), kInputCapVariable);
}

}  // namespace

int info_command(const SceneOptions& options) {
  try {
    io::SceneFile file = resolve_scene(options);
    Simulation sim = make_simulation(file, options.threads);
    print_sizes(file, sim);
    print_moduli(sim.world());
    double stable = Simulation::stable_dt_limit(file.scene);
    StepTiming timing = time_steps(sim);
    print_timing(file.scene, sim, stable, resolved_threads(options.threads), timing);
    print_limits();
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
