// Files for tests that write: a fresh directory per test under the build tree, and reading a
// file back whole.
#pragma once
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace papertear::testing {

// An empty directory build/.../test-output/<topic>/<name>, removed and made anew.
inline std::filesystem::path fresh_test_dir(const std::string& topic, const std::string& name) {
  const std::filesystem::path dir = std::filesystem::path(PAPERTEAR_BINARY_DIR) / "test-output" / topic / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

}  // namespace papertear::testing
