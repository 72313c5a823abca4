// `papertear sweep`: sweep files and their point order, and the program run as a child
// process: a whole sweep, its points run one by one with --index and merged with --collect,
// --count, agreement with `papertear run`, independence of --jobs/--threads, bad input,
// Ctrl-C.
#include <signal.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "tools/sweep_file.hpp"
#include "tools/sweep_results.hpp"
#include "tests/cli_runner.hpp"
#include "tests/test_files.hpp"

namespace io = papertear::io;
namespace fs = std::filesystem;
using Catch::Matchers::Contains;
using papertear::testing::read_text;
using papertear::testing::run_cli;

namespace {

fs::path test_dir(const std::string& name) { return papertear::testing::fresh_test_dir("sweep", name); }

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// A tiny tearing scene: 12 x 12 x 2 cells, 60 steps, a few frames.
constexpr const char* kBaseScene = R"(
[sheet]
cells = [12, 12, 2]
[load]
notch = 2
grip_margin = 1
speed = 0.2
ramp_time = 2.0
[run]
steps = 60
frames = 3
)";

// Writes base.toml and sweep.toml into `dir`; returns the sweep file.
fs::path write_sweep(const fs::path& dir, const std::string& body) {
  write_text(dir / "base.toml", kBaseScene);
  write_text(dir / "sweep.toml", "scene = \"base.toml\"\n" + body);
  return dir / "sweep.toml";
}

const std::string kTwoPoints = "[grid]\nmaterial.fiber_length = [3.0, 6.0]\n";

std::string q(const fs::path& p) { return "'" + p.string() + "'"; }

papertear::testing::CliResult sweep(const std::string& args, const fs::path& dir) {
  return run_cli(PAPERTEAR_CLI, "sweep " + args, dir);
}

bool no_files_under(const fs::path& dir) { return !fs::exists(dir) || fs::is_empty(dir); }

}  // namespace

TEST_CASE("sweep points: grid keys in file order, the first slowest, seeds innermost", "[sweep]") {
  const fs::path dir = test_dir("order");
  const fs::path file = write_sweep(dir, R"(
seeds = [7, 9]
[set]
run.steps = 10
[grid]
sheet.cells = [[12, 12, 2], [14, 12, 2]]
material.block_width = [1, 2, 3]
)");
  const io::SweepDefinition s = io::load_sweep(file);
  REQUIRE(s.points.size() == 12);
  REQUIRE(s.keys == std::vector<std::string>{"sheet.cells", "material.block_width"});
  CHECK(s.points[0].values[0].toml == "[12, 12, 2]");
  CHECK(s.points[0].values[1].toml == "1");
  CHECK(*s.points[0].seed == 7);
  CHECK(*s.points[1].seed == 9);
  CHECK(s.points[2].values[1].toml == "2");
  CHECK(s.points[6].values[0].toml == "[14, 12, 2]");
  CHECK(s.points[11].values[1].toml == "3");
  CHECK(s.points[11].index == 11);
  const std::vector<io::SetOverride> o = io::point_overrides(s, s.points[3]);
  REQUIRE(o.size() == 4);
  CHECK(o[0].argument() == "run.steps=10");
  CHECK(o[3].argument() == "run.seed=9");
  CHECK(io::resolve_point(s, s.points[11]).scene.material.block_width == 3);
}

TEST_CASE("sweep point tables: one point per table in file order, their keys are the columns", "[sweep]") {
  const fs::path dir = test_dir("point_tables");
  const fs::path file = write_sweep(dir, R"(
[[point]]
material.preset = "washi"
[[point]]
material.preset = "kraft"
material.strain_inter = 0.125
)");
  const io::SweepDefinition s = io::load_sweep(file);
  REQUIRE(s.points.size() == 2);
  CHECK(s.keys == std::vector<std::string>{"material.preset", "material.strain_inter"});
  CHECK(s.points[1].values[1].toml == "0.125");
  CHECK(io::resolve_point(s, s.points[1]).scene.material.strain_inter == 0.125);
  CHECK(io::resolve_point(s, s.points[0]).scene.material.fiber_length == 16.0);
}

