#include "tools/output_files.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

#include "core/atomic_file.hpp"

namespace papertear::io {
namespace fs = std::filesystem;
namespace {

[[noreturn]] void fail(const fs::path& path, const std::string& problem) {
  throw OutputError(path.string() + ": " + problem);
}

std::string errno_text(int err) { return std::strerror(err); }

// The closest ancestor of `dir` that exists ("." for a relative path with none).
fs::path existing_ancestor(const fs::path& dir) {
  fs::path p = dir;
  std::error_code ec;
  while (!p.empty() && !fs::exists(p, ec)) p = p.parent_path();
  return p.empty() ? fs::path(".") : p;
}

bool writable_dir(const fs::path& p) { return ::access(p.c_str(), W_OK | X_OK) == 0; }

}  // namespace

void check_output_dir(const fs::path& dir) {
  std::error_code ec;
  if (dir.empty()) throw OutputError("the output directory name is empty");
  if (fs::exists(dir, ec)) {
    if (!fs::is_directory(dir, ec)) fail(dir, "exists and is not a directory");
    if (!writable_dir(dir)) fail(dir, "directory is not writable (" + errno_text(errno) + ")");
    return;
  }
  fs::path ancestor = existing_ancestor(dir);
  if (!fs::is_directory(ancestor, ec))
    fail(dir, "cannot create it: '" + ancestor.string() + "' is not a directory");
  if (!writable_dir(ancestor))
    fail(dir, "cannot create it in '" + ancestor.string() + "' (" + errno_text(errno) + ")");
}

void check_output_names(const fs::path& dir, std::initializer_list<const char*> files,
                        std::initializer_list<const char*> dirs) {
  std::error_code ec;
  for (const char* name : files) {
    const fs::file_status st = fs::symlink_status(dir / name, ec);
    if (fs::exists(st) && !fs::is_regular_file(st))
      fail(dir / name, "is in the way: the run writes a file of that name, and this is not a regular file");
  }
  for (const char* name : dirs) {
    const fs::file_status st = fs::status(dir / name, ec);
    if (fs::exists(st) && !fs::is_directory(st))
      fail(dir / name, "is in the way: the run writes a directory of that name, and this is not one");
  }
}

void create_output_dir(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) fail(dir, "cannot create directory (" + ec.message() + ")");
}

void write_file_atomically(const fs::path& path, std::string_view content) {
  try {
    papertear::write_file_atomically(path, content);
  } catch (const FileWriteError& e) {
    throw OutputError(e.what());
  }
}

}  // namespace papertear::io
