// The `papertear` program and the pieces it is made of: the frame loop and its sinks,
// progress lines, atomic output files, and the program itself run as a child process
// (bad input leaves no output, a run's summary.json agrees with its stdout).
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "tools/output_files.hpp"
#include "tools/progress.hpp"
#include "tools/run_frames.hpp"
#include "tools/scene_file.hpp"
#include "tools/summary.hpp"
#include "tests/cli_runner.hpp"
#include "tests/test_files.hpp"

namespace pt = papertear;
namespace io = papertear::io;
namespace fs = std::filesystem;
using Catch::Matchers::Contains;

namespace {

fs::path test_dir(const std::string& name) { return pt::testing::fresh_test_dir("cli", name); }

using pt::testing::read_text;

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

pt::Scene tiny_scene(int steps, int frames) {
  pt::Scene s;
  s.sheet.cells = {6, 6, 2};
  s.load.grip_margin = 0;
  s.load.notch = 0;
  s.run.steps = steps;
  s.run.frames = frames;
  return s;
}

// Records what the run loop hands to a sink.
struct RecordingSink : io::FrameSink {
  int starts = 0, finishes = 0;
  std::vector<int> frames;
  std::vector<std::int64_t> sim_steps, metric_steps;
  void on_start(const pt::Simulation&) override { ++starts; }
  void on_frame(const pt::Simulation& sim, int frame, int, const pt::Metrics& m) override {
    frames.push_back(frame);
    sim_steps.push_back(sim.steps_done());
    metric_steps.push_back(m.step);
  }
  void on_finish(const pt::Simulation&, const io::RunRecord&) override { ++finishes; }
};

}  // namespace

TEST_CASE("frames spread the steps evenly and end at the last step", "[cli]") {
  for (int steps : {0, 1, 7, 20, 3000}) {
    for (int frames : {1, 2, 3, 30}) {
      std::int64_t prev = 0;
      for (int f = 0; f < frames; ++f) {
        std::int64_t end = io::frame_end_step(steps, frames, f);
        CHECK(end >= prev);
        CHECK(end - prev <= steps / frames + 1);
        CHECK(end - prev >= steps / frames);
        prev = end;
      }
      CHECK(prev == steps);
    }
  }
}

TEST_CASE("run_frames hands every frame to the sinks and chunking keeps the digest", "[cli]") {
  const pt::Scene scene = tiny_scene(20, 3);
  pt::Simulation sim(scene, {.threads = 1});
  RecordingSink sink;
  io::FrameSink* sinks[] = {&sink};
  std::ostringstream log;
  io::Progress progress(io::ProgressStyle::Lines, log, 20, 3);
  const io::RunRecord record = io::run_frames(sim, sinks, &progress);

  CHECK(sink.starts == 1);
  CHECK(sink.finishes == 1);
  CHECK(sink.frames == std::vector<int>{0, 1, 2});
  CHECK(sink.sim_steps == std::vector<std::int64_t>{6, 13, 20});
  CHECK(sink.metric_steps == sink.sim_steps);
  REQUIRE(record.frames.size() == 3);
  CHECK(record.frames.back().step == 20);
  CHECK(record.steps_done == 20);
  CHECK(!record.failure);
  CHECK(record.dt == sim.dt());
  CHECK(lines_of(log.str()).size() == 3);
  CHECK_THAT(log.str(), Contains("frame 2/3  step 13/20"));

  pt::Simulation straight(scene, {.threads = 1});
  straight.step(20);
  CHECK(record.digest == straight.digest());
}

TEST_CASE("progress: plain lines or a bar or nothing", "[cli]") {
  pt::Metrics m;
  m.step = 10;
  m.splits_inplane = 3;
  m.pieces = 2;
  std::ostringstream lines, bar, silent;
  io::Progress p_lines(io::ProgressStyle::Lines, lines, 20, 2);
  io::Progress p_bar(io::ProgressStyle::Bar, bar, 20, 2);
  io::Progress p_silent(io::ProgressStyle::Silent, silent, 20, 2);
  for (io::Progress* p : {&p_lines, &p_bar, &p_silent}) {
    p->steps_done(10);
    p->frame_done(0, m);
    p->finish();
  }
  CHECK_THAT(lines.str(), Contains("frame 1/2  step 10/20  splits 3  pieces 2"));
  CHECK(lines.str().find('\r') == std::string::npos);
  CHECK_THAT(bar.str(), Contains("\r 50% [###############...............] step 10/20"));
  CHECK(bar.str().back() == '\n');
  CHECK(silent.str().empty());
  CHECK(io::choose_progress_style(true, 0) == io::ProgressStyle::Silent);
  CHECK(io::format_duration(75) == "1m15s");
  CHECK(io::format_duration(3.24) == "3.2s");
}

