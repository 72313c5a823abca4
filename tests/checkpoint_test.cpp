// Checkpoints (core/checkpoint.hpp) and resuming runs (tools/run_checkpoints.hpp, `papertear
// resume`): a restored world steps in lockstep with the original, a resumed run ends where an
// uninterrupted one does, every kind of damaged file is refused by name, and Ctrl-C leaves a
// checkpoint that resumes.
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "core/checkpoint.hpp"
#include "core/digest.hpp"
#include "core/lattice_builder.hpp"
#include "core/simulation.hpp"
#include "tools/run_checkpoints.hpp"
#include "tools/run_frames.hpp"
#include "tools/summary.hpp"
#include "tests/cli_runner.hpp"
#include "tests/test_files.hpp"

extern char** environ;

namespace pt = papertear;
namespace io = papertear::io;
namespace fs = std::filesystem;
using Catch::Matchers::Contains;
using Kind = pt::CheckpointError::Kind;

namespace {

fs::path test_dir(const std::string& name) { return pt::testing::fresh_test_dir("checkpoint", name); }

using pt::testing::read_text;

// A small sheet that tears within a few hundred steps (splits start before step 300).
pt::Scene tearing_scene() {
  pt::Scene s;
  s.sheet.cells = {24, 16, 3};
  s.load.speed = 0.1;
  s.load.notch = 3;
  s.load.grip_cells = 2;
  s.load.grip_margin = 2;
  s.run.steps = 600;
  return s;
}

pt::Scene tiny_scene() {
  pt::Scene s;
  s.sheet.cells = {6, 6, 2};
  s.load.grip_margin = 0;
  s.load.notch = 0;
  return s;
}

bool same_events(const std::vector<pt::SplitEvent>& a, const std::vector<pt::SplitEvent>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const pt::SplitEvent &x = a[i], &y = b[i];
    if (x.step != y.step || x.node != y.node || x.new_node != y.new_node || x.axis != y.axis ||
        x.interlayer != y.interlayer || x.cell != y.cell || x.slot != y.slot)
      return false;
  }
  return true;
}

// The file image of a world a few steps into a tiny run.
std::string tiny_checkpoint() {
  pt::Simulation sim(tiny_scene(), {.threads = 1});
  sim.step(5);
  return pt::serialize_world(sim.world(), "user bytes");
}

// A file image around `payload` with a correct header, so that the payload's own checks
// are reached.
std::string wrap_payload(const std::string& payload, std::uint32_t version = pt::kCheckpointFormatVersion) {
  std::string out(pt::kCheckpointMagic);
  auto put = [&](std::uint64_t v, int bytes) {
    for (int i = 0; i < bytes; ++i) out.push_back(char((v >> (8 * i)) & 0xff));
  };
  put(version, 4);
  put(0, 4);
  put(payload.size(), 8);
  put(pt::checkpoint_checksum(payload), 8);
  return out + payload;
}

// Calls deserialize_checkpoint and returns the error it throws (fails the test if none).
pt::CheckpointError refusal(const std::string& bytes) {
  try {
    pt::deserialize_checkpoint(bytes);
  } catch (const pt::CheckpointError& e) {
    return e;
  }
  FAIL("the checkpoint was accepted");
  return pt::CheckpointError(Kind::Io, "unreachable");
}

}  // namespace

TEST_CASE("a restored world steps in lockstep with the original", "[checkpoint]") {
  pt::Simulation original(tearing_scene(), {.threads = 2});
  // The checkpoint is taken just after the tear has started, so that it goes on tearing.
  while (original.world().events.empty() && original.steps_done() < 3000) original.step(1);
  original.step(2);
  REQUIRE(!original.world().events.empty());

  pt::Simulation restored(pt::deserialize_world(pt::serialize_world(original.world())), {.threads = 2});
  REQUIRE(restored.steps_done() == original.steps_done());
  REQUIRE(restored.digest() == original.digest());
  const std::size_t events_at_checkpoint = original.world().events.size();
  for (int i = 0; i < 250; ++i) {
    original.step(1);
    restored.step(1);
    INFO("step " << original.steps_done() << ": digests " << original.digest() << " and " << restored.digest());
    REQUIRE(restored.digest() == original.digest());
    REQUIRE(same_events(restored.world().events, original.world().events));
  }
  CHECK(original.world().events.size() > events_at_checkpoint);  // it kept tearing
  CHECK(restored.time() == original.time());
  CHECK(restored.dt() == original.dt());
}

