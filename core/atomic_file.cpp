#include "core/atomic_file.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace papertear {
namespace {

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& problem) {
  throw FileWriteError(path.string() + ": " + problem + " (" + std::strerror(errno) + ")");
}

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

void write_all(int fd, std::string_view bytes, const std::filesystem::path& path) {
  while (!bytes.empty()) {
    const ssize_t n = ::write(fd, bytes.data(), bytes.size());
    if (n < 0 && errno == EINTR) continue;  // a signal (Ctrl-C) during the write: go on
    if (n < 0) fail(path, "cannot write");
    bytes.remove_prefix(std::size_t(n));
  }
}

}  // namespace

void write_file_atomically(const std::filesystem::path& path, std::string_view bytes) {
  const std::filesystem::path dir = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  // Hidden, so that directory listings never show a half-written file.
  const std::string pattern = (dir / ("." + path.filename().string() + ".tmp-XXXXXX")).string();
  std::vector<char> name(pattern.begin(), pattern.end());
  name.push_back('\0');
  TempFile tmp;
  tmp.fd = ::mkstemp(name.data());
  if (tmp.fd < 0) fail(path, "cannot create a temporary file");
  tmp.path = name.data();
  write_all(tmp.fd, bytes, path);
  (void)::fchmod(tmp.fd, 0644);  // mkstemp makes it 0600; outputs are ordinary files
  if (::fsync(tmp.fd) != 0) fail(path, "cannot flush");
  const int fd = tmp.fd;
  tmp.fd = -1;
  if (::close(fd) != 0) fail(path, "cannot close");
  if (::rename(tmp.path.c_str(), path.c_str()) != 0) fail(path, "cannot rename the temporary file into place");
  tmp.keep = true;
}

}  // namespace papertear