TEST_CASE("output files are written atomically and bad output paths are refused", "[cli]") {
  const fs::path dir = test_dir("atomic");
  io::write_file_atomically(dir / "a.json", "first");
  io::write_file_atomically(dir / "a.json", "second");
  CHECK(read_text(dir / "a.json") == "second");
  CHECK(std::distance(fs::directory_iterator(dir), fs::directory_iterator()) == 1);  // no temp left
  CHECK_THROWS_WITH(io::write_file_atomically(dir / "missing" / "a.json", "x"),
                    Contains("missing/a.json"));

  std::ofstream(dir / "file.txt") << "not a directory";
  CHECK_THROWS_AS(io::check_output_dir(dir / "file.txt"), io::OutputError);
  CHECK_THROWS_WITH(io::check_output_dir(dir / "file.txt" / "out"), Contains("is not a directory"));
  CHECK_NOTHROW(io::check_output_dir(dir / "new" / "deeper"));
  CHECK(!fs::exists(dir / "new"));  // checking creates nothing
  CHECK_NOTHROW(io::check_output_dir(dir));
}

TEST_CASE("summary_json holds the scene and every frame and the digest", "[cli]") {
  const pt::Scene scene = tiny_scene(10, 2);
  pt::Simulation sim(scene, {.threads = 1});
  const io::RunRecord record = io::run_frames(sim, {}, nullptr);
  const nlohmann::json j = io::summary_json(scene, {"x.toml", 1, 0.5}, record);
  CHECK(j["schema_version"] == io::kSummarySchemaVersion);
  CHECK(j["digest"] == io::digest_hex(sim.digest()));
  CHECK(j["frames"].size() == 2);
  CHECK(j["frames"][1].at("frame") == 1);
  CHECK(j["final"]["step"] == 10);
  CHECK(j["scene"]["sheet"]["cells"] == nlohmann::json::array({6, 6, 2}));
  CHECK(j["scene_file"] == "x.toml");
  CHECK(j["status"] == "completed");
  CHECK(j["error"].is_null());
  CHECK(io::digest_hex(0xabcULL) == "0000000000000abc");
}

TEST_CASE("docs/summary-schema.md documents every key of summary.json", "[cli]") {
  const std::string doc = read_text(fs::path(PAPERTEAR_SOURCE_DIR) / "docs" / "summary-schema.md");
  REQUIRE(!doc.empty());
  io::RunRecord record;
  record.frames.emplace_back();
  record.failure = io::RunFailure{"boom", 3, 4};
  const nlohmann::json j = io::summary_json(pt::Scene{}, {}, record);
  auto documented = [&](const std::string& key) { return doc.find("| `" + key + "` |") != std::string::npos; };
  for (const auto& [key, value] : j.items()) CHECK(documented(key));
  for (const auto& [key, value] : j["final"].items()) CHECK(documented(key));
  for (const auto& [key, value] : j["error"].items()) CHECK(documented(key));
  CHECK(documented("frame"));
  for (const auto& [section, keys] : j["scene"].items()) {
    INFO(section);
    CHECK(doc.find("| `" + section + "` |") != std::string::npos);
    for (const auto& [key, value] : keys.items()) CHECK(doc.find("`" + key + "`") != std::string::npos);
  }
}

#ifdef PAPERTEAR_CLI

namespace {

using pt::testing::CliResult;
CliResult run_cli(const std::string& args, const fs::path& dir) { return pt::testing::run_cli(PAPERTEAR_CLI, args, dir); }


constexpr const char* kTiny =
    "--set 'sheet.cells=[6,6,2]' --set load.notch=0 --set load.grip_margin=0 --steps 20 --frames 2";

}  // namespace

