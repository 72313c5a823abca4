// Hostile input, as an adversarial user or a broken pipeline would give it: devices, FIFOs,
// unreadable and oversized files, runaway counts, output paths in the way, a full stdout, a
// load that blows the lattice up. Every case runs the real program under a 10 s kill timer
// and must end on its own with the documented exit code and one line naming the problem,
// having written nothing (a blow-up still writes summary.json).
#include <sys/stat.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "tests/cli_runner.hpp"
#include "tests/test_files.hpp"

namespace fs = std::filesystem;
using Catch::Matchers::Contains;

namespace {

constexpr int kHung = 124;  // timeout(1)'s exit code when it had to kill the program

struct Outcome {
  int code = -1;
  std::string out, err;
};

// `papertear <args>` with stdout to `stdout_path`, killed after 10 s.
Outcome run_bounded(const fs::path& dir, const std::string& args, const std::string& env = "",
                    const std::string& stdout_path = "") {
  const fs::path out = stdout_path.empty() ? dir / "stdout.txt" : fs::path(stdout_path);
  const fs::path err = dir / "stderr.txt";
  const std::string command = env + " timeout -k 2 10 '" + std::string(PAPERTEAR_CLI) + "' " + args + " >'" +
                              out.string() + "' 2>'" + err.string() + "' </dev/null";
  const int status = std::system(command.c_str());
  Outcome o;
  o.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (stdout_path.empty()) o.out = papertear::testing::read_text(out);
  o.err = papertear::testing::read_text(err);
  return o;
}

int line_count(const std::string& text) {
  int n = 0;
  for (char c : text) n += c == '\n';
  return n;
}

struct Case {
  const char* name;
  std::string args;      // after the program name; OUT is the output directory
  const char* expected;  // a part of the error line
  std::string env = "";
};

std::string with_out(std::string args, const fs::path& out) {
  const std::string key = "OUT";
  for (std::size_t at; (at = args.find(key)) != std::string::npos;) args.replace(at, key.size(), "'" + out.string() + "'");
  return args;
}

}  // namespace

TEST_CASE("hostile input: every file kind, count and path gets one line, exit 1 and no output", "[cli][input]") {
  const fs::path dir = papertear::testing::fresh_test_dir("hostile", "table");
  const std::string d = dir.string();
  const fs::path fifo = dir / "fifo";
  REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);  // no writer ever opens it
  fs::create_directories(dir / "a_directory");
  fs::resize_file((std::ofstream(dir / "huge.toml"), dir / "huge.toml"), std::uintmax_t(17) << 20);  // sparse
  fs::resize_file((std::ofstream(dir / "two_mib.ptck"), dir / "two_mib.ptck"), std::uintmax_t(2) << 20);
  std::ofstream(dir / "small.toml") << "[sheet]\ncells = [8, 6, 2]\n";
  std::ofstream(dir / "long_key.toml") << "[run]\n" << std::string(10'000'000, 'k') << " = 1\n";
  std::ofstream(dir / "many_lines.toml") << [] {
    std::string s;
    for (int i = 0; i < 1001; ++i) s += "[[line]]\nkind = \"cut\"\npoints = [[1, 1], [2, 2]]\n";
    return s;
  }();
  const std::string f = "'" + fifo.string() + "'";
  const std::vector<Case> cases = {
      {"scene /dev/zero", "run /dev/zero --out OUT", "/dev/zero: is a character device, not a scene file"},
      {"scene /dev/urandom", "run /dev/urandom --out OUT", "is a character device"},
      {"info of /dev/zero", "info /dev/zero", "is a character device"},
      {"checkpoint /dev/zero", "resume /dev/zero --out OUT", "not a checkpoint"},
      {"scene FIFO", "run " + f + " --out OUT", "is a FIFO (named pipe)"},
      {"checkpoint FIFO", "resume " + f + " --out OUT", "is a FIFO (named pipe)"},
      {"sweep FIFO", "sweep " + f + " --out OUT", "is a FIFO (named pipe), not a sweep file"},
      {"scene directory", "run '" + d + "/a_directory' --out OUT", "is a directory, not a scene file"},
      {"scene /proc/self/mem", "run /proc/self/mem --out OUT", "cannot read the scene file"},
      {"17 MiB scene", "run '" + d + "/huge.toml' --out OUT", "over the cap of 16 MiB"},
      {"checkpoint over a lowered cap", "resume '" + d + "/two_mib.ptck' --out OUT", "over the cap of 1 MiB",
       "PAPERTEAR_MAX_INPUT_MB=1"},
      {"malformed cap", "run '" + d + "/small.toml' --out OUT", "PAPERTEAR_MAX_INPUT_MB: must be a whole number",
       "PAPERTEAR_MAX_INPUT_MB=lots"},
      {"10 MB key", "run '" + d + "/long_key.toml' --out OUT", "unknown key of 10000000 characters"},
      {"1001 lines", "run '" + d + "/many_lines.toml' --out OUT", "at most 1000"},
      {"2^31 frames", "run --frames 2147483647 --steps 10 --out OUT", "run.frames: must be at most 100000"},
      {"runaway sheet", "run --set 'sheet.cells=[100000,100000,64]' --out OUT", "nx * ny * layers must be at most"},
      {"too many threads", "run --threads 5000 --out OUT", "--threads"},
      {"print image /dev/zero", "run --set print.image=/dev/zero --steps 2 --out OUT", "not a print image"},
      {"print image FIFO", "run --set print.image=" + f + " --steps 2 --out OUT", "is a FIFO (named pipe)"},
      {"prefix with NUL", "run --set 'output.prefix=\"a\\u0000b\"' --steps 2 --out OUT", "output.prefix"},
      {"prefix ..", "run --set 'output.prefix=\"..\"' --steps 2 --out OUT", "output.prefix: must not begin with"},
      {"huge image", "run --set render.width=100000 --steps 2 --out OUT", "render.width: must be in [1, 16384]"},
      {"camera.up along the view",
       "run --set 'camera.position=[0,0,50]' --set 'camera.target=[0,0,0]' --set 'camera.up=[0,0,1]' --steps 2 --out OUT",
       "camera.up: parallel to the viewing direction"},
      {"empty --out", "run --steps 2 --out ''", "--out: must not be empty"},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const Case& c = cases[i];
    DYNAMIC_SECTION(c.name) {
      const fs::path out = dir / ("out_" + std::to_string(i));
      const Outcome o = run_bounded(dir, with_out(c.args, out), c.env);
      INFO(c.args.substr(0, 200) << "\nstderr: " << o.err.substr(0, 400));
      CHECK(o.code != kHung);
      CHECK(o.code == 1);
      CHECK_THAT(o.err, Contains(c.expected));
      CHECK(line_count(o.err) == 1);
      CHECK(o.out.empty());
      CHECK_FALSE(fs::exists(out));
    }
  }
}

