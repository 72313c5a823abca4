// Runs the papertear command-line tool from a test: `papertear <args>` in a shell (the
// caller quotes arguments), with stdout and stderr captured into files in `dir`.
#pragma once
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>

#include "tests/test_files.hpp"

namespace papertear::testing {

struct CliResult {
  int code = -1;
  std::string out, err;
  std::string last_line() const {
    std::istringstream in(out);
    std::string line, last;
    while (std::getline(in, line)) last = line;
    return last;
  }
};

inline CliResult run_cli(const std::string& cli, const std::string& args, const std::filesystem::path& dir) {
  const std::filesystem::path out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string command =
      "'" + cli + "' " + args + " >'" + out.string() + "' 2>'" + err.string() + "' </dev/null";
  const int status = std::system(command.c_str());
  CliResult r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = read_text(out);
  r.err = read_text(err);
  return r;
}

}  // namespace papertear::testing