TEST_CASE("A 2-point sweep runs, --index results merged by --collect equal the whole sweep's rows, digests included",
          "[sweep][cli]") {
  const fs::path dir = test_dir("index_collect");
  const fs::path file = write_sweep(dir, kTwoPoints);
  const fs::path whole = dir / "whole", split = dir / "split";
  const auto all = sweep(q(file) + " --out " + q(whole) + " --jobs 2", dir);
  INFO(all.err);
  REQUIRE(all.code == 0);
  CHECK_THAT(all.out, Contains("2 points, 2 completed"));

  for (int i : {1, 0}) {
    const auto one = sweep(q(file) + " --index " + std::to_string(i) + " --out " + q(split) + " --threads 1", dir);
    INFO(one.err);
    REQUIRE(one.code == 0);
    CHECK_THAT(one.last_line(), Contains("digest: "));
  }
  CHECK_FALSE(fs::exists(split / "sweep.csv"));
  const auto merged = sweep(q(file) + " --collect " + q(split), dir);
  INFO(merged.err);
  REQUIRE(merged.code == 0);

  const std::string csv = read_text(whole / "sweep.csv");
  CHECK(csv == read_text(split / "sweep.csv"));
  CHECK(read_text(whole / "sweep.json") == read_text(split / "sweep.json"));

  const nlohmann::json j = nlohmann::json::parse(read_text(whole / "sweep.json"));
  REQUIRE(j["rows"].size() == 2);
  CHECK(j["keys"] == nlohmann::json::array({"material.fiber_length"}));
  for (int i = 0; i < 2; ++i) {
    const nlohmann::json& row = j["rows"][i];
    CHECK(row["index"] == i);
    CHECK(row["material.fiber_length"] == (i == 0 ? 3.0 : 6.0));
    CHECK(row["status"] == "completed");
    CHECK(row["digest"].get<std::string>().size() == 16);
    CHECK(row["steps"] == 60);
    CHECK(row.contains("edge_roughness"));
    CHECK(row.contains("peak_grip_force"));
    CHECK(row["peak_grip_force"].get<double>() >= row["grip_force"].get<double>());
    CHECK(row["separation_roughness"].get<double>() >= 0.0);
    CHECK_THAT(csv, Contains(row["digest"].get<std::string>()));
  }
  // Two fibre lengths give two different sheets.
  CHECK(j["rows"][0]["digest"] != j["rows"][1]["digest"]);
  CHECK_THAT(csv.substr(0, csv.find('\n')), Contains("index,seed,material.fiber_length,status,error,digest"));
}

TEST_CASE("sweep --count prints the number of points: grid x seeds", "[sweep][cli]") {
  const fs::path dir = test_dir("count");
  const fs::path file = write_sweep(dir, "seeds = [1, 2]\n[grid]\nmaterial.block_width = [1, 2, 3]\n"
                                         "material.block_depth = [1, 2]\n");
  const auto r = sweep(q(file) + " --count", dir);
  INFO(r.err);
  REQUIRE(r.code == 0);
  CHECK(r.out == "12\n");
  write_sweep(dir, "");  // neither [grid] nor [[point]]: the base scene once
  CHECK(sweep(q(file) + " --count", dir).out == "1\n");
}

TEST_CASE("a sweep point's digest equals papertear run of the same scene with the same overrides",
          "[sweep][cli]") {
  const fs::path dir = test_dir("run_equal");
  const fs::path file = write_sweep(dir, "seeds = [5]\n[set]\nmaterial.strain_inter = 0.09\n" + kTwoPoints);
  const auto point = sweep(q(file) + " --index 1 --out " + q(dir / "out"), dir);
  INFO(point.err);
  REQUIRE(point.code == 0);
  const auto run = run_cli(PAPERTEAR_CLI,
                           "run " + q(dir / "base.toml") +
                               " --set material.strain_inter=0.09 --set material.fiber_length=6.0 --set run.seed=5 --quiet",
                           dir);
  INFO(run.err);
  REQUIRE(run.code == 0);
  CHECK(point.last_line() == run.last_line());
  const nlohmann::json p = nlohmann::json::parse(read_text(dir / "out/points/point_00001.json"));
  CHECK("digest: " + p["row"]["digest"].get<std::string>() == run.last_line());
  CHECK(p["row"]["seed"] == 5);
}

TEST_CASE("sweep rows do not depend on --jobs or --threads", "[sweep][cli]") {
  const fs::path dir = test_dir("jobs");
  const fs::path file = write_sweep(dir, "seeds = [1, 2]\n" + kTwoPoints);
  const auto a = sweep(q(file) + " --out " + q(dir / "a") + " --jobs 1 --threads 1", dir);
  INFO(a.err);
  REQUIRE(a.code == 0);
  const auto b = sweep(q(file) + " --out " + q(dir / "b") + " --jobs 2 --threads 2", dir);
  INFO(b.err);
  REQUIRE(b.code == 0);
  CHECK(read_text(dir / "a/sweep.csv") == read_text(dir / "b/sweep.csv"));
  CHECK(read_text(dir / "a/sweep.json") == read_text(dir / "b/sweep.json"));
  CHECK(nlohmann::json::parse(read_text(dir / "a/sweep.json"))["rows"].size() == 4);
}

