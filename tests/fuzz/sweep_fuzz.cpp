// libFuzzer target for the sweep-file parser (tools/sweep_file.hpp). Whatever the text,
// parse_sweep must either give a sweep whose every point resolves to a valid scene or throw
// SceneError: no crash, no other exception, no allocation beyond the point cap.
// Relative base scenes resolve against the working directory's "fuzz.toml", so a seed may
// name one of tests/fuzz/corpus/scene/ (run from the repository root) or the default.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "core/scene.hpp"
#include "tools/sweep_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const papertear::io::SweepDefinition sweep = papertear::io::parse_sweep(text, "fuzz.toml");
    // Resolving a point parses its overrides as scene values; a few are enough to reach it.
    for (std::size_t i = 0; i < sweep.points.size() && i < 4; ++i)
      papertear::io::resolve_point(sweep, sweep.points[i]);
  } catch (const papertear::SceneError&) {
    // refused with a message: the expected outcome for most inputs
  }
  return 0;
}
