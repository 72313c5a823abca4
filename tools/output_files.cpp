#include "tools/output_files.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <vector>

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

// Unlinks the temporary file unless the rename went through.
struct TempFile {
  std::string path;
  int fd = -1;
  bool keep = false;
  ~TempFile() {
    if (fd >= 0) ::close(fd);
    if (!keep && !path.empty()) ::unlink(path.c_str());
  }
};

void write_all(int fd, std::string_view content, const fs::path& path) {
  while (!content.empty()) {
    ssize_t n = ::write(fd, content.data(), content.size());
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) fail(path, "cannot write (" + errno_text(errno) + ")");
    content.remove_prefix(static_cast<std::size_t>(n));
  }
}

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

void create_output_dir(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) fail(dir, "cannot create directory (" + ec.message() + ")");
}

void write_file_atomically(const fs::path& path, std::string_view content) {
  fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
  std::string temp_name = path.filename().string();
  temp_name.insert(temp_name.begin(), '.');  // hidden, so listings never show a half file
  temp_name += ".tmp-XXXXXX";
  std::string pattern = (dir / temp_name).string();
  std::vector<char> name(pattern.begin(), pattern.end());
  name.push_back('\0');
  TempFile tmp;
  tmp.fd = ::mkstemp(name.data());
  if (tmp.fd < 0) fail(path, "cannot create a temporary file (" + errno_text(errno) + ")");
  tmp.path = name.data();
  write_all(tmp.fd, content, path);
  // mkstemp makes the file 0600; outputs are ordinary files readable like any other.
  (void)::fchmod(tmp.fd, 0644);
  if (::fsync(tmp.fd) != 0) fail(path, "cannot flush (" + errno_text(errno) + ")");
  if (::close(tmp.fd) != 0) {
    tmp.fd = -1;
    fail(path, "cannot close (" + errno_text(errno) + ")");
  }
  tmp.fd = -1;
  if (::rename(tmp.path.c_str(), path.c_str()) != 0)
    fail(path, "cannot rename the temporary file into place (" + errno_text(errno) + ")");
  tmp.keep = true;
}

}  // namespace papertear::io
