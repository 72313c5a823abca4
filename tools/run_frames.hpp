// The run loop shared by the CLI and embedders that want frames: steps a Simulation through
// its scene's run.steps, cut into run.frames frames, measuring after each frame and handing
// the frame to every FrameSink. A blow-up ends the run but not the record: the frames
// measured so far and the failure are kept, so that the summary can still be written.
// A run can also be stopped between steps (Ctrl-C), write checkpoints as it goes, and be
// continued from a checkpoint with the frames it had measured (tools/run_checkpoints.hpp).
#pragma once
#include <csignal>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/simulation.hpp"
#include "fracture/metrics.hpp"
#include "tools/frame_sink.hpp"
#include "tools/progress.hpp"

namespace papertear::io {

// Why a run stopped early (papertear::BlowUpError).
struct RunFailure {
  std::string message;
  std::int64_t step = 0;
  std::uint32_t node = 0;
};

struct RunRecord {
  std::vector<Metrics> frames;         // one per finished frame, in order
  std::optional<RunFailure> failure;   // set when the run blew up
  bool stopped = false;                // the run was stopped early (RunControl::stop)
  std::int64_t steps_planned = 0;      // counted from the plan's first step
  std::int64_t steps_done = 0;         // likewise, so a resumed run counts the steps before it
  std::uint64_t digest = 0;            // Simulation::digest() at the end
  double dt = 0.0;                     // the step used (resolved from run.dt)
  double time = 0.0;                   // simulated time at the end
  double wall_seconds = 0.0;           // the whole loop: stepping, measuring and sinks
  double step_seconds = 0.0;           // stepping alone (both include a resumed run's past)
};

// The step count at which frame `frame` (0-based) of `frames` ends: the steps are spread
// evenly (frame lengths differ by at most one) and the last frame ends at `steps`.
std::int64_t frame_end_step(std::int64_t steps, int frames, int frame);

// Where the frames of a run end, in absolute step counts. A run's plan is fixed when it
// starts (for_run); a resumed run keeps it, so its frames end where those of a run that
// never stopped do. Given another end step (resume --steps), the frames keep their spacing
// and the last one ends at end_step.
struct FramePlan {
  std::int64_t first_step = 0;     // the step the run started from
  std::int64_t end_step = 0;       // the step it stops at
  std::int64_t spacing_steps = 0;  // frames are spaced as spacing_frames frames over
  int spacing_frames = 1;          // spacing_steps steps (the scene's run.steps, run.frames)

  // run.steps steps from `first_step` in run.frames frames.
  static FramePlan for_run(const RunParams& run, std::int64_t first_step);
  int frame_count() const;
  std::int64_t frame_end(int frame) const;  // 0-based frame
};

// How a run may end early and what it does between steps.
struct RunControl {
  // Set asynchronously (by a signal handler, hence volatile sig_atomic_t); when non-zero, the
  // run stops after the step in progress and the record says `stopped`. Null: never stops.
  const volatile std::sig_atomic_t* stop = nullptr;
  // Called at every step that is a multiple of checkpoint_every (0: never), after the frame
  // ending at that step (if any) has been measured. Its exceptions propagate.
  std::int64_t checkpoint_every = 0;
  std::function<void(const Simulation&, const RunRecord&)> on_checkpoint;
};

// Runs sim.scene().run.steps steps (counted from the simulation's current step) in
// sim.scene().run.frames frames. `progress` may be null. Sink exceptions propagate.
RunRecord run_frames(Simulation& sim, std::span<FrameSink* const> sinks, Progress* progress);
// The same for any plan. `so_far` holds what a resumed run measured before it stopped: the
// loop goes on from frame so_far.frames.size() and adds to its times. Chunking the steps
// differently (for progress, checkpoints or a stop flag) never changes the result.
RunRecord run_frames(Simulation& sim, std::span<FrameSink* const> sinks, Progress* progress,
                     const FramePlan& plan, const RunControl& control, RunRecord so_far = {});

}  // namespace papertear::io