TEST_CASE("a run resumed from a checkpoint file ends with the uninterrupted digest", "[checkpoint]") {
  const fs::path dir = test_dir("resume_file");
  const pt::Scene scene = tearing_scene();
  std::uint64_t reference = 0;
  for (int threads : {1, 2}) {
    INFO("threads " << threads);
    pt::Simulation straight(scene, {.threads = threads});
    straight.step(600);
    if (threads == 1) reference = straight.digest();
    CHECK(straight.digest() == reference);

    pt::Simulation first(scene, {.threads = threads});
    first.step(350);
    const std::string path = (dir / ("t" + std::to_string(threads) + ".ptck")).string();
    pt::save_checkpoint(first.world(), path);
    pt::Simulation resumed(pt::load_checkpoint(path), {.threads = 3 - threads});  // other thread count
    resumed.step(250);
    CHECK(resumed.steps_done() == 600);
    CHECK(resumed.digest() == reference);
    CHECK(same_events(resumed.world().events, straight.world().events));
  }
  // Atomic save: no temporary file is left beside the checkpoints.
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(dir)) files.push_back(e.path().filename());
  std::sort(files.begin(), files.end());
  CHECK(files == std::vector<std::string>{"t1.ptck", "t2.ptck"});
}

TEST_CASE("serialize and deserialize round-trip to an identical file", "[checkpoint]") {
  pt::Simulation sim(tearing_scene(), {.threads = 2});
  sim.step(320);
  const std::string user(std::string("run state \0 with a zero byte", 28));
  const std::string bytes = pt::serialize_world(sim.world(), user);
  const pt::CheckpointContents back = pt::deserialize_checkpoint(bytes);
  CHECK(back.user_data == user);
  CHECK(pt::serialize_world(back.world, user) == bytes);
  CHECK(pt::state_digest(back.world) == sim.digest());
  // The stage state is the state between steps (core/lattice_builder.hpp reset_stage_state).
  const pt::World& w = back.world;
  REQUIRE(w.scratch.sx.size() == w.nodes.count);
  CHECK(std::equal(w.nodes.vx.begin(), w.nodes.vx.end(), w.scratch.svx.begin()));
  CHECK(std::equal(w.nodes.pz.begin(), w.nodes.pz.end(), w.scratch.sz.begin()));
  // Without user data, the file still round-trips and reads back an empty string.
  CHECK(pt::deserialize_checkpoint(pt::serialize_world(sim.world())).user_data.empty());
}

TEST_CASE("every scene field survives a checkpoint", "[checkpoint]") {
  pt::Simulation sim(tiny_scene(), {.threads = 1});
  pt::World world = sim.world();
  // A value other than the default in every field the stored world lets change (the sheet's
  // size must keep matching the lattice).
  pt::Scene& s = world.scene;
  pt::MaterialParams& m = s.material;
  m.preset = "washi";
  m.grain = 'y';
  for (double* v : {&m.E_md, &m.E_cd, &m.E_zd, &m.G_md_cd, &m.G_md_zd, &m.G_cd_zd, &m.density, &m.damping,
                    &m.fiber_length, &m.fiber_length_sigma, &m.block_stiffness, &m.strain_intra, &m.strain_inter,
                    &m.strain_layer, &m.strain_surface, &m.grain_strength, &m.cross_stretch, &m.strength_jitter, &m.tip_strength,
                    &m.bridge_time})
    *v *= 1.25;
  m.block_width += 1;
  m.block_depth += 1;
  s.load.kind = "none";
  s.load.axis = 'y';
  s.load.grip_cells = 1;
  s.load.speed = 0.07;
  s.load.ramp_time = 3.5;
  s.load.grip_margin = 1;
  s.load.notch = 2;
  s.load.indenter = "cone";
  s.load.indenter_radius = 1.5;
  s.load.indenter_angle = 45.0;
  s.load.indenter_at = {0.25, 0.75};
  s.load.contact_stiffness = 4.0;
  s.world.gravity = {0.1, -0.2, -9.8};
  s.world.drag = 0.01;
  s.run.steps = 1234;
  s.run.dt = world.dt;
  s.run.dt_safety = 0.4;
  s.run.frames = 17;
  s.run.seed = 0xfedcba9876543210ull;
  s.run.max_splits_per_step = 9;
  pt::LineParams line;
  line.kind = "perforation";
  line.points = {{1.0, 0.5}, {2.25, 3.0}};
  line.strength = 0.75;
  line.depth = 1;
  line.pitch = 2.5;
  line.duty = 0.3;
  s.lines = {line};
  pt::recompute_masses(world);  // the stored masses must follow the new density

  const pt::Scene back = pt::deserialize_world(pt::serialize_world(world)).scene;
  const nlohmann::json before = io::scene_to_json(s), after = io::scene_to_json(back),
                       defaults = io::scene_to_json(pt::Scene{});
  CHECK(after == before);
  CHECK(back.run.seed == s.run.seed);  // beyond a double's 53 bits
  // The test is only as good as its coverage: every key but the sheet's size was changed.
  CHECK(back.lines == s.lines);
  for (const auto& [key, value] : before["line"][0].items()) {
    INFO("line." << key);
    CHECK(value != io::scene_to_json(pt::Scene{.lines = {pt::LineParams{}}})["line"][0][key]);
  }
  for (const auto& [section, keys] : before.items())
    for (const auto& [key, value] : keys.items()) {
      if (section == "sheet" || section == "line") continue;
      INFO(section << "." << key);
      CHECK(value != defaults[section][key]);
    }
}

