// Two builds of the library in one process, timed side by side: the step of build A, then of
// build B, alternated in blocks of steps, and the median of the blocks' ratios B / A. On a
// shared host whose speed drifts by 1.5-2x within minutes (bench/README.md, round 9), runs of
// two binaries minutes apart cannot resolve a change of 10 %; pairs of blocks a few hundred
// milliseconds apart can.
//
//   step_ab A.so B.so [nx [threads [torn [blocks [steps]]]]]
//     defaults: 90 (a 90 x 90 x 5 sheet), 2 threads, 0 (the quiet pulled sheet; 1: the default
//     scene after it has torn), 12 blocks, 40 steps per block (the first steps of a block run
//     on caches the other build has just used).
#include <dlfcn.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <vector>

namespace {

struct Build {
  void* (*make)(int, int, int, int, int);
  double (*step_ms)(void*, int);
  void (*free)(void*);
};

Build load(const char* path) {
  void* lib = dlopen(path, RTLD_NOW | RTLD_LOCAL | RTLD_DEEPBIND);
  if (lib == nullptr) {
    std::fprintf(stderr, "step_ab: %s\n", dlerror());
    std::exit(1);
  }
  Build b{reinterpret_cast<void* (*)(int, int, int, int, int)>(dlsym(lib, "ab_make")),
          reinterpret_cast<double (*)(void*, int)>(dlsym(lib, "ab_step_ms")),
          reinterpret_cast<void (*)(void*)>(dlsym(lib, "ab_free"))};
  if (b.make == nullptr || b.step_ms == nullptr || b.free == nullptr) {
    std::fprintf(stderr, "step_ab: %s lacks the ab_* functions of bench/ab/step_library.cpp\n", path);
    std::exit(1);
  }
  return b;
}

double at(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[std::size_t(q * double(v.size() - 1) + 0.5)];
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: step_ab A.so B.so [nx [threads [torn [blocks [steps]]]]]\n");
    return 2;
  }
  const Build a = load(argv[1]), b = load(argv[2]);
  const int nx = argc > 3 ? std::atoi(argv[3]) : 90, threads = argc > 4 ? std::atoi(argv[4]) : 2;
  const int torn = argc > 5 ? std::atoi(argv[5]) : 0, blocks = argc > 6 ? std::atoi(argv[6]) : 12;
  const int steps = argc > 7 ? std::atoi(argv[7]) : 40;
  void* sa = a.make(nx, nx, 5, threads, torn);
  void* sb = b.make(nx, nx, 5, threads, torn);
  std::vector<double> ta, tb, ratio;
  for (int i = 0; i < blocks; ++i) {
    ta.push_back(a.step_ms(sa, steps));
    tb.push_back(b.step_ms(sb, steps));
    ratio.push_back(tb.back() / ta.back());
  }
  if (torn != 0) std::printf("default scene torn (90x90x5)");
  else std::printf("quiet sheet %dx%dx5", nx, nx);
  std::printf(", %d threads: A %.3f ms, B %.3f ms per step (medians of %d blocks of %d steps); B / A %.3f "
              "(quartiles %.3f-%.3f)\n",
              threads, at(ta, 0.5), at(tb, 0.5), blocks, steps, at(ratio, 0.5), at(ratio, 0.25), at(ratio, 0.75));
  a.free(sa);
  b.free(sb);
  return 0;
}