TEST_CASE("sweep --collect fails naming the missing points, and refuses another sweep's point files", "[sweep][cli]") {
  const fs::path dir = test_dir("collect_missing");
  const fs::path file = write_sweep(dir, "seeds = [1, 2]\n" + kTwoPoints);
  const fs::path out = dir / "out";
  REQUIRE(sweep(q(file) + " --index 2 --out " + q(out), dir).code == 0);
  const auto r = sweep(q(file) + " --collect " + q(out), dir);
  CHECK(r.code == 1);
  CHECK_THAT(r.err, Contains("3 of 4 point files are missing: point_00000.json, point_00001.json, point_00003.json"));
  CHECK_FALSE(fs::exists(out / "sweep.csv"));
  CHECK_FALSE(fs::exists(out / "sweep.json"));

  // The same points of an edited sweep: point 2's file now belongs to another sweep.
  for (int i : {0, 1, 3}) REQUIRE(sweep(q(file) + " --index " + std::to_string(i) + " --out " + q(out), dir).code == 0);
  write_sweep(dir, "seeds = [1, 2]\n[set]\nload.speed = 0.1\n" + kTwoPoints);
  REQUIRE(sweep(q(file) + " --index 0 --out " + q(out), dir).code == 0);
  const auto foreign = sweep(q(file) + " --collect " + q(out), dir);
  CHECK(foreign.code == 1);
  CHECK_THAT(foreign.err, Contains("point_00001.json: belongs to another sweep"));
  CHECK_FALSE(fs::exists(out / "sweep.csv"));
}

TEST_CASE("bad sweep input fails naming the problem and writes nothing", "[sweep][cli]") {
  const fs::path dir = test_dir("bad");
  const fs::path out = dir / "out";
  struct Case {
    std::string body, args, message;
  };
  const std::vector<Case> cases = {
      {kTwoPoints, "--index 2", "--index 2 is out of range: the sweep has 2 points"},
      {kTwoPoints, "--index -1", "--index -1 is out of range"},
      {kTwoPoints, "", ""},  // sentinel replaced below: the file is missing
      {"[grid]\n", "", "[grid] is empty"},
      {"[grid]\nmaterial.fiber_length = []\n", "", "the list of values is empty"},
      {"[grid]\nmaterial.fiber_length = 4.0\n", "", "[grid] material.fiber_length: expected a list of values"},
      {"[grid]\nmaterial.fiber_lenght = [1.0]\n", "",
       "unknown scene key 'material.fiber_lenght' (did you mean 'material.fiber_length'?)"},
      {"seed = [1]\n", "", "unknown key 'seed' (did you mean 'seeds'?)"},
      {"seeds = []\n", "", "the list of seeds is empty"},
      {"seeds = [1]\n[grid]\nrun.seed = [1, 2]\n", "", "run.seed is set by `seeds`"},
      {"[grid]\nmaterial.block_width = [1, \"two\"]\n", "", "point 1: "},
      {"[grid]\nmaterial.block_width = [1]\n[[point]]\nmaterial.block_width = 2\n", "", "not both"},
      {"[grid\n", "", "TOML syntax error"},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    Case c = cases[i];
    fs::path file = write_sweep(dir, c.body);
    if (c.message.empty()) {
      file = dir / "absent.toml";
      c.message = "absent.toml: sweep file not found";
    }
    INFO("case " << i << ": " << c.body);
    const auto r = sweep(q(file) + " --out " + q(out) + " " + c.args, dir);
    CHECK(r.code == 1);
    CHECK_THAT(r.err, Contains(c.message));
    CHECK(no_files_under(out));
  }
  write_text(dir / "sweep.toml", "scene = \"nowhere.toml\"\n");
  const auto missing_scene = sweep(q(dir / "sweep.toml") + " --out " + q(out), dir);
  CHECK(missing_scene.code == 1);
  CHECK_THAT(missing_scene.err, Contains("nowhere.toml: scene file not found"));
  CHECK(no_files_under(out));
  const auto no_out = sweep(q(write_sweep(dir, kTwoPoints)), dir);
  CHECK(no_out.code == 1);
  CHECK_THAT(no_out.err, Contains("needs --out DIR"));
}

TEST_CASE("a sweep point that cannot run is recorded with its error and the sweep exits 2", "[sweep][cli]") {
  const fs::path dir = test_dir("failed_point");
  // run.dt = 50 is far above the stable limit: that point's Simulation refuses it.
  const fs::path file = write_sweep(dir, "[grid]\nrun.dt = [\"auto\", 50.0]\n");
  const auto r = sweep(q(file) + " --out " + q(dir / "out"), dir);
  CHECK(r.code == 2);
  CHECK_THAT(r.err, Contains("point 1"));
  CHECK_THAT(r.out, Contains("2 points, 1 completed, 1 failed"));
  const nlohmann::json j = nlohmann::json::parse(read_text(dir / "out/sweep.json"));
  CHECK(j["rows"][0]["status"] == "completed");
  CHECK(j["rows"][1]["status"] == "error");
  CHECK_THAT(j["rows"][1]["error"].get<std::string>(), Contains("run.dt"));
}