TEST_CASE("damaged or foreign files are refused with the reason", "[checkpoint]") {
  const std::string good = tiny_checkpoint();
  REQUIRE_NOTHROW(pt::deserialize_checkpoint(good));

  SECTION("not a checkpoint") {
    for (const std::string bad : {std::string("[sheet]\ncells = [6, 6, 2]\n"), std::string(), std::string("\x89PNG\r\n\x1a\n....")}) {
      const pt::CheckpointError e = refusal(bad);
      CHECK(e.kind == Kind::NotACheckpoint);
      CHECK_THAT(e.what(), Contains("not a papertear checkpoint"));
    }
  }
  SECTION("another format version") {
    std::string bad = good;
    bad[8] = 7;
    const pt::CheckpointError e = refusal(bad);
    CHECK(e.kind == Kind::WrongVersion);
    CHECK_THAT(e.what(), Contains("written by format version 7, this build reads version " +
                                  std::to_string(pt::kCheckpointFormatVersion)));
  }
  SECTION("truncated") {
    for (std::size_t keep : {std::size_t(4), std::size_t(20), good.size() / 2, good.size() - 1}) {
      INFO("kept " << keep << " bytes");
      const pt::CheckpointError e = refusal(good.substr(0, keep));
      CHECK(e.kind == Kind::Truncated);
      CHECK_THAT(e.what(), Contains("truncated"));
    }
    // A payload that is whole by its header but ends inside a section.
    const std::string payload = good.substr(pt::kCheckpointHeaderSize);
    const pt::CheckpointError e = refusal(wrap_payload(payload.substr(0, payload.size() - 12)));
    CHECK(e.kind == Kind::Truncated);
    CHECK_THAT(e.what(), Contains("section USER"));
  }
  SECTION("corrupted") {
    for (std::size_t at : {pt::kCheckpointHeaderSize + 3, good.size() / 2, good.size() - 1}) {
      std::string bad = good;
      bad[at] = char(bad[at] ^ 0x10);
      const pt::CheckpointError e = refusal(bad);
      CHECK(e.kind == Kind::Corrupted);
      CHECK_THAT(e.what(), Contains("corrupted") && Contains("checksum"));
    }
    const pt::CheckpointError e = refusal(good + "trailing");
    CHECK(e.kind == Kind::Corrupted);
    CHECK_THAT(e.what(), Contains("8 unexpected bytes"));
  }
  SECTION("inconsistent contents") {
    const pt::World world = pt::deserialize_world(good);
    auto refused_because = [&](auto&& edit, const std::string& says) {
      pt::World w = world;
      edit(w);
      const pt::CheckpointError e = refusal(pt::serialize_world(w));
      CHECK(e.kind == Kind::Inconsistent);
      CHECK_THAT(e.what(), Contains("inconsistent") && Contains(says));
    };
    refused_because([](pt::World& w) { w.topo.cell_nodes[9] = std::uint32_t(w.nodes.count + 5); },
                    "beyond the node count");
    refused_because([](pt::World& w) { w.topo.cell_scale.pop_back(); }, "cell_scale");
    refused_because([](pt::World& w) { w.topo.dims.nx = 5; }, "sheet.cells");
    refused_because([](pt::World& w) { w.nodes.px.resize(w.nodes.count - 1); }, "node column");
    refused_because([](pt::World& w) { w.scene.material.E_md = -1.0; }, "material.E_md");
    refused_because([](pt::World& w) { w.topo.cell_block[0] = 100000; }, "names block");
    refused_because([](pt::World& w) { w.gripped_nodes.pop_back(); }, "gripped-node list");
    refused_because([](pt::World& w) { w.nodes.mass[3] *= 2.0f; }, "mass");
    refused_because([](pt::World& w) { w.dt = 0.0; }, "time step");
    refused_because([](pt::World& w) { w.events.push_back({w.step + 5, 0, 1, 0, false, 0, 0}); }, "split event");
  }
}

