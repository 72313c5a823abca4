// `papertear run`: resolve and check everything, create the output directory, run the frames
// (with checkpoints, stopping cleanly on Ctrl-C), write summary.json, print the digest last.
// `papertear resume` (resume_command.cpp) builds its session from a checkpoint and ends here too.
#include <unistd.h>

#include <cstdio>
#include <iostream>
#include <sstream>

#include "tools/commands.hpp"
#include "tools/output_files.hpp"
#include "tools/progress.hpp"
#include "tools/run_checkpoints.hpp"
#include "tools/run_frames.hpp"
#include "tools/summary.hpp"

namespace papertear::cli {
namespace {

std::vector<io::SetOverride> step_overrides(const RunOptions& options) {
  std::vector<io::SetOverride> out;
  if (options.steps) {
    std::string n = std::to_string(*options.steps);
    out.push_back({"run.steps", n, "--steps " + n});
  }
  if (options.frames) {
    std::string n = std::to_string(*options.frames);
    out.push_back({"run.frames", n, "--frames " + n});
  }
  return out;
}

// Everything that can be checked before a file is created. Throws SceneError/OutputError.
RunSession prepare(const RunOptions& options, const std::filesystem::path* out_dir) {
  if (options.checkpoints.every > 0 && !out_dir)
    throw SceneError("--checkpoint-every needs --out DIR (checkpoints go to DIR/checkpoints)");
  io::SceneFile file = resolve_scene(options.scene, step_overrides(options));
  Simulation sim = make_simulation(file, options.scene.threads);  // refuses a run.dt above the stable limit
  auto sinks = make_frame_sinks(file, sim, out_dir);
  if (out_dir) check_run_outputs(*out_dir);
  const io::FramePlan plan = io::FramePlan::for_run(file.scene.run, 0);
  std::optional<std::filesystem::path> out;
  if (out_dir) out = *out_dir;
  return {std::move(file), std::move(sim), std::move(sinks), resolved_threads(options.scene.threads),
          std::move(out), plan, {}, options.checkpoints, options.quiet};
}

io::RunState run_state(const RunSession& s) {
  std::ostringstream render;
  render << s.file.render_config;
  return {s.file.path, render.str(), s.plan, {}};
}

const char* signal_name(int signal_number) {
  switch (signal_number) {
    case SIGINT: return "SIGINT (Ctrl-C)";
    case SIGTERM: return "SIGTERM";
    default: return "a signal";
  }
}

// Single quotes for a shell, so that the printed command can be pasted as it is.
std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

void print_interrupted(int signal_number, const io::RunRecord& record,
                       const std::optional<std::filesystem::path>& checkpoint) {
  std::cerr << "papertear: interrupted by " << signal_name(signal_number) << " after step " << record.steps_done
            << " of " << record.steps_planned;
  if (checkpoint)
    std::cerr << "; checkpoint saved. Continue with:\n  papertear resume " << shell_quote(checkpoint->string());
  else
    std::cerr << "; nothing was saved (run with --out DIR to keep a checkpoint)";
  std::cerr << std::endl;
}

// summary.json, its status "interrupted" when the run was stopped early.
void write_run_summary(const RunSession& s, const io::RunRecord& record) {
  const io::RunSettings settings{s.file.path, s.threads, Simulation::stable_dt_limit(s.file.scene)};
  if (!record.stopped) return io::write_summary(*s.out_dir, s.file.scene, settings, record);
  nlohmann::json j = io::summary_json(s.file.scene, settings, record);
  j["status"] = "interrupted";
  io::write_file_atomically(*s.out_dir / "summary.json",
                            j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
}

void print_result(const io::SceneFile& file, const io::RunRecord& record, int threads,
                  const std::filesystem::path* out_dir) {
  const auto& c = file.scene.sheet.cells;
  std::printf("scene: %s, %d x %d x %d cells, %lld of %lld steps of dt %.6g, %d threads\n",
              file.path.empty() ? "built-in default" : file.path.c_str(), c[0], c[1], c[2],
              static_cast<long long>(record.steps_done),
              static_cast<long long>(record.steps_planned), record.dt, threads);
  if (!record.frames.empty()) {
    const Metrics& m = record.frames.back();
    std::printf("final: %lld in-plane and %lld interlayer splits, %lld pieces, torn edge %.4g, "
                "roughness %.4g, peeled area %.4g\n",
                static_cast<long long>(m.splits_inplane),
                static_cast<long long>(m.splits_interlayer), static_cast<long long>(m.pieces),
                m.torn_edge_length, m.edge_roughness, m.peeled_area);
  }
  double per_step = record.steps_done > 0 ? record.step_seconds / double(record.steps_done) : 0.0;
  std::printf("wall time: %s, of which stepping %s (%.3g ms per step)\n",
              io::format_duration(record.wall_seconds).c_str(),
              io::format_duration(record.step_seconds).c_str(), per_step * 1e3);
  if (!out_dir) return;
  std::printf("summary: %s\n", (*out_dir / "summary.json").c_str());
  // The files an artist opens first, when the run made them ([output] video, animation).
  for (const char* name : {"video.mp4", "animation.glb"})
    if (std::filesystem::exists(*out_dir / name))
      std::printf("%s: %s\n", std::filesystem::path(name).stem().c_str(), (*out_dir / name).c_str());
}

}  // namespace

void check_output_dir_option(const std::filesystem::path& dir) {
  try {
    io::check_output_dir(dir);
  } catch (const io::OutputError& e) {
    throw io::OutputError(std::string("--out ") + e.what());
  }
}

void check_run_outputs(const std::filesystem::path& dir) {
  check_output_dir_option(dir);
  io::check_output_names(dir, {"summary.json", "video.mp4", "animation.glb"}, {"frames", "mesh", "checkpoints"});
}

int run_command(const RunOptions& options) {
  std::optional<std::filesystem::path> out;
  if (!options.out_dir.empty()) out = std::filesystem::path(options.out_dir);
  const std::filesystem::path* out_dir = out ? &*out : nullptr;

  std::optional<RunSession> run;
  try {
    run.emplace(prepare(options, out_dir));
    if (out_dir) io::create_output_dir(*out_dir);
  } catch (const std::exception& e) {
    print_error(e.what());
    return kExitBadInput;
  }
  return execute_run(*run);
}

namespace {

io::RunRecord step_session(RunSession& s, const io::InterruptGuard& interrupt, io::CheckpointWriter* writer) {
  io::Progress progress(io::choose_progress_style(s.quiet, STDERR_FILENO), std::cerr,
                        s.plan.end_step - s.plan.first_step, s.plan.frame_count());
  std::vector<io::FrameSink*> sinks;
  for (auto& sink : s.sinks) sinks.push_back(sink.get());
  io::RunControl control;
  control.stop = interrupt.flag();
  if (writer) {
    control.checkpoint_every = s.checkpoints.every;
    control.on_checkpoint = [writer](const Simulation& sim, const io::RunRecord& r) { writer->write(sim, r); };
  }
  try {
    return io::run_frames(s.sim, sinks, &progress, s.plan, control, std::move(s.so_far));
  } catch (...) {
    progress.finish();
    throw;
  }
}

// Reports the run (blow-up, interruption and its checkpoint, summary.json, the result lines,
// the digest last) and returns the exit code.
int finish_session(const RunSession& s, const io::RunRecord& record, int signal_number,
                   io::CheckpointWriter* writer) {
  int code = kExitOk;
  if (record.failure) {
    print_error("simulation blew up (step " + std::to_string(record.failure->step) + ", node " +
                std::to_string(record.failure->node) + "): " + record.failure->message);
    code = kExitBlowUp;
  }
  std::optional<std::filesystem::path> checkpoint;
  if (record.stopped) {
    code = kExitInterrupted + signal_number;
    try {
      if (writer) checkpoint = writer->write(s.sim, record);
    } catch (const std::exception& e) {
      print_error(e.what());
    }
  }
  if (s.out_dir) {
    try {
      write_run_summary(s, record);
    } catch (const std::exception& e) {
      print_error(e.what());
      code = code == kExitOk ? kExitOutput : code;
    }
  }
  if (!s.quiet) print_result(s.file, record, s.threads, s.out_dir ? &*s.out_dir : nullptr);
  if (record.stopped) print_interrupted(signal_number, record, checkpoint);
  std::printf("digest: %s\n", io::digest_hex(record.digest).c_str());
  std::fflush(stdout);
  return code;
}

}  // namespace

int execute_run(RunSession& s) {
  std::optional<io::CheckpointWriter> writer;
  if (s.out_dir) writer.emplace(*s.out_dir, s.checkpoints.keep, run_state(s));
  io::CheckpointWriter* checkpoints = writer ? &*writer : nullptr;
  io::InterruptGuard interrupt;
  io::RunRecord record;
  try {
    record = step_session(s, interrupt, checkpoints);
  } catch (const std::exception& e) {
    print_error(std::string("writing output: ") + e.what());
    return kExitOutput;
  }
  return finish_session(s, record, interrupt.signal_number(), checkpoints);
}

}  // namespace papertear::cli