TEST_CASE("a sweep draws its plots with gnuplot, and without gnuplot still writes its tables", "[sweep][cli]") {
  const fs::path dir = test_dir("plots");
  const fs::path file = write_sweep(dir, "seeds = [1, 2]\n" + kTwoPoints);
  const auto no_gnuplot = run_cli("/usr/bin/env", "PATH=/nonexistent '" + std::string(PAPERTEAR_CLI) + "' sweep " +
                                                      q(file) + " --out " + q(dir / "plain"),
                                  dir);
  INFO(no_gnuplot.err);
  CHECK(no_gnuplot.code == 0);
  CHECK_THAT(no_gnuplot.err, Contains("gnuplot not found"));
  CHECK(fs::exists(dir / "plain/sweep.csv"));
  CHECK_FALSE(fs::exists(dir / "plain/plots"));

  if (system("command -v gnuplot >/dev/null 2>&1") != 0) {
    WARN("gnuplot is not installed: plots not checked");
    return;
  }
  const auto r = sweep(q(file) + " --out " + q(dir / "plotted"), dir);
  INFO(r.err);
  REQUIRE(r.code == 0);
  for (const char* metric :
       {"edge_roughness", "separation_roughness", "peeled_area", "peak_grip_force", "torn_edge_length"}) {
    const fs::path png = dir / "plotted/plots" / (std::string(metric) + "_vs_material.fiber_length.png");
    INFO(png);
    REQUIRE(fs::exists(png));
    CHECK(read_text(png).substr(1, 3) == "PNG");
  }
  CHECK(read_text(dir / "plain/sweep.csv") == read_text(dir / "plotted/sweep.csv"));
}

#ifdef PAPERTEAR_CLI
namespace {

struct Stopped {
  int code = -1;
  std::string err;
};

// Sends SIGINT to a spawned sweep once `ready` says it has got that far, and waits for it.
template <class Ready>
Stopped interrupt_when(pid_t pid, const fs::path& err, const Ready& ready) {
  const bool got_there = ready();
  kill(pid, SIGINT);
  int status = 0;
  Stopped s;
  if (waitpid(pid, &status, 0) != pid || !got_there) return s;
  s.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  s.err = read_text(err);
  return s;
}

}  // namespace

TEST_CASE("Ctrl-C stops a sweep: point files already written stay, nothing half-written, exit 130", "[sweep][cli]") {
  const fs::path dir = test_dir("interrupt");
  // Point 0 ends at once, point 1 would run for many minutes.
  const fs::path file = write_sweep(dir, "[grid]\nrun.steps = [5, 5000000]\n");
  const std::string cli = PAPERTEAR_CLI;

  SECTION("the whole sweep") {
    const fs::path out = dir / "whole", err = dir / "whole.err";
    const pid_t pid = papertear::testing::spawn_cli(cli, {"sweep", file.string(), "--out", out.string(), "--jobs", "1"},
                                                    dir / "whole.out", err);
    REQUIRE(pid > 0);
    const Stopped s = interrupt_when(pid, err, [&] {
      return papertear::testing::wait_for_text(err, "1/2 points done", std::chrono::seconds(120));
    });
    INFO(s.err);
    CHECK(s.code == 130);
    CHECK_THAT(s.err, Contains("sweep interrupted: 1 of 2 point files written") && Contains("--index I, then --collect"));
    CHECK(fs::exists(io::point_file(out, 0)));
    CHECK_FALSE(fs::exists(io::point_file(out, 1)));
    // The finished point's file is whole; no temporary file is left; no tables were written.
    CHECK(nlohmann::json::parse(read_text(io::point_file(out, 0)))["row"]["status"] == "completed");
    std::size_t files = 0;
    for (const auto& entry : fs::directory_iterator(out / "points")) files += entry.is_regular_file() ? 1 : 0;
    CHECK(files == 1);
    CHECK_FALSE(fs::exists(out / "sweep.csv"));
    CHECK_FALSE(fs::exists(out / "sweep.json"));
  }

  SECTION("one point run with --index") {
    const fs::path out = dir / "one", err = dir / "one.err";
    const pid_t pid = papertear::testing::spawn_cli(cli, {"sweep", file.string(), "--index", "1", "--out", out.string()},
                                                    dir / "one.out", err);
    REQUIRE(pid > 0);
    const Stopped s = interrupt_when(pid, err, [&] {
      return papertear::testing::wait_for_handler(pid, SIGINT, std::chrono::seconds(60));
    });
    INFO(s.err);
    CHECK(s.code == 130);
    CHECK_THAT(s.err, Contains("point 1 interrupted; nothing written"));
    CHECK_FALSE(fs::exists(io::point_file(out, 1)));
  }
}
#endif  // PAPERTEAR_CLI