TEST_CASE("checkpoint files: errors name the path, saving replaces atomically", "[checkpoint]") {
  const fs::path dir = test_dir("files");
  const std::string path = (dir / "a.ptck").string();
  pt::Simulation sim(tiny_scene(), {.threads = 1});
  pt::save_checkpoint(sim.world(), path, "one");
  sim.step(3);
  pt::save_checkpoint(sim.world(), path, "two");
  const pt::CheckpointContents c = pt::read_checkpoint(path);
  CHECK(c.user_data == "two");
  CHECK(c.world.step == 3);
  CHECK(std::distance(fs::directory_iterator(dir), fs::directory_iterator()) == 1);

  try {
    pt::load_checkpoint((dir / "missing.ptck").string());
    FAIL("a missing file was read");
  } catch (const pt::CheckpointError& e) {
    CHECK(e.kind == Kind::Io);
    CHECK_THAT(e.what(), Contains("missing.ptck") && Contains("checkpoint not found"));
  }
  std::ofstream(dir / "scene.toml") << "[sheet]\ncells = [6, 6, 2]\n";
  CHECK_THROWS_WITH(pt::load_checkpoint((dir / "scene.toml").string()),
                    Contains("scene.toml: not a papertear checkpoint"));
  CHECK_THROWS_AS(pt::save_checkpoint(sim.world(), (dir / "no" / "such" / "dir.ptck").string()),
                  pt::CheckpointError);
}

TEST_CASE("frame plans: a resumed or extended run keeps the frame spacing", "[checkpoint]") {
  pt::RunParams run;
  run.steps = 20;
  run.frames = 3;
  const io::FramePlan plan = io::FramePlan::for_run(run, 0);
  REQUIRE(plan.frame_count() == 3);
  for (int f = 0; f < 3; ++f) CHECK(plan.frame_end(f) == io::frame_end_step(20, 3, f));

  io::FramePlan longer = plan;
  longer.end_step = 30;  // resume --steps: ten more steps than planned
  CHECK(longer.frame_count() == 5);
  CHECK(longer.frame_end(2) == 20);
  CHECK(longer.frame_end(3) == 26);
  CHECK(longer.frame_end(4) == 30);

  io::FramePlan shorter = plan;
  shorter.end_step = 8;
  CHECK(shorter.frame_count() == 2);
  CHECK(shorter.frame_end(0) == 6);
  CHECK(shorter.frame_end(1) == 8);
}

