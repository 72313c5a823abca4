// Prints "<scene> <digest> splits=<n>" for the standard scenes (tests/standard_scenes.hpp).
#include <cstdio>

#include "core/simulation.hpp"
#include "tests/standard_scenes.hpp"

int main() {
  for (const auto& s : papertear::standard::scenes()) {
    papertear::Simulation sim(s.scene, {.threads = 2});
    sim.step(s.steps);
    std::printf("%s %016llx splits=%zu\n", s.name, static_cast<unsigned long long>(sim.digest()),
                sim.world().events.size());
  }
  return 0;
}
