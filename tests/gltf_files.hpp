// Reading .glb files back in tests: the whole model, and a FLOAT accessor's values.
#pragma once
#include <catch2/catch.hpp>

#include <tiny_gltf.h>

#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

namespace papertear::testing {

inline tinygltf::Model load_glb(const std::filesystem::path& file) {
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  INFO(file.string());
  REQUIRE(loader.LoadBinaryFromFile(&model, &err, &warn, file.string()));
  return model;
}

// The values of a tightly packed FLOAT accessor (what papertear writes).
inline std::vector<float> read_floats(const tinygltf::Model& m, int accessor_index) {
  const tinygltf::Accessor& a = m.accessors[std::size_t(accessor_index)];
  REQUIRE(a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT);
  const tinygltf::BufferView& v = m.bufferViews[std::size_t(a.bufferView)];
  const std::size_t n = a.count * std::size_t(tinygltf::GetNumComponentsInType(std::uint32_t(a.type)));
  std::vector<float> out(n);
  std::memcpy(out.data(), m.buffers[std::size_t(v.buffer)].data.data() + v.byteOffset + a.byteOffset, n * sizeof(float));
  return out;
}

}  // namespace papertear::testing
