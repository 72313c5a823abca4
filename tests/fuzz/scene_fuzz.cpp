// libFuzzer target for the scene parser (tools/scene_file.hpp). Whatever the text, parsing
// must either give a scene that passes validate() or throw SceneError (syntax errors, unknown
// keys, wrong types, impossible values all become SceneError): no crash, no other exception.
// Scenes the parser accepts must also print back (scene_to_toml) to a scene it accepts.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string_view>

#include "core/scene.hpp"
#include "tools/scene_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const papertear::io::SceneFile file = papertear::io::parse_scene(text, "fuzz");
    std::ostringstream again;
    again << papertear::io::scene_to_toml(file.scene);
    papertear::io::parse_scene(again.str(), "fuzz-again");
  } catch (const papertear::SceneError&) {
    // refused with a message: the expected outcome for most inputs
  }
  return 0;
}
