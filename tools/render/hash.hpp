// Deterministic pseudo-random numbers for display detail (fibre shapes, pixel jitter, the
// built-in print). Every value is a pure function of a key such as (cell, face) or
// (pixel, sample), so the same state draws the same picture on any thread count and in any
// tile order; nothing here keeps state between calls.
#pragma once
#include <cstdint>

namespace papertear::render {

// The SplitMix64 finaliser: a bijective scramble of 64 bits.
constexpr std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

constexpr std::uint64_t hash_key(std::uint64_t a, std::uint64_t b) {
  return mix64(a * 0x9e3779b97f4a7c15ull + mix64(b + 0x632be59bd9b4e019ull));
}
constexpr std::uint64_t hash_key(std::uint64_t a, std::uint64_t b, std::uint64_t c) {
  return hash_key(hash_key(a, b), c);
}

// A stream of uniform numbers in [0, 1) drawn from one key.
class HashStream {
 public:
  explicit constexpr HashStream(std::uint64_t key) : state_(mix64(key ^ 0xd1b54a32d192ed03ull)) {}
  constexpr std::uint64_t next_bits() {
    state_ += 0x9e3779b97f4a7c15ull;
    return mix64(state_);
  }
  // 24 random bits: exactly representable as a float in [0, 1).
  constexpr float uniform() { return float(std::uint32_t(next_bits() >> 40)) * 0x1.0p-24f; }
  constexpr float uniform(float lo, float hi) { return lo + (hi - lo) * uniform(); }
  constexpr int below(int n) { return int(next_bits() % std::uint64_t(n)); }

 private:
  std::uint64_t state_;
};

}  // namespace papertear::render
