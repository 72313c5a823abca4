#include "core/digest.hpp"

#include <cstring>

namespace papertear {
namespace {

// FNV-1a over 32-bit words, then a final avalanche (splitmix64's finaliser) so that nearby
// states give unrelated digests. Serial and in index order: it must not depend on threads.
struct Hasher {
  std::uint64_t h = 0xcbf29ce484222325ull;
  void word(std::uint32_t w) { h = (h ^ w) * 0x100000001b3ull; }
  void floats(const float* p, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) {
      std::uint32_t w;
      std::memcpy(&w, p + i, sizeof w);
      word(w);
    }
  }
  void ids(const std::uint32_t* p, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) word(p[i]);
  }
  std::uint64_t finish() const {
    std::uint64_t z = h;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
};

}  // namespace

std::uint64_t state_digest(const World& w) {
  Hasher h;
  const std::size_t n = w.nodes.count;
  h.word(std::uint32_t(n));
  h.word(std::uint32_t(w.topo.cell_nodes.size()));
  for (const AlignedArray<float>* col : {&w.nodes.px, &w.nodes.py, &w.nodes.pz, &w.nodes.vx, &w.nodes.vy, &w.nodes.vz})
    h.floats(col->data(), n);
  h.ids(w.topo.cell_nodes.data(), w.topo.cell_nodes.size());
  return h.finish();
}

}  // namespace papertear
