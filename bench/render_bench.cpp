// Rendering: the display mesh (surface extraction with frayed fibres and peeled skins) and
// one ray-traced 1280 × 720 frame at the default settings (4 samples per pixel, soft
// shadows), of the default scene's sheet (<size> = 120x80x3) intact and torn in two:
//   render/surface/<state>/<size>/threads:<t>   build_surface_mesh (a fresh mesh each time)
//   render/surface_kept/<state>/<size>/threads:<t>  the same into one mesh kept across
//                                                iterations, as a frame loop does
//   render/frame/<state>/<size>/threads:<t>     Renderer::draw (mesh + Embree scene + trace)
// The torn sheet is bench::torn_render_sheet() (bench_cases.hpp).
#include <oneapi/tbb/task_arena.h>

#include "bench_cases.hpp"
#include "core/simulation.hpp"
#include "tools/render/render.hpp"

namespace papertear::bench {
namespace {

enum class SheetState { intact, torn };

const World& sheet(SheetState state) {
  if (state == SheetState::torn) return torn_render_sheet();
  static const World intact = [] {
    Simulation sim(Scene{});
    sim.step(10);
    return sim.world();
  }();
  return intact;
}

void render_surface(benchmark::State& state, SheetState s, int threads, bool kept) {
  const World& world = sheet(s);
  tbb::task_arena arena(threads);
  render::Renderer renderer(render::RenderSettings{});
  render::SurfaceMesh mesh;
  std::size_t triangles = 0;
  for (auto _ : state) {
    const double t = timed([&] {
      arena.execute([&] {
        if (kept) {
          render::build_surface_mesh(world, renderer.mesh_options(), mesh);
          triangles = mesh.triangle_count();
        } else {  // built and freed
          triangles = render::build_surface_mesh(world, renderer.mesh_options()).triangle_count();
        }
      });
    });
    state.SetIterationTime(t);
  }
  state.counters["triangles"] = double(triangles);
}

void render_frame(benchmark::State& state, SheetState s, int threads) {
  const World& world = sheet(s);
  tbb::task_arena arena(threads);
  render::Renderer renderer(render::RenderSettings{});
  const render::Camera camera = renderer.camera_for(world);
  for (auto _ : state) {
    const double t = timed([&] { arena.execute([&] { benchmark::DoNotOptimize(renderer.draw(world, camera)); }); });
    state.SetIterationTime(t);
  }
  state.counters["pixels_per_s"] = benchmark::Counter(1280.0 * 720.0, benchmark::Counter::kIsIterationInvariantRate);
}

}  // namespace

void register_render_benchmarks() {
  for (SheetState s : {SheetState::intact, SheetState::torn}) {
    const std::string state = s == SheetState::intact ? "intact" : "torn";
    for (int threads : {1, 2}) {
      const std::string suffix = state + "/" + default_scene_size() + "/threads:" + std::to_string(threads);
      register_timed("render/surface/" + suffix, benchmark::kMillisecond, render_surface, s, threads, false);
      register_timed("render/surface_kept/" + suffix, benchmark::kMillisecond, render_surface, s, threads, true);
      register_timed("render/frame/" + suffix, benchmark::kMillisecond, render_frame, s, threads);
    }
  }
}

}  // namespace papertear::bench
