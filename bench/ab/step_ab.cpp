// Two builds of the library in one process, timed side by side: the step (or one rendered
// frame) of build A, then of build B, alternated in blocks, and the median of the blocks'
// ratios B / A. On a shared host whose speed drifts by 1.5-2x within minutes (bench/README.md,
// round 9), runs of two binaries minutes apart cannot resolve a change of 10 %; pairs of
// blocks a few hundred milliseconds apart can.
//
//   step_ab A.so B.so [nx [threads [torn [blocks [steps]]]]]
//     objects of bench/ab/step_library.cpp; defaults: 90 (a 90 x 90 x 5 sheet), 2 threads, 0
//     (the quiet pulled sheet; 1: the default scene after it has torn), 12 blocks, 40 steps
//     per block (the first steps of a block run on caches the other build has just used).
//   step_ab A.so B.so render [threads [frames]]
//     objects of bench/ab/render_library.cpp; the torn frame of render/frame/torn, one frame
//     per block after one untimed frame each; defaults: 2 threads, 20 frames.
#include <dlfcn.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace {

void* open_build(const char* path) {
  void* lib = dlopen(path, RTLD_NOW | RTLD_LOCAL | RTLD_DEEPBIND);
  if (lib == nullptr) {
    std::fprintf(stderr, "step_ab: %s\n", dlerror());
    std::exit(1);
  }
  return lib;
}

template <class F>
F symbol(void* lib, const char* name, const char* path) {
  void* f = dlsym(lib, name);
  if (f == nullptr) {
    std::fprintf(stderr, "step_ab: %s lacks %s (bench/ab/step_library.cpp, render_library.cpp)\n", path, name);
    std::exit(1);
  }
  return reinterpret_cast<F>(f);
}

struct StepBuild {
  void* (*make)(int, int, int, int, int);
  double (*step_ms)(void*, int);
  void (*free)(void*);
  explicit StepBuild(const char* path) {
    void* lib = open_build(path);
    make = symbol<void* (*)(int, int, int, int, int)>(lib, "ab_make", path);
    step_ms = symbol<double (*)(void*, int)>(lib, "ab_step_ms", path);
    free = symbol<void (*)(void*)>(lib, "ab_free", path);
  }
};

struct FrameBuild {
  void* (*make)(int);
  double (*frame_ms)(void*);
  void (*free)(void*);
  explicit FrameBuild(const char* path) {
    void* lib = open_build(path);
    make = symbol<void* (*)(int)>(lib, "ab_frame_make", path);
    frame_ms = symbol<double (*)(void*)>(lib, "ab_frame_ms", path);
    free = symbol<void (*)(void*)>(lib, "ab_frame_free", path);
  }
};

double at(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[std::size_t(q * double(v.size() - 1) + 0.5)];
}

// Runs a, then b, `blocks` times and prints the medians (per `unit`) and the ratios' median
// and quartiles, finishing the line the caller has begun.
template <class A, class B>
void compare(int blocks, const A& a, const B& b, const char* unit) {
  std::vector<double> ta, tb, ratio;
  for (int i = 0; i < blocks; ++i) {
    ta.push_back(a());
    tb.push_back(b());
    ratio.push_back(tb.back() / ta.back());
  }
  std::printf(": A %.3f ms, B %.3f ms %s (medians of %d blocks); B / A %.3f (quartiles %.3f-%.3f)\n", at(ta, 0.5),
              at(tb, 0.5), unit, blocks, at(ratio, 0.5), at(ratio, 0.25), at(ratio, 0.75));
}

int compare_frames(const char* path_a, const char* path_b, int argc, char** argv) {
  const FrameBuild a(path_a), b(path_b);
  const int threads = argc > 4 ? std::atoi(argv[4]) : 2, frames = argc > 5 ? std::atoi(argv[5]) : 20;
  void* fa = a.make(threads);
  void* fb = b.make(threads);
  a.frame_ms(fa);  // the first frame allocates what the next ones reuse
  b.frame_ms(fb);
  std::printf("torn frame (90x90x5, 1280x720), %d threads", threads);
  compare(frames, [&] { return a.frame_ms(fa); }, [&] { return b.frame_ms(fb); }, "per frame");
  a.free(fa);
  b.free(fb);
  return 0;
}

int compare_steps(const char* path_a, const char* path_b, int argc, char** argv) {
  const StepBuild a(path_a), b(path_b);
  const int nx = argc > 3 ? std::atoi(argv[3]) : 90, threads = argc > 4 ? std::atoi(argv[4]) : 2;
  const int torn = argc > 5 ? std::atoi(argv[5]) : 0, blocks = argc > 6 ? std::atoi(argv[6]) : 12;
  const int steps = argc > 7 ? std::atoi(argv[7]) : 40;
  void* sa = a.make(nx, nx, 5, threads, torn);
  void* sb = b.make(nx, nx, 5, threads, torn);
  if (torn != 0) std::printf("default scene torn (90x90x5)");
  else std::printf("quiet sheet %dx%dx5", nx, nx);
  std::printf(", %d threads, %d steps per block", threads, steps);
  compare(blocks, [&] { return a.step_ms(sa, steps); }, [&] { return b.step_ms(sb, steps); }, "per step");
  a.free(sa);
  b.free(sb);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr,
                 "usage: step_ab A.so B.so [nx [threads [torn [blocks [steps]]]]]\n"
                 "       step_ab A.so B.so render [threads [frames]]\n");
    return 2;
  }
  if (argc > 3 && std::strcmp(argv[3], "render") == 0) return compare_frames(argv[1], argv[2], argc, argv);
  return compare_steps(argv[1], argv[2], argc, argv);
}
