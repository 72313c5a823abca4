// Embeds papertear through its installed package: builds a small sheet, steps it twice from
// the same scene (and on different thread counts) and checks the digests agree. Exit status
// 0 means the installed headers, library and CMake package work together.
#include <cstdint>
#include <cstdio>
#include <exception>

#include <core/simulation.hpp>

namespace {

constexpr int kSteps = 40;

papertear::Scene small_scene() {
  papertear::Scene scene;
  scene.sheet.cells = {10, 10, 2};
  scene.load.kind = "pull";
  return scene;
}

std::uint64_t run(const papertear::Scene& scene, int threads, std::uint64_t* initial) {
  papertear::Simulation sim(scene, {.threads = threads});
  if (initial) *initial = sim.digest();
  sim.step(kSteps);
  return sim.digest();
}

int check() {
  const papertear::Scene scene = small_scene();
  std::uint64_t initial = 0;
  const std::uint64_t first = run(scene, 1, &initial);
  const std::uint64_t second = run(scene, 1, nullptr);
  const std::uint64_t threaded = run(scene, 2, nullptr);
  std::printf("digest before: %016llx\n", static_cast<unsigned long long>(initial));
  std::printf("digest after %d steps: %016llx (1 thread), %016llx (again), %016llx (2 threads)\n",
              kSteps, static_cast<unsigned long long>(first), static_cast<unsigned long long>(second),
              static_cast<unsigned long long>(threaded));
  if (first == initial) {
    std::fprintf(stderr, "FAIL: the state did not change over %d steps\n", kSteps);
    return 1;
  }
  if (first != second || first != threaded) {
    std::fprintf(stderr, "FAIL: identical runs gave different digests\n");
    return 1;
  }
  std::printf("OK\n");
  return 0;
}

}  // namespace

int main() {
  try {
    return check();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "FAIL: %s\n", e.what());
    return 1;
  }
}