TEST_CASE("run_frames stops on its flag, checkpoints, and a resumed loop matches", "[checkpoint]") {
  pt::Scene scene = tearing_scene();
  scene.run.steps = 400;
  scene.run.frames = 8;
  pt::Simulation straight(scene, {.threads = 2});
  const io::RunRecord whole = io::run_frames(straight, {}, nullptr);

  // A sink raises the stop flag in frame 3 (as a signal handler would, between steps).
  struct StopAt : io::FrameSink {
    volatile std::sig_atomic_t* flag;
    explicit StopAt(volatile std::sig_atomic_t* f) : flag(f) {}
    void on_frame(const pt::Simulation&, int frame, int, const pt::Metrics&) override {
      if (frame == 3) *flag = SIGINT;
    }
  };
  volatile std::sig_atomic_t stop = 0;
  StopAt stopper(&stop);
  io::FrameSink* sinks[] = {&stopper};
  std::vector<std::int64_t> checkpoint_steps;
  std::string saved;
  io::RunControl control;
  control.stop = &stop;
  control.checkpoint_every = 60;
  control.on_checkpoint = [&](const pt::Simulation& sim, const io::RunRecord& r) {
    checkpoint_steps.push_back(sim.steps_done());
    saved = pt::serialize_world(sim.world(), io::encode_run_state({"", "", {}, r}));
  };
  pt::Simulation first(scene, {.threads = 1});
  const io::FramePlan plan = io::FramePlan::for_run(scene.run, 0);
  const io::RunRecord part = io::run_frames(first, sinks, nullptr, plan, control);
  CHECK(part.stopped);
  CHECK(part.steps_done == 200);  // frame 3 ends at step 200
  CHECK(part.frames.size() == 4);
  CHECK(checkpoint_steps == std::vector<std::int64_t>{60, 120, 180});

  // Resume from the checkpoint at step 180: it holds the three frames measured by then.
  const pt::CheckpointContents c = pt::deserialize_checkpoint(saved);
  io::RunState state = io::decode_run_state(c.user_data);
  REQUIRE(state.record.frames.size() == 3);
  pt::Simulation resumed(pt::World(c.world), {.threads = 2});
  const io::RunRecord rest = io::run_frames(resumed, {}, nullptr, plan, {}, state.record);
  CHECK(!rest.stopped);
  CHECK(rest.digest == whole.digest);
  CHECK(rest.steps_done == 400);
  REQUIRE(rest.frames.size() == whole.frames.size());
  for (std::size_t f = 0; f < whole.frames.size(); ++f)
    CHECK(io::metrics_to_json(rest.frames[f]) == io::metrics_to_json(whole.frames[f]));
}

TEST_CASE("the run state round-trips every metric exactly", "[checkpoint]") {
  io::RunState s;
  s.scene_path = "scenes/a b.toml";
  s.render_config = "[render]\nwidth = 64\n";
  s.plan = {10, 500, 400, 7};
  pt::Metrics m;
  m.step = 123;
  m.time = 0.1 + 0.2;
  m.splits_inplane = 4;
  m.splits_interlayer = 5;
  m.pieces = 2;
  m.torn_edge_length = 1.0 / 3.0;
  m.edge_roughness = 1.5e-300;
  m.peeled_area = 7.25;
  m.grip_force = -2.0 / 7.0;
  m.indenter_force = 5.0 / 9.0;
  m.kinetic_energy = 1e300;
  m.elastic_energy = 3.14159;
  m.intact_blocks = 99;
  m.piece_cells = {40, 31, 2};
  m.fragments = 1;
  m.fragment_fraction = 2.0 / 73.0;
  m.tear_length = 12.625;
  m.splits_per_tear_length = 6.5;
  s.record.frames = {m, pt::Metrics{}};
  s.record.wall_seconds = 1.5;
  s.record.step_seconds = 1.25;
  const io::RunState back = io::decode_run_state(io::encode_run_state(s));
  CHECK(back.scene_path == s.scene_path);
  CHECK(back.render_config == s.render_config);
  CHECK(back.plan.first_step == 10);
  CHECK(back.plan.end_step == 500);
  CHECK(back.plan.spacing_steps == 400);
  CHECK(back.plan.spacing_frames == 7);
  REQUIRE(back.record.frames.size() == 2);
  // metrics_to_json lists every metric; each one must come back with the same bits.
  const nlohmann::json want = io::metrics_to_json(m), got = io::metrics_to_json(back.record.frames[0]);
  for (const auto& [key, value] : want.items()) {
    INFO(key);
    CHECK(got.at(key) == value);
    CHECK(value != io::metrics_to_json(pt::Metrics{}).at(key));  // every metric was set
  }
  CHECK(back.record.wall_seconds == 1.5);
  CHECK_THROWS_AS(io::decode_run_state("not cbor"), pt::CheckpointError);
  const std::vector<std::uint8_t> odd = nlohmann::json::to_cbor({{"schema", 5}});
  CHECK_THROWS_WITH(io::decode_run_state(std::string(odd.begin(), odd.end())), Contains("run state"));
}

