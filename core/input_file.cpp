#include "core/input_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstdlib>
#include <cstring>
#include <string_view>

namespace papertear {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw InputFileError(path + ": " + what);
}

std::string system_reason() { return std::strerror(errno); }

// What a non-regular file is, for the message.
const char* file_type_name(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

std::string mib_text(std::uint64_t bytes) {
  if (bytes < (std::uint64_t(1) << 20)) return std::to_string(bytes) + " bytes";
  return std::to_string((bytes + (std::uint64_t(1) << 19)) >> 20) + " MiB";
}

void require_regular(const std::string& path, const struct stat& st, const InputKind& kind) {
  if (!S_ISREG(st.st_mode))
    fail(path, std::string("is ") + file_type_name(st.st_mode) + ", not a " + kind.name + " (only regular files are read)");
}

// `size_text`: the file's size, or "larger than ..." when the read found more than it said.
[[noreturn]] void over_cap(const std::string& path, const InputKind& kind, std::uint64_t cap, const std::string& size_text) {
  fail(path, std::string("the ") + kind.name + " is " + size_text + ", over the cap of " + mib_text(cap) + " (set " +
                 kInputCapVariable + " to raise it)");
}

// Closes the descriptor on every way out.
struct Descriptor {
  int fd;
  ~Descriptor() {
    if (fd >= 0) ::close(fd);
  }
};

}  // namespace

std::uint64_t input_cap_bytes(const InputKind& kind) {
  const char* text = std::getenv(kInputCapVariable);
  if (!text || !*text) return kind.cap_bytes;
  std::uint64_t mib = 0;
  const std::string_view s(text);
  auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), mib);
  if (ec != std::errc() || end != s.data() + s.size() || mib == 0 || mib > (std::uint64_t(1) << 24))
    throw InputFileError(std::string(kInputCapVariable) + ": must be a whole number of MiB from 1 to 16777216 (got '" +
                         std::string(s) + "')");
  return mib << 20;
}

std::string read_input_file(const std::string& path, const InputKind& kind) {
  if (path.empty()) throw InputFileError(std::string("the ") + kind.name + " name is empty");
  if (path.find('\0') != std::string::npos) fail(path, "the file name contains a NUL character");
  const std::uint64_t cap = input_cap_bytes(kind);  // a malformed PAPERTEAR_MAX_INPUT_MB fails first
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    if (errno == ENOENT) fail(path, std::string(kind.name) + " not found");
    fail(path, std::string("cannot open the ") + kind.name + " (" + system_reason() + ")");
  }
  require_regular(path, st, kind);  // before open: opening a FIFO or a device may wait
  // O_NONBLOCK: if the path was swapped for a FIFO since the stat, the open still returns.
  Descriptor file{::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC)};
  if (file.fd < 0) fail(path, std::string("cannot open the ") + kind.name + " (" + system_reason() + ")");
  if (::fstat(file.fd, &st) != 0) fail(path, std::string("cannot read the ") + kind.name + " (" + system_reason() + ")");
  require_regular(path, st, kind);
  if (std::uint64_t(st.st_size) > cap) over_cap(path, kind, cap, mib_text(std::uint64_t(st.st_size)));
  // Read to the cap plus one byte whatever the size said: /proc and /sys files report 0 and
  // a file may grow while it is read.
  std::string bytes;
  bytes.reserve(std::size_t(st.st_size));
  char buffer[1 << 16];
  for (;;) {
    const ssize_t n = ::read(file.fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) fail(path, std::string("cannot read the ") + kind.name + " (" + system_reason() + ")");
    if (n == 0) break;
    bytes.append(buffer, std::size_t(n));
    if (bytes.size() > cap) over_cap(path, kind, cap, "larger than " + mib_text(cap));
  }
  return bytes;
}

}  // namespace papertear
