// Atomic writes (core/atomic_file.hpp) when the disk fills up: the error names the file, the
// earlier version of the file stays whole, and no temporary file is left behind. A full disk
// is simulated in a child process with a file-size limit (RLIMIT_FSIZE): writes past it fail
// with EFBIG, as they would with ENOSPC.
#include <catch2/catch.hpp>

#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "core/atomic_file.hpp"
#include "tests/test_files.hpp"

namespace fs = std::filesystem;

namespace {

using papertear::testing::read_text;

// Runs `body` in a child whose files may not grow beyond `limit` bytes; returns its exit code.
template <class Body>
int in_child_with_file_limit(rlim_t limit, const Body& body) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::signal(SIGXFSZ, SIG_IGN);  // report EFBIG from write() instead of killing the process
    const rlimit r{limit, limit};
    ::setrlimit(RLIMIT_FSIZE, &r);
    ::_exit(body());
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 100;
}

}  // namespace

TEST_CASE("a write that fills the disk fails cleanly and keeps the earlier file", "[output]") {
  const fs::path dir = papertear::testing::fresh_test_dir("output", "full-disk");
  const fs::path file = dir / "summary.json";
  papertear::write_file_atomically(file, "the earlier, complete file\n");

  const int code = in_child_with_file_limit(1024, [&] {
    try {
      papertear::write_file_atomically(file, std::string(64 * 1024, 'x'));
      return 1;  // it should not have succeeded
    } catch (const papertear::FileWriteError& e) {
      const std::string what = e.what();
      return what.find("summary.json") != std::string::npos && what.find("cannot write") != std::string::npos ? 0 : 2;
    }
  });
  CHECK(code == 0);  // 1: the write succeeded, 2: the message did not name the file and the failure
  CHECK(read_text(file) == "the earlier, complete file\n");
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++entries;
  CHECK(entries == 1);  // no temporary file left behind
}

TEST_CASE("an atomic write replaces the file whole", "[output]") {
  const fs::path dir = papertear::testing::fresh_test_dir("output", "atomic");
  papertear::write_file_atomically(dir / "a.txt", "first");
  papertear::write_file_atomically(dir / "a.txt", "second, longer");
  CHECK(read_text(dir / "a.txt") == "second, longer");
  CHECK(fs::status(dir / "a.txt").permissions() == (fs::perms::owner_read | fs::perms::owner_write |
                                                    fs::perms::group_read | fs::perms::others_read));
  CHECK_THROWS_AS(papertear::write_file_atomically(dir / "no_such_dir" / "b.txt", "x"), papertear::FileWriteError);
}
