// Runs the papertear command-line tool from a test: `papertear <args>` in a shell (the
// caller quotes arguments), with stdout and stderr captured into files in `dir`; or as a
// child process the test can signal (spawn_cli), with wait_for_text to see how far it got.
#pragma once
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

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

// Starts `cli args...` in a child process with stdout and stderr in the files `out` and
// `err`: no shell, so a signal sent to the returned pid reaches the program (and is not
// ignored, as it is in a shell's background job). Returns -1 if it could not start.
inline pid_t spawn_cli(const std::string& cli, const std::vector<std::string>& args, const std::filesystem::path& out,
                       const std::filesystem::path& err) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  std::vector<std::string> all = {cli};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, cli.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return rc == 0 ? pid : -1;
}

// Waits until the file `path` contains `text`, or the timeout passes; true if it did.
inline bool wait_for_text(const std::filesystem::path& path, const std::string& text, std::chrono::seconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    if (read_text(path).find(text) != std::string::npos) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

// Waits until process `pid` catches signal `sig` (Linux: its SigCgt mask in /proc), i.e. has
// installed its handler, or the timeout passes; true if it did. For commands that print
// nothing before their work starts.
inline bool wait_for_handler(pid_t pid, int sig, std::chrono::seconds timeout) {
  const std::filesystem::path status = "/proc/" + std::to_string(pid) + "/status";
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    std::istringstream in(read_text(status));
    for (std::string line; std::getline(in, line);)
      if (line.rfind("SigCgt:", 0) == 0 && (std::stoull(line.substr(7), nullptr, 16) >> (sig - 1) & 1u) != 0)
        return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

}  // namespace papertear::testing