namespace {

// The fuzz target's seed corpus (tests/fuzz/): a leading byte picks the mode (0: a whole
// file, 1: a payload that the target wraps in a valid header), then the bytes.
struct FuzzSeed {
  std::string name;
  std::string bytes;                 // with the mode byte
  std::optional<Kind> refused_as;    // empty: accepted
};

std::vector<FuzzSeed> fuzz_seeds() {
  pt::Scene s;  // a sheet that splits within ten steps: the seeds hold split events
  s.sheet.cells = {8, 4, 1};
  s.load.notch = 1;
  s.load.grip_cells = 1;
  s.load.grip_margin = 0;
  s.load.speed = 0.3;
  s.load.ramp_time = 1.0;
  pt::Simulation sim(s, {.threads = 1});
  sim.step(10);
  const std::string good = pt::serialize_world(sim.world(), "u");
  const std::string payload = good.substr(pt::kCheckpointHeaderSize);
  std::string corrupted = good, version = good;
  corrupted[good.size() / 2] = char(corrupted[good.size() / 2] ^ 0x20);
  version[8] = char(pt::kCheckpointFormatVersion + 1);  // another format version
  pt::World broken = sim.world();
  broken.topo.cell_nodes[5] = 1000000;
  const std::string file(1, '\0'), wrapped(1, '\1');
  return {
      {"valid_file", file + good, std::nullopt},
      {"valid_payload", wrapped + payload, std::nullopt},
      {"truncated_file", file + good.substr(0, good.size() / 2), Kind::Truncated},
      {"corrupted_file", file + corrupted, Kind::Corrupted},
      {"wrong_version_file", file + version, Kind::WrongVersion},
      {"not_a_checkpoint", file + "[sheet]\ncells = [6, 6, 2]\n", Kind::NotACheckpoint},
      {"inconsistent_payload", wrapped + pt::serialize_world(broken).substr(pt::kCheckpointHeaderSize),
       Kind::Inconsistent},
      {"short_payload", wrapped + payload.substr(0, payload.size() - 3), Kind::Truncated},
  };
}

}  // namespace

// After a format change, rewrite the seeds with
//   PAPERTEAR_UPDATE_FUZZ_CORPUS=1 papertear_tests "the fuzz seed corpus*"
TEST_CASE("the fuzz seed corpus is of this format and each seed does what its name says", "[checkpoint]") {
  const fs::path dir = fs::path(PAPERTEAR_SOURCE_DIR) / "tests" / "fuzz" / "corpus" / "checkpoint";
  const std::vector<FuzzSeed> seeds = fuzz_seeds();
  if (std::getenv("PAPERTEAR_UPDATE_FUZZ_CORPUS"))
    for (const FuzzSeed& seed : seeds) std::ofstream(dir / seed.name, std::ios::binary) << seed.bytes;
  for (const FuzzSeed& seed : seeds) {
    INFO(seed.name << " (rewrite the corpus with PAPERTEAR_UPDATE_FUZZ_CORPUS=1 if the format changed)");
    const std::string stored = read_text(dir / seed.name);
    REQUIRE(stored.size() > 1);
    const std::string body = stored.substr(1);
    const std::string bytes = stored[0] & 1 ? wrap_payload(body) : body;
    if (!seed.refused_as) {
      CHECK_NOTHROW(pt::deserialize_checkpoint(bytes));
    } else {
      CHECK(refusal(bytes).kind == *seed.refused_as);
    }
  }
}

#ifdef PAPERTEAR_CLI

namespace {

using pt::testing::CliResult;
CliResult run_cli(const std::string& args, const fs::path& dir) { return pt::testing::run_cli(PAPERTEAR_CLI, args, dir); }


std::string quoted(const fs::path& p) { return "'" + p.string() + "'"; }

constexpr const char* kTearing =
    "--set 'sheet.cells=[24,16,3]' --set load.speed=0.1 --set load.notch=3 --set load.grip_cells=2 "
    "--set load.grip_margin=2 --set output.png=false --quiet";

nlohmann::json summary_of(const fs::path& dir) { return nlohmann::json::parse(read_text(dir / "summary.json")); }

// What a resumed run must reproduce: everything but timing and the thread count.
nlohmann::json comparable(nlohmann::json j) {
  for (const char* key : {"wall_time_s", "step_time_s", "threads"}) j.erase(key);
  return j;
}

}  // namespace

