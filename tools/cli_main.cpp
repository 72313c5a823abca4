// The `papertear` program: command-line parsing (CLI11) and dispatch to the subcommands.
#include <CLI/CLI.hpp>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "tools/commands.hpp"

#ifndef PAPERTEAR_VERSION
#define PAPERTEAR_VERSION "unknown"
#endif

namespace papertear::cli {

namespace {

// An option given as an empty string ("--out ''") is a mistake, not "no directory".
const CLI::Validator kNotEmpty(
    [](std::string& value) { return value.empty() ? std::string("must not be empty") : std::string(); }, "", "not empty");

constexpr const char* kSetHelp =
    "Override a scene key by its dotted name, e.g. --set sheet.cells=[30,30,5] "
    "--set material.grain=y (a TOML value; a bare word is a string). Repeatable.";

void add_scene_options(CLI::App& cmd, SceneOptions& o) {
  cmd.add_option("scene", o.scene_path,
                 "Scene file (TOML). Without one: the built-in default, the paper's experiment");
  cmd.add_option("--set", o.sets, kSetHelp)->type_name("KEY=VALUE")->allow_extra_args(false);
  cmd.add_option("--threads", o.threads, "Worker threads (0: all hardware threads)")
      ->check(CLI::Range(0, papertear::limits::kMaxThreads))
      ->default_val(0);
}

void add_checkpoint_options(CLI::App& cmd, CheckpointOptions& o) {
  cmd.add_option("--checkpoint-every", o.every,
                 "Write DIR/checkpoints/step_N.ptck every N steps (needs --out; 0: none). "
                 "Ctrl-C always leaves one when there is an output directory")
      ->type_name("N")
      ->check(CLI::NonNegativeNumber)
      ->default_val(0);
  cmd.add_option("--keep-checkpoints", o.keep,
                 "Keep only the newest K checkpoints this run wrote (0: keep all)")
      ->type_name("K")
      ->check(CLI::NonNegativeNumber)
      ->default_val(3);
}

void add_sweep_options(CLI::App& cmd, SweepOptions& o) {
  cmd.add_option("sweep_file", o.sweep_file, "Sweep file (TOML): base scene, seeds, [set], [grid] or [[point]]")
      ->required();
  cmd.add_option("--out", o.out_dir, "Output directory: points/, sweep.csv, sweep.json, plots/")
      ->type_name("DIR")
      ->check(kNotEmpty);
  cmd.add_option("--index", o.index, "Run point I only and write DIR/points/point_I.json (a job-array task)")
      ->type_name("I");
  cmd.add_flag("--count", o.count, "Print the number of points and exit");
  cmd.add_option("--collect", o.collect_dir,
                 "Merge DIR/points/*.json into DIR/sweep.csv, sweep.json and plots/; fails naming missing points")
      ->type_name("DIR");
  cmd.add_option("--jobs,-j", o.jobs, "Points run at a time (0: hardware threads / --threads)")
      ->check(CLI::Range(0, papertear::limits::kMaxThreads))
      ->default_val(0);
  cmd.add_option("--threads", o.threads,
                 "Worker threads per point (0: 1 for a whole sweep, all hardware threads with --index)")
      ->check(CLI::Range(0, papertear::limits::kMaxThreads))
      ->default_val(0);
  cmd.add_flag("--quiet,-q", o.quiet, "No progress lines");
}

// What a command printed on stdout (the digest line, info's table) is its result: when it
// cannot be written (a full disk, a closed pipe), the command failed.
int finish_stdout(int code) {
  if (std::fflush(stdout) == 0 && !std::ferror(stdout)) return code;
  print_error(std::string("cannot write the result to standard output (") + std::strerror(errno) + ")");
  return code == kExitOk ? kExitOutput : code;
}

}  // namespace

}  // namespace papertear::cli