TEST_CASE("hostile input: a file in the output directory where the run writes a directory, and the reverse",
          "[cli][input]") {
  const fs::path dir = papertear::testing::fresh_test_dir("hostile", "in_the_way");
  for (const char* name : {"summary.json", "frames"}) {
    DYNAMIC_SECTION(name) {
      const fs::path out = dir / (std::string("out_") + name);
      fs::create_directories(out);
      if (std::string(name) == "frames")
        std::ofstream(out / name) << "a file";
      else
        fs::create_directories(out / name);
      const Outcome o = run_bounded(dir, "run --steps 2 --out '" + out.string() + "'");
      CHECK(o.code == 1);
      CHECK_THAT(o.err, Contains(std::string(name) + ": is in the way"));
      CHECK(line_count(o.err) == 1);
      CHECK(std::distance(fs::directory_iterator(out), fs::directory_iterator()) == 1);  // nothing added
    }
  }
}

TEST_CASE("hostile input: a stdout that cannot be written fails the run with exit 3", "[cli][input]") {
  const fs::path dir = papertear::testing::fresh_test_dir("hostile", "full_stdout");
  const Outcome o = run_bounded(dir, "run --quiet --steps 2", "", "/dev/full");
  CHECK(o.code == 3);
  CHECK_THAT(o.err, Contains("cannot write the result to standard output"));
}

TEST_CASE("hostile input: a load far faster than the sheet's waves blows up, blamed on load.speed", "[cli][input]") {
  const fs::path dir = papertear::testing::fresh_test_dir("hostile", "blow_up");
  const fs::path out = dir / "out";
  const Outcome o = run_bounded(dir,
                                "run --quiet --set 'sheet.cells=[8,6,2]' --set load.speed=1e6 --steps 200 "
                                "--set output.png=false --set output.mesh=none --set output.animation=false --out '" +
                                    out.string() + "'");
  INFO(o.err);
  CHECK(o.code == 2);
  CHECK_THAT(o.err, Contains("likely cause: load.speed"));
  CHECK_THAT(o.err, Contains("times the sheet's in-plane wave speed"));
  const nlohmann::json summary = nlohmann::json::parse(papertear::testing::read_text(out / "summary.json"));
  CHECK(summary["status"] == "blew_up");
}
