// The `papertear` program's subcommands. cli_main.cpp parses the command line into these
// options; each command returns the process exit code.
#pragma once
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/simulation.hpp"
#include "tools/frame_sink.hpp"
#include "tools/run_frames.hpp"
#include "tools/scene_file.hpp"

namespace papertear::cli {

enum ExitCode : int {
  kExitOk = 0,
  kExitBadInput = 1,  // bad command line, scene, parameter or output path: nothing written
  kExitBlowUp = 2,    // the simulation became non-finite: summary.json says where
  kExitOutput = 3,    // an output file could not be written during the run
  kExitInterrupted = 128,  // + the signal: 130 for Ctrl-C (SIGINT), 143 for SIGTERM; the run
                           // stopped after a whole step and left a checkpoint and summary.json
};

struct SceneOptions {
  std::string scene_path;         // empty: the built-in default scene
  std::vector<std::string> sets;  // --set key=value, applied in order
  int threads = 0;                // 0: all hardware threads
};

struct CheckpointOptions {
  int every = 0;  // --checkpoint-every: steps between checkpoints (0: none); needs an output dir
  int keep = 3;   // --keep-checkpoints: how many of the newest to keep (0: all)
};

struct RunOptions {
  SceneOptions scene;
  std::string out_dir;  // empty: write no files
  std::optional<int> steps, frames;
  bool quiet = false;
  CheckpointOptions checkpoints;
};

struct ResumeOptions {
  std::string checkpoint;    // the .ptck file
  std::optional<int> steps;  // run this many more steps instead of finishing the scene's run
  std::string out_dir;       // empty: the run directory the checkpoint is in (DIR of
                             // DIR/checkpoints/step_N.ptck), otherwise write no files
  int threads = 0;
  bool quiet = false;
  CheckpointOptions checkpoints;
};

struct CalibrateOptions {
  std::vector<std::string> presets;  // empty: every preset
  int seeds = 3;                     // seeds 1..N per test
  bool quick = false;                // small specimens (what the tests run)
  std::string out_dir;               // empty: print the table only
  int threads = 0;
  bool quiet = false;
};

// `papertear sweep` (tools/sweep_command.cpp, format in tools/sweep_file.hpp).
struct SweepOptions {
  std::string sweep_file;
  std::string out_dir;      // results: DIR/points/, sweep.csv, sweep.json, plots/
  std::string collect_dir;  // --collect: merge DIR/points/ instead of running
  std::optional<int> index; // run this point only
  bool count = false;       // print the number of points
  int jobs = 0;             // points at a time (0: hardware threads / threads per point)
  int threads = 0;          // workers per point (0: 1 for a whole sweep, all for --index)
  bool quiet = false;
};

int run_command(const RunOptions& options);
int calibrate_command(const CalibrateOptions& options);
int sweep_command(const SweepOptions& options);
int resume_command(const ResumeOptions& options);
int info_command(const SceneOptions& options);

// A run ready to step, checked and with its output directory created: `run` and `resume`
// both end in execute_run, which steps it through its plan (writing checkpoints and
// stopping cleanly on Ctrl-C), writes summary.json and prints the digest line last.
struct RunSession {
  io::SceneFile file;
  Simulation sim;
  std::vector<std::unique_ptr<io::FrameSink>> sinks;
  int threads = 0;
  std::optional<std::filesystem::path> out_dir;
  io::FramePlan plan;
  io::RunRecord so_far;  // what a resumed run measured before its checkpoint
  CheckpointOptions checkpoints;
  bool quiet = false;
};
int execute_run(RunSession& session);

// Loads the scene (or the default) with the --set overrides and then `extra` ones.
// Throws papertear::SceneError.
io::SceneFile resolve_scene(const SceneOptions& options,
                            const std::vector<io::SetOverride>& extra = {});
// The file's Simulation; a scene the constructor refuses (run.dt above the stable limit)
// gets its error located in the file like any other bad value. Throws SceneError.
Simulation make_simulation(const io::SceneFile& file, int threads);
// The worker count a Simulation given `requested` threads will use.
int resolved_threads(int requested);
// io::check_output_dir with the error naming the --out option. Throws io::OutputError.
void check_output_dir_option(const std::filesystem::path& dir);
// check_output_dir_option, and no file or directory a run writes (summary.json, frames/...)
// is in the way as the other kind. Throws io::OutputError.
void check_run_outputs(const std::filesystem::path& dir);
// Prints "papertear: error: <message>" on stderr.
void print_error(const std::string& message);

// The frame sinks of a run (tools/cli_frame_sinks.cpp): the renderer's PNG frames and meshes.
// Called after the scene is resolved and before the output directory is created; `out_dir`
// is null without --out (then no sinks, but the render sections are still checked).
// Each sink is checked against `sim` (FrameSink::check). Throws papertear::SceneError for a
// bad [render]/[output] section.
std::vector<std::unique_ptr<io::FrameSink>> make_frame_sinks(const io::SceneFile& scene, const Simulation& sim,
                                                             const std::filesystem::path* out_dir);

}  // namespace papertear::cli
