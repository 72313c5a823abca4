// `papertear resume CHECKPOINT`: continue a run from a checkpoint written by `papertear run`
// (tools/run_checkpoints.hpp). The run goes on with the plan it was started with, so it ends
// with the digest and summary metrics of a run that never stopped; --steps N instead runs N
// more steps, the frames keeping their spacing. Everything is checked before any file is
// written, as for `run`; then execute_run (run_command.cpp) does the rest.
#include <sstream>

#include "core/checkpoint.hpp"
#include "tools/commands.hpp"
#include "tools/output_files.hpp"
#include "tools/run_checkpoints.hpp"

namespace papertear::cli {
namespace {

namespace fs = std::filesystem;

// --out, or the run directory that holds the checkpoint's `checkpoints` folder.
std::optional<fs::path> resume_out_dir(const ResumeOptions& options) {
  if (!options.out_dir.empty()) return fs::path(options.out_dir);
  const fs::path folder = fs::path(options.checkpoint).parent_path();
  if (folder.filename() != "checkpoints") return std::nullopt;
  return folder.has_parent_path() ? folder.parent_path() : fs::path(".");
}

// A checkpoint saved by an embedding program carries no run state: it is continued as a new
// run from its step to the scene's run.steps, framed like the scene's run.
io::RunState state_of(const CheckpointContents& loaded) {
  if (!loaded.user_data.empty()) return io::decode_run_state(loaded.user_data);
  const World& w = loaded.world;
  io::RunState s;
  const std::int64_t end = std::max<std::int64_t>(w.step, w.scene.run.steps);
  s.plan = {w.step, end, std::max<std::int64_t>(w.scene.run.steps, 0), std::max(w.scene.run.frames, 1)};
  return s;
}

[[noreturn]] void inconsistent(const std::string& origin, const std::string& why) {
  throw CheckpointError(CheckpointError::Kind::Inconsistent,
                        origin + ": " + checkpoint_error_name(CheckpointError::Kind::Inconsistent) + ": " + why);
}

// The stored plan must agree with the world's step and the frames measured so far.
void check_plan(const io::RunState& s, std::int64_t step, const std::string& origin) {
  const io::FramePlan& p = s.plan;
  if (step < p.first_step || step > p.end_step)
    inconsistent(origin, "step " + std::to_string(step) + " lies outside the run's plan (steps " +
                             std::to_string(p.first_step) + " to " + std::to_string(p.end_step) + ")");
  const std::size_t done = s.record.frames.size();
  if (done > std::size_t(p.frame_count()) || (done > 0 && s.record.frames.back().step > step))
    inconsistent(origin, "the frames measured so far do not fit the run's plan");
}

toml::table parse_render_config(const std::string& text, const std::string& origin) {
  try {
    return toml::parse(text);
  } catch (const toml::parse_error& e) {
    inconsistent(origin, std::string("the stored render settings do not parse: ") + std::string(e.description()));
  }
}

RunSession prepare(const ResumeOptions& options, const std::optional<fs::path>& out) {
  if (options.checkpoints.every > 0 && !out)
    throw SceneError("--checkpoint-every needs --out DIR (checkpoints go to DIR/checkpoints)");
  CheckpointContents loaded = read_checkpoint(options.checkpoint);
  io::RunState state = state_of(loaded);
  const std::int64_t step = loaded.world.step;
  if (options.steps) state.plan.end_step = step + *options.steps;
  check_plan(state, step, options.checkpoint);
  io::SceneFile file{loaded.world.scene, parse_render_config(state.render_config, options.checkpoint),
                     state.scene_path, {}};
  Simulation sim(std::move(loaded.world), {.threads = options.threads});
  const fs::path* out_dir = out ? &*out : nullptr;
  auto sinks = make_frame_sinks(file, sim, out_dir);
  if (out_dir) check_run_outputs(*out_dir);
  return {std::move(file), std::move(sim), std::move(sinks), resolved_threads(options.threads),
          out, state.plan, std::move(state.record), options.checkpoints, options.quiet};
}

}  // namespace

int resume_command(const ResumeOptions& options) {
  const std::optional<fs::path> out = resume_out_dir(options);
  std::optional<RunSession> run;
  try {
    run.emplace(prepare(options, out));
    if (out) io::create_output_dir(*out);
  } catch (const std::exception& e) {
    print_error(e.what());
    return kExitBadInput;
  }
  if (!options.quiet)
    std::printf("resuming %s at step %lld\n", options.checkpoint.c_str(),
                static_cast<long long>(run->sim.steps_done()));
  return execute_run(*run);
}

}  // namespace papertear::cli
