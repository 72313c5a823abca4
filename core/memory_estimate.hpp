// What a sheet costs in memory, before it is built (scene validation, `papertear info`).
#pragma once
#include <cstdint>

#include "core/scene.hpp"

namespace papertear {

// Bytes of state for an intact sheet: node columns and RK4 scratch (26 floats/ids per node),
// the cell table and per-cell data (8 ids + 9 floats + 1 id), and block-lattice springs
// (at most 28 per block of two or more cells, 30 bytes each; bounded by 28 per cell / 2).
inline std::uint64_t estimate_memory_bytes(const SheetParams& s) {
  const std::uint64_t cells = std::uint64_t(s.cells[0]) * std::uint64_t(s.cells[1]) * std::uint64_t(s.cells[2]);
  const std::uint64_t nodes = std::uint64_t(s.cells[0] + 1) * std::uint64_t(s.cells[1] + 1) * std::uint64_t(s.cells[2] + 1);
  return nodes * 26u * 4u + cells * (8u * 4u + 9u * 4u + 4u) + cells * 14u * 30u;
}

}  // namespace papertear