int main(int argc, char** argv) {
  using namespace papertear::cli;
  CLI::App app("papertear: paper tearing for computer graphics (multi-layer mass-spring lattice)",
               "papertear");
  app.set_version_flag("--version", PAPERTEAR_VERSION);
  app.require_subcommand(1);
  app.footer(
      "Exit codes: 0 done, 1 bad input (nothing written), 2 the simulation blew up "
      "(summary.json still written), 3 an output file could not be written, 130 (143) stopped by "
      "Ctrl-C (SIGTERM) after a whole step (a checkpoint and summary.json written with --out).");

  RunOptions run;
  CLI::App* run_cmd = app.add_subcommand("run", "Run a scene; print the state digest last");
  add_scene_options(*run_cmd, run.scene);
  run_cmd->add_option("--out", run.out_dir, "Output directory for summary.json (and frames)")
      ->type_name("DIR")
      ->check(kNotEmpty);
  run_cmd->add_option("--steps", run.steps, "Number of steps (overrides run.steps)");
  run_cmd->add_option("--frames", run.frames, "Number of frames (overrides run.frames)");
  run_cmd->add_flag("--quiet,-q", run.quiet, "Print only errors and the final digest line");
  add_checkpoint_options(*run_cmd, run.checkpoints);

  ResumeOptions resume;
  CLI::App* resume_cmd = app.add_subcommand(
      "resume", "Continue a run from a checkpoint to its planned end (or --steps N more); print the "
                "digest last");
  resume_cmd->add_option("checkpoint", resume.checkpoint, "Checkpoint file (DIR/checkpoints/step_N.ptck)")
      ->required();
  resume_cmd->add_option("--steps", resume.steps, "Run N more steps instead of finishing the planned run")
      ->type_name("N")
      ->check(CLI::NonNegativeNumber);
  resume_cmd->add_option("--out", resume.out_dir,
                         "Output directory (default: DIR of DIR/checkpoints/step_N.ptck, the run's own)")
      ->type_name("DIR")
      ->check(kNotEmpty);
  resume_cmd->add_option("--threads", resume.threads, "Worker threads (0: all hardware threads)")
      ->check(CLI::Range(0, papertear::limits::kMaxThreads))
      ->default_val(0);
  resume_cmd->add_flag("--quiet,-q", resume.quiet, "Print only errors and the final digest line");
  add_checkpoint_options(*resume_cmd, resume.checkpoints);

  SceneOptions info;
  CLI::App* info_cmd = app.add_subcommand(
      "info", "Sizes, memory, time step and estimated run time of a scene, from a few timed steps");
  add_scene_options(*info_cmd, info);

  CalibrateOptions calibrate;
  CLI::App* calibrate_cmd = app.add_subcommand(
      "calibrate", "Tensile and Elmendorf-style tear tests of the material presets along and across the "
                   "grain; prints the MD/CD ratios beside the published ranges");
  calibrate_cmd->add_option("--preset", calibrate.presets, "A preset to test (repeatable; default: all)");
  calibrate_cmd->add_option("--seeds", calibrate.seeds, "Seeds per test (1..N)")
      ->check(CLI::Range(1, 1000))
      ->default_val(3);
  calibrate_cmd->add_flag("--quick", calibrate.quick, "Small specimens: faster, noisier");
  calibrate_cmd->add_option("--out", calibrate.out_dir, "Write calibration.md and calibration.json here")
      ->type_name("DIR")
      ->check(kNotEmpty);
  calibrate_cmd->add_option("--threads", calibrate.threads, "Worker threads (0: all hardware threads)")
      ->check(CLI::Range(0, papertear::limits::kMaxThreads))
      ->default_val(0);
  calibrate_cmd->add_flag("--quiet,-q", calibrate.quiet, "Print only errors and the table");

  SweepOptions sweep;
  CLI::App* sweep_cmd = app.add_subcommand(
      "sweep", "Run a parameter study: a grid or list of scene overrides x seeds; one row per run in "
               "DIR/sweep.csv and DIR/sweep.json, plots in DIR/plots (docs/sweeps.md)");
  add_sweep_options(*sweep_cmd, sweep);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    print_error(std::string(e.what()) + " (see papertear --help)");
    return kExitBadInput;
  }
  int code = kExitOk;
  if (run_cmd->parsed())
    code = run_command(run);
  else if (resume_cmd->parsed())
    code = resume_command(resume);
  else if (calibrate_cmd->parsed())
    code = calibrate_command(calibrate);
  else if (sweep_cmd->parsed())
    code = sweep_command(sweep);
  else
    code = info_command(info);
  return finish_stdout(code);
}