TEST_CASE("papertear: bad input fails with one line naming the problem and writes nothing",
          "[cli]") {
  const fs::path dir = test_dir("bad_input");
  const fs::path out = dir / "out";
  const std::string out_arg = " --out '" + out.string() + "'";
  std::ofstream(dir / "broken.toml") << "[sheet]\ncells = [6, 6, 2\n";
  std::ofstream(dir / "unstable.toml") << "[sheet]\ncells = [6, 6, 2]\n\n[run]\ndt = 100.0\n";
  std::ofstream(dir / "file.txt") << "x";

  struct Case {
    std::string args;
    std::vector<std::string> says;
  };
  const std::vector<Case> cases = {
      {"run --bogus", {"--bogus"}},
      {"run --set 'sheet.cels=[6,6,2]'", {"sheet.cels", "did you mean 'sheet.cells'"}},
      {"run '" + (dir / "missing.toml").string() + "'", {"missing.toml", "not found"}},
      {"run '" + (dir / "broken.toml").string() + "'", {"broken.toml:2:", "syntax"}},
      {"run --set material.density=heavy", {"material.density", "expected a number"}},
      {"run --set 'sheet.cells=[0,6,2]'", {"sheet.cells"}},
      {"run --set material.E_md=nan", {"material.E_md", "finite"}},
      {"run --set 'sheet.cells=[6,6,2]' --set run.dt=100", {"--set run.dt=100: run.dt", "stable"}},
      {"run '" + (dir / "unstable.toml").string() + "'", {"unstable.toml:5:", "run.dt", "stable limit"}},
      {"run --threads -2", {"--threads"}},
      {"run --set print.image=no_such_print.png", {"no_such_print.png"}},
  };
  for (const Case& c : cases) {
    INFO(c.args);
    const CliResult r = run_cli(c.args + out_arg, dir);
    CHECK(r.code == 1);
    for (const std::string& s : c.says) CHECK_THAT(r.err, Contains(s));
    CHECK_THAT(r.err, Contains("papertear: error: "));
    CHECK(lines_of(r.err).size() == 1);
    CHECK(!fs::exists(out));
  }

  const CliResult r = run_cli(std::string("run ") + kTiny + " --out '" + (dir / "file.txt" / "out").string() + "'", dir);
  CHECK(r.code == 1);
  CHECK_THAT(r.err, Contains("file.txt") && Contains("not a directory"));

  const CliResult info = run_cli("info '" + (dir / "unstable.toml").string() + "'", dir);
  CHECK(info.code == 1);
  CHECK_THAT(info.err, Contains("unstable.toml:5:") && Contains("run.dt") && Contains("stable limit"));
}

