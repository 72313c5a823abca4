// A bound the float-tolerance tests share: max over nodes of Σ_s k_s L0_s / m, the scale of a
// node's acceleration per unit of relative error in its spring forces.
#pragma once
#include <algorithm>
#include <vector>

#include "kernels/reference.hpp"

namespace papertear::testing {

inline double max_spring_scale(const ReferenceModel& ref) {
  std::vector<double> kl(ref.nodes().size(), 0.0);
  for (const auto& s : ref.springs()) {
    kl[s.a] += s.k * s.rest;
    kl[s.b] += s.k * s.rest;
  }
  double worst = 0.0;
  for (std::size_t i = 0; i < kl.size(); ++i) worst = std::max(worst, kl[i] / ref.nodes()[i].mass);
  return worst;
}

}  // namespace papertear::testing