TEST_CASE("papertear resume: same digest and summary as an uninterrupted run", "[checkpoint][cli]") {
  const fs::path dir = test_dir("cli_resume");
  const fs::path whole = dir / "whole", part = dir / "part", again = dir / "again";
  const std::string plan = std::string(kTearing) + " --steps 600 --frames 6";
  const CliResult a = run_cli("run " + plan + " --threads 1 --out " + quoted(whole), dir);
  REQUIRE(a.code == 0);
  const CliResult b = run_cli("run " + plan + " --threads 1 --checkpoint-every 100 --keep-checkpoints 0 --out " +
                                  quoted(part),
                              dir);
  REQUIRE(b.code == 0);
  CHECK(b.last_line() == a.last_line());  // writing checkpoints does not change the run
  for (int step = 100; step <= 600; step += 100)
    CHECK(fs::exists(io::checkpoint_path(part, step)));

  // Resume mid-run on another thread count into another directory.
  const CliResult r = run_cli("resume " + quoted(io::checkpoint_path(part, 300)) + " --threads 2 --quiet --out " +
                                  quoted(again),
                              dir);
  INFO(r.err);
  REQUIRE(r.code == 0);
  CHECK(r.last_line() == a.last_line());
  CHECK(r.out == r.last_line() + "\n");  // --quiet: only the digest line
  CHECK(comparable(summary_of(again)) == comparable(summary_of(whole)));
  CHECK(summary_of(again)["frames"].size() == 6);

  // Without --out, the run's own directory is written.
  fs::remove(part / "summary.json");
  const CliResult own = run_cli("resume " + quoted(io::checkpoint_path(part, 500)) + " --threads 2", dir);
  REQUIRE(own.code == 0);
  CHECK_THAT(own.out, Contains("resuming") && Contains("step 500"));
  CHECK(own.last_line() == a.last_line());
  CHECK(comparable(summary_of(part)) == comparable(summary_of(whole)));

  // --steps N: N more steps; the digest is that of a run that long.
  const CliResult more = run_cli("resume " + quoted(io::checkpoint_path(part, 300)) + " --steps 50 --out " +
                                     quoted(dir / "more"),
                                 dir);
  const CliResult straight = run_cli("run " + std::string(kTearing) + " --steps 350 --threads 2", dir);
  REQUIRE(more.code == 0);
  CHECK(more.last_line() == straight.last_line());
  const nlohmann::json m = summary_of(dir / "more");
  CHECK(m["final"]["step"] == 350);
  CHECK(m["steps"] == 350);
  CHECK(m["frames"].size() == 4);  // three measured before the checkpoint, one at step 350
}

TEST_CASE("papertear resume past the plan writes the mesh of its own last frame", "[checkpoint][cli]") {
  const fs::path dir = test_dir("cli_resume_mesh");
  const fs::path part = dir / "part", more = dir / "more";
  const std::string tiny =
      "--set 'sheet.cells=[6,6,2]' --set load.notch=0 --set load.grip_margin=0 --set output.png=false "
      "--set output.mesh=glb --quiet";
  REQUIRE(run_cli("run " + tiny + " --steps 40 --frames 4 --checkpoint-every 10 --keep-checkpoints 0 --out " +
                      quoted(part),
                  dir)
              .code == 0);
  auto meshes_in = [](const fs::path& d) {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(d / "mesh")) names.push_back(e.path().filename());
    std::sort(names.begin(), names.end());
    return names;
  };
  CHECK(meshes_in(part) == std::vector<std::string>{"frame_0003.glb"});
  // From step 30 to step 60: frames 3, 4 and 5 at the plan's spacing; the last is frame 5.
  const CliResult r = run_cli("resume " + quoted(io::checkpoint_path(part, 30)) + " --steps 30 --quiet --out " +
                                  quoted(more),
                              dir);
  INFO(r.err);
  REQUIRE(r.code == 0);
  CHECK(summary_of(more)["frames"].size() == 6);
  CHECK(meshes_in(more) == std::vector<std::string>{"frame_0005.glb"});
}