TEST_CASE("papertear run: summary.json agrees with stdout", "[cli]") {
  const fs::path dir = test_dir("tiny_run");
  const fs::path out = dir / "out" / "nested";
  const CliResult r = run_cli(std::string("run ") + kTiny +
                                  " --set render.width=64 --set render.height=36 --set render.samples=1"
                                  " --threads 1 --out '" + out.string() + "'",
                              dir);
  INFO(r.err);
  REQUIRE(r.code == 0);
  const std::string last = r.last_line();
  REQUIRE(last.size() == 8 + 16);
  CHECK(last.starts_with("digest: "));
  CHECK(last.find_first_not_of("0123456789abcdef", 8) == std::string::npos);

  const nlohmann::json j = nlohmann::json::parse(read_text(out / "summary.json"));
  CHECK(j["schema_version"] == io::kSummarySchemaVersion);
  CHECK("digest: " + j["digest"].get<std::string>() == last);
  CHECK(j["status"] == "completed");
  CHECK(j["steps"] == 20);
  CHECK(j["threads"] == 1);
  CHECK(j["dt"].get<double>() > 0.0);
  CHECK(j["dt"].get<double>() <= j["stable_dt"].get<double>());
  CHECK(j["wall_time_s"].get<double>() >= j["step_time_s"].get<double>());
  CHECK(j["step_time_s"].get<double>() > 0.0);
  REQUIRE(j["frames"].size() == 2);
  CHECK(j["frames"][0]["step"] == 10);
  CHECK(j["frames"][1]["step"] == 20);
  CHECK(j["final"] == [&] { auto f = j["frames"][1]; f.erase("frame"); return f; }());
  CHECK(j["scene"]["sheet"]["cells"] == nlohmann::json::array({6, 6, 2}));
  CHECK(j["scene"]["run"]["steps"] == 20);
  CHECK(j["scene_file"].is_null());
  // summary.json and the renderer's frames (tools/render): the temporary file was renamed away.
  auto files_in = [](const fs::path& d) {
    std::vector<std::string> files;
    for (const auto& entry : fs::directory_iterator(d)) files.push_back(entry.path().filename());
    std::sort(files.begin(), files.end());
    return files;
  };
  // ffmpeg is among the packages tools/install-deps.sh installs: the video is made by default.
  CHECK(files_in(out) ==
        std::vector<std::string>{"animation.glb", "frames", "mesh", "summary.json", "video.mp4"});
  // The end of the run names what an artist opens first.
  CHECK_THAT(r.out, Catch::Contains("video: " + (out / "video.mp4").string() + "\n") &&
                        Catch::Contains("animation: " + (out / "animation.glb").string() + "\n"));
  CHECK(files_in(out / "frames") == std::vector<std::string>{"frame_0000.png", "frame_0001.png"});
  CHECK(files_in(out / "mesh") == std::vector<std::string>{"frame_0001.glb"});  // the last frame
}

TEST_CASE("papertear run: same digest on 1 and 2 threads and quiet prints only the digest", "[cli]") {
  const fs::path dir = test_dir("threads");
  const CliResult one = run_cli(std::string("run ") + kTiny + " --threads 1", dir);
  const CliResult two = run_cli(std::string("run ") + kTiny + " --threads 2 --quiet", dir);
  REQUIRE(one.code == 0);
  REQUIRE(two.code == 0);
  CHECK(one.last_line() == two.last_line());
  CHECK(lines_of(two.out) == std::vector<std::string>{two.last_line()});
  CHECK(two.err.empty());
  CHECK_THAT(one.err, Contains("frame 2/2"));  // not a terminal: plain progress lines
}

TEST_CASE("papertear run: a blow-up is reported and still leaves a summary", "[cli]") {
  const fs::path dir = test_dir("blow_up");
  const fs::path out = dir / "out";
  const CliResult r = run_cli(std::string("run ") + kTiny +
                                  " --set load.speed=1e30 --set load.ramp_time=0 --quiet --out '" +
                                  out.string() + "'",
                              dir);
  CHECK(r.code == 2);
  CHECK_THAT(r.err, Contains("blew up") && Contains("step") && Contains("node"));
  const nlohmann::json j = nlohmann::json::parse(read_text(out / "summary.json"));
  CHECK(j["status"] == "blew_up");
  CHECK(j["error"]["kind"] == "blow_up");
  CHECK(j["error"]["step"].get<std::int64_t>() <= 20);
  CHECK(j["frames"].size() < 2);
}

TEST_CASE("papertear: help on every subcommand and info on a tiny scene", "[cli]") {
  const fs::path dir = test_dir("help_info");
  for (const char* cmd : {"--help", "run --help", "info --help"}) {
    const CliResult r = run_cli(cmd, dir);
    CHECK(r.code == 0);
    CHECK_THAT(r.out, Contains("Usage: papertear"));
  }
  CHECK_THAT(run_cli("run --help", dir).out, Contains("--set") && Contains("--out") && Contains("--quiet"));

  const CliResult info = run_cli("info --set 'sheet.cells=[6,6,2]' --set load.notch=0 --set load.grip_margin=0 --threads 1", dir);
  INFO(info.err);
  REQUIRE(info.code == 0);
  CHECK_THAT(info.out, Contains("6 x 6 x 2 cells"));
  CHECK_THAT(info.out, Contains("nodes:          147"));  // 7 * 7 * 3
  CHECK_THAT(info.out, Contains("stable dt:") && Contains("dt used:") && Contains("estimated run:"));
}

#endif  // PAPERTEAR_CLI
