// One build's renderer behind a plain C interface, as step_library.cpp is for the step: built
// into a shared object per build (bench/ab/run.sh with RENDER=1), so that `step_ab … render`
// can load two builds into one process and draw the same frame with each in turn.
#include <chrono>

#include <oneapi/tbb/task_arena.h>

#include "bench/bench_cases.hpp"
#include "tools/render/render.hpp"

namespace {

// The torn sheet of render/frame/torn (bench/render_bench.cpp), drawn at the default
// settings on `threads` threads.
struct Frame {
  const papertear::World& world = papertear::bench::torn_render_sheet();
  papertear::render::Renderer renderer{papertear::render::RenderSettings{}};
  papertear::render::Camera camera = renderer.camera_for(world);
  tbb::task_arena arena;
  explicit Frame(int threads) : arena(threads) {}
};

}  // namespace

extern "C" void* ab_frame_make(int threads) { return new Frame(threads); }

// Wall milliseconds of one frame (surface mesh, Embree scenes, both passes).
extern "C" double ab_frame_ms(void* frame) {
  auto& f = *static_cast<Frame*>(frame);
  const auto start = std::chrono::steady_clock::now();
  f.arena.execute([&] { benchmark::DoNotOptimize(f.renderer.draw(f.world, f.camera)); });
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

extern "C" void ab_frame_free(void* frame) { delete static_cast<Frame*>(frame); }
