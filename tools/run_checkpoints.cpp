#include "tools/run_checkpoints.hpp"

#include <cstdio>

#include <nlohmann/json.hpp>

#include "core/checkpoint.hpp"
#include "tools/output_files.hpp"
#include "tools/summary.hpp"

namespace papertear::io {
namespace {

using nlohmann::json;

constexpr const char* kRunStateSchema = "papertear-run-state";
constexpr int kRunStateVersion = 1;

// The inverse of metrics_to_json (tools/summary.hpp): the same keys (visit_metrics).
Metrics metrics_from_json(const json& j) {
  Metrics m;
  visit_metrics(m, [&](const char* key, auto& value) { j.at(key).get_to(value); });
  return m;
}

json plan_to_json(const FramePlan& p) {
  return {{"first_step", p.first_step}, {"end_step", p.end_step}, {"spacing_steps", p.spacing_steps},
          {"spacing_frames", p.spacing_frames}};
}

FramePlan plan_from_json(const json& j) {
  FramePlan p;
  j.at("first_step").get_to(p.first_step);
  j.at("end_step").get_to(p.end_step);
  j.at("spacing_steps").get_to(p.spacing_steps);
  j.at("spacing_frames").get_to(p.spacing_frames);
  if (p.first_step < 0 || p.end_step < p.first_step || p.spacing_steps < 0 || p.spacing_frames < 1)
    throw std::invalid_argument("the frame plan is impossible");
  return p;
}

[[noreturn]] void bad_state(const std::string& why) {
  throw CheckpointError(CheckpointError::Kind::Inconsistent,
                        std::string(checkpoint_error_name(CheckpointError::Kind::Inconsistent)) +
                            ": the run state stored by papertear run is unreadable (" + why + ")");
}

}  // namespace

std::string encode_run_state(const RunState& state) {
  json frames = json::array();
  for (const Metrics& m : state.record.frames) frames.push_back(metrics_to_json(m));
  const json j = {
      {"schema", kRunStateSchema},
      {"version", kRunStateVersion},
      {"scene_path", state.scene_path},
      {"render_config", state.render_config},
      {"plan", plan_to_json(state.plan)},
      {"frames", frames},
      {"wall_seconds", state.record.wall_seconds},
      {"step_seconds", state.record.step_seconds},
  };
  const std::vector<std::uint8_t> bytes = json::to_cbor(j);
  return std::string(bytes.begin(), bytes.end());
}

RunState decode_run_state(std::string_view bytes) {
  try {
    const json j = json::from_cbor(bytes.begin(), bytes.end());
    if (!j.is_object() || j.value("schema", "") != kRunStateSchema) bad_state("not a run state");
    if (j.value("version", 0) != kRunStateVersion)
      bad_state("run state version " + j.value("version", json(nullptr)).dump() + ", this build reads " +
                std::to_string(kRunStateVersion));
    RunState s;
    j.at("scene_path").get_to(s.scene_path);
    j.at("render_config").get_to(s.render_config);
    s.plan = plan_from_json(j.at("plan"));
    for (const json& f : j.at("frames")) s.record.frames.push_back(metrics_from_json(f));
    j.at("wall_seconds").get_to(s.record.wall_seconds);
    j.at("step_seconds").get_to(s.record.step_seconds);
    return s;
  } catch (const CheckpointError&) {
    throw;
  } catch (const std::exception& e) {  // nlohmann::json errors, an impossible plan
    bad_state(e.what());
  }
}

std::filesystem::path checkpoint_path(const std::filesystem::path& out_dir, std::int64_t step) {
  char name[48];
  std::snprintf(name, sizeof name, "step_%08lld.ptck", static_cast<long long>(step));
  return out_dir / "checkpoints" / name;
}

CheckpointWriter::CheckpointWriter(std::filesystem::path out_dir, int keep, RunState base)
    : dir_(std::move(out_dir)), keep_(keep), base_(std::move(base)) {}

std::filesystem::path CheckpointWriter::write(const Simulation& sim, const RunRecord& record) {
  const std::filesystem::path path = checkpoint_path(dir_, sim.steps_done());
  create_output_dir(path.parent_path());
  RunState state = base_;
  state.record.frames = record.frames;
  state.record.wall_seconds = record.wall_seconds;
  state.record.step_seconds = record.step_seconds;
  try {
    save_checkpoint(sim.world(), path.string(), encode_run_state(state));
  } catch (const CheckpointError& e) {
    throw OutputError(e.what());
  }
  if (written_.empty() || written_.back() != path) written_.push_back(path);
  while (keep_ > 0 && written_.size() > std::size_t(keep_)) {
    std::error_code ignored;  // a checkpoint that cannot be deleted only costs disk space
    std::filesystem::remove(written_.front(), ignored);
    written_.pop_front();
  }
  return path;
}

namespace {

// The one piece of global state in the program: a signal handler can reach nothing else.
// Only the handler writes it and only the run loop (through RunControl::stop) reads it.
volatile std::sig_atomic_t g_interrupt_signal = 0;

extern "C" void record_interrupt(int signal_number) { g_interrupt_signal = signal_number; }

void install(int signal_number, struct sigaction& old) {
  sigaction(signal_number, nullptr, &old);
  // A signal ignored from the start (nohup, a shell's background job) stays ignored.
  if (old.sa_handler == SIG_IGN) return;
  struct sigaction action {};
  action.sa_handler = record_interrupt;
  sigemptyset(&action.sa_mask);
  // SA_RESETHAND: the second signal gets the default action and ends the program.
  // SA_RESTART: a system call the signal interrupts (a file write) resumes instead of failing.
  action.sa_flags = SA_RESETHAND | SA_RESTART;
  sigaction(signal_number, &action, nullptr);
}

}  // namespace

InterruptGuard::InterruptGuard() {
  g_interrupt_signal = 0;
  install(SIGINT, old_int_);
  install(SIGTERM, old_term_);
}

InterruptGuard::~InterruptGuard() {
  sigaction(SIGINT, &old_int_, nullptr);
  sigaction(SIGTERM, &old_term_, nullptr);
}

const volatile std::sig_atomic_t* InterruptGuard::flag() const { return &g_interrupt_signal; }

int InterruptGuard::signal_number() const { return g_interrupt_signal; }

}  // namespace papertear::io
