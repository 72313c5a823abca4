// Stopping a run and continuing it: the checkpoints `papertear run --checkpoint-every N`
// writes, what the CLI stores in them beside the world, and Ctrl-C.
//
// A checkpoint (core/checkpoint.hpp) holds the world and the application's bytes. The CLI's
// bytes are a RunState: the frame plan the run started with, the frames measured so far and
// the renderer's sections of the scene file. `papertear resume` reads it back, so a resumed
// run ends with the same digest and writes the same summary metrics as one that never
// stopped. Checkpoints go to DIR/checkpoints/step_NNNNNNNN.ptck (the absolute step, eight
// digits or more), written atomically; a run keeps the newest few it wrote (--keep-checkpoints).
#pragma once
#include <signal.h>

#include <csignal>
#include <deque>
#include <filesystem>
#include <string>
#include <string_view>

#include "core/simulation.hpp"
#include "tools/run_frames.hpp"

namespace papertear::io {

struct RunState {
  std::string scene_path;     // the scene file the run read; empty for the built-in default
  std::string render_config;  // the renderer's sections of the scene, as TOML text
  FramePlan plan;
  RunRecord record;           // frames measured so far and the time spent so far
};

// CBOR (nlohmann::json::to_cbor): doubles are stored exactly.
std::string encode_run_state(const RunState& state);
// Throws CheckpointError (kind Inconsistent) for bytes that are not a RunState.
RunState decode_run_state(std::string_view bytes);

std::filesystem::path checkpoint_path(const std::filesystem::path& out_dir, std::int64_t step);

// Writes a run's checkpoints into out_dir/checkpoints and deletes the older ones it wrote
// beyond the newest `keep` (0: keeps all). Files of earlier runs are never deleted.
class CheckpointWriter {
 public:
  CheckpointWriter(std::filesystem::path out_dir, int keep, RunState base);
  // Checkpoints the simulation's current step with the record so far; returns the file.
  // Throws OutputError naming the file.
  std::filesystem::path write(const Simulation& sim, const RunRecord& record);

 private:
  std::filesystem::path dir_;
  int keep_;
  RunState base_;
  std::deque<std::filesystem::path> written_;
};

// While alive, SIGINT and SIGTERM do not end the process: the first one sets flag() to the
// signal's number, which the run loop reads between steps (RunControl::stop), and puts back
// the default action, so that a second Ctrl-C ends the program at once. At most one guard
// may be alive at a time; the destructor restores the previous handlers.
class InterruptGuard {
 public:
  InterruptGuard();
  ~InterruptGuard();
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

  const volatile std::sig_atomic_t* flag() const;
  int signal_number() const;  // 0 while none has arrived

 private:
  struct sigaction old_int_{}, old_term_{};
};

}  // namespace papertear::io
