// Writing a file so that no reader ever sees half of it, even after a crash or Ctrl-C: the
// bytes go to a hidden temporary file in the same directory, are flushed to disk, and the
// file is renamed over the target (rename is atomic within a file system). Checkpoints and
// every output of the command-line tool are written this way.
#pragma once
#include <filesystem>
#include <stdexcept>
#include <string_view>

namespace papertear {

// The message is "<path>: <what failed> (<system reason>)".
struct FileWriteError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Writes `bytes` to `path` atomically; the file is readable by all (0644). Throws
// FileWriteError and removes the temporary file when anything fails.
void write_file_atomically(const std::filesystem::path& path, std::string_view bytes);

}  // namespace papertear
