// Typed ids: a NodeId cannot be passed where a CellId is meant. Kernels work on the raw
// uint32_t values (index arithmetic in hot loops); the API and topology edits use the types.
#pragma once
#include <compare>
#include <cstdint>
#include <limits>

namespace papertear {

template <class Tag>
struct Id {
  std::uint32_t value = std::numeric_limits<std::uint32_t>::max();
  constexpr Id() = default;
  constexpr explicit Id(std::uint32_t v) : value(v) {}
  constexpr bool valid() const { return value != std::numeric_limits<std::uint32_t>::max(); }
  constexpr auto operator<=>(const Id&) const = default;
};

using NodeId = Id<struct NodeTag>;
using CellId = Id<struct CellTag>;
using BlockId = Id<struct BlockTag>;
// A fine spring is named by its cell and its slot (0..27) in the cell: id = cell * 28 + slot.
using SpringId = Id<struct SpringTag>;

}  // namespace papertear