TEST_CASE("papertear run keeps the newest checkpoints; bad resumes fail cleanly", "[checkpoint][cli]") {
  const fs::path dir = test_dir("cli_keep");
  const fs::path out = dir / "out";
  const std::string tiny =
      "--set 'sheet.cells=[6,6,2]' --set load.notch=0 --set load.grip_margin=0 --set output.png=false --quiet";
  REQUIRE(run_cli("run " + tiny + " --steps 50 --checkpoint-every 10 --keep-checkpoints 2 --out " + quoted(out), dir)
              .code == 0);
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(out / "checkpoints")) files.push_back(e.path().filename());
  std::sort(files.begin(), files.end());
  CHECK(files == std::vector<std::string>{"step_00000040.ptck", "step_00000050.ptck"});

  const CliResult no_out = run_cli("run " + tiny + " --steps 50 --checkpoint-every 10", dir);
  CHECK(no_out.code == 1);
  CHECK_THAT(no_out.err, Contains("--checkpoint-every needs --out"));

  std::string bytes = read_text(out / "checkpoints" / "step_00000050.ptck");
  bytes[bytes.size() / 2] = char(bytes[bytes.size() / 2] ^ 1);
  std::ofstream(dir / "bad.ptck", std::ios::binary) << bytes;
  std::ofstream(dir / "short.ptck", std::ios::binary) << bytes.substr(0, 100);
  struct Case {
    std::string file, says;
  };
  for (const Case& c : {Case{"bad.ptck", "corrupted checkpoint"}, Case{"short.ptck", "truncated checkpoint"},
                        Case{"missing.ptck", "No such file"}}) {
    INFO(c.file);
    const CliResult r = run_cli("resume " + quoted(dir / c.file) + " --out " + quoted(dir / "never"), dir);
    CHECK(r.code == 1);
    CHECK_THAT(r.err, Contains("papertear: error: ") && Contains(c.file) && Contains(c.says));
    CHECK(!fs::exists(dir / "never"));
  }
}

TEST_CASE("Ctrl-C: the run stops after a step, saves a checkpoint and says how to resume", "[checkpoint][cli]") {
  const fs::path dir = test_dir("cli_interrupt");
  const fs::path out = dir / "out";
  // Long enough never to finish before the signal; a frame every 10 steps shows progress.
  const std::vector<std::string> args = {"run", "--set", "sheet.cells=[24,16,3]", "--set", "load.speed=0.1",
                                         "--set", "load.notch=3", "--set", "load.grip_margin=2",
                                         "--set", "output.png=false", "--steps", "200000", "--frames", "20000",
                                         "--threads", "2", "--out", out.string()};
  const pid_t pid = pt::testing::spawn_cli(PAPERTEAR_CLI, args, dir / "run.out", dir / "run.err");
  REQUIRE(pid > 0);
  const bool started = pt::testing::wait_for_text(dir / "run.err", "frame 3/", std::chrono::seconds(120));
  kill(pid, SIGINT);
  int status = 0;
  REQUIRE(waitpid(pid, &status, 0) == pid);
  REQUIRE(started);
  const std::string err = read_text(dir / "run.err");
  INFO(err);
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 130);
  CHECK_THAT(err, Contains("interrupted by SIGINT") && Contains("papertear resume '"));

  // The message names the checkpoint; the summary so far says the run was interrupted.
  const std::size_t at = err.find("papertear resume '") + 18;
  const fs::path checkpoint = err.substr(at, err.find('\'', at) - at);
  REQUIRE(fs::exists(checkpoint));
  const nlohmann::json j = summary_of(out);
  CHECK(j["status"] == "interrupted");
  const std::int64_t stopped_at = j["steps"];
  CHECK(stopped_at > 0);
  CHECK(checkpoint == io::checkpoint_path(out, stopped_at));
  const std::string run_out = read_text(dir / "run.out");
  CHECK_THAT(run_out, Contains("digest: "));

  // It resumes: 20 more steps end where an uninterrupted run of that length does.
  const CliResult resumed = run_cli("resume " + quoted(checkpoint) + " --steps 20 --quiet --out " + quoted(dir / "resumed"), dir);
  REQUIRE(resumed.code == 0);
  const CliResult straight =
      run_cli("run --set 'sheet.cells=[24,16,3]' --set load.speed=0.1 --set load.notch=3 --set load.grip_margin=2 "
              "--quiet --steps " + std::to_string(stopped_at + 20),
              dir);
  REQUIRE(straight.code == 0);
  CHECK(resumed.last_line() == straight.last_line());
}

#endif  // PAPERTEAR_CLI
