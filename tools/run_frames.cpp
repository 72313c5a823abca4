#include "tools/run_frames.hpp"

#include <algorithm>
#include <chrono>

namespace papertear::io {
namespace {

// Steps between progress redraws: small enough for a smooth bar, large enough that the
// per-call overhead of step() does not show. Chunking never changes the result: step(n)
// is n single steps.
std::int64_t progress_chunk(std::int64_t total_steps) {
  return std::max<std::int64_t>(1, total_steps / 200);
}

enum class Outcome { Reached, Stopped, BlewUp };

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// One call of run_frames: steps frame by frame, keeps the record's times current (a
// checkpoint stores them) and writes checkpoints between steps and after frames.
class FrameLoop {
 public:
  FrameLoop(Simulation& sim, const FramePlan& plan, const RunControl& control, Progress* progress,
            RunRecord& record)
      : sim_(sim), plan_(plan), control_(control), progress_(progress), record_(record),
        chunk_(progress_chunk(plan.end_step - plan.first_step)), wall_before_(record.wall_seconds),
        resumed_at_(sim.steps_done()) {}

  bool stop_requested() const { return control_.stop && *control_.stop != 0; }

  // Steps up to `end` (absolute step count). Checkpoints falling before `end` are written
  // here; one at `end` is left to after_frame, which comes after the frame is measured.
  Outcome step_until(std::int64_t end) {
    try {
      while (sim_.steps_done() < end) {
        if (stop_requested()) return Outcome::Stopped;
        const auto step_start = std::chrono::steady_clock::now();
        sim_.step(static_cast<int>(next_pause(end) - sim_.steps_done()));
        record_.step_seconds += seconds_since(step_start);
        if (progress_) progress_->steps_done(sim_.steps_done() - plan_.first_step);
        if (sim_.steps_done() < end) checkpoint_if_due(sim_.steps_done());
      }
      return Outcome::Reached;
    } catch (const BlowUpError& e) {
      record_.failure = RunFailure{e.what(), e.step, e.node};
      return Outcome::BlewUp;
    }
  }

  void after_frame(std::int64_t end) {
    if (end > resumed_at_) checkpoint_if_due(end);
  }

  void update_wall_time() { record_.wall_seconds = wall_before_ + seconds_since(start_); }

 private:
  // The next step at which stepping pauses: the frame's end, the next progress update, the
  // next checkpoint. With a stop flag, every step: the flag is read between steps.
  std::int64_t next_pause(std::int64_t end) const {
    const std::int64_t now = sim_.steps_done();
    std::int64_t next = std::min(end, now + (control_.stop ? 1 : chunk_));
    if (control_.checkpoint_every > 0)
      next = std::min(next, (now / control_.checkpoint_every + 1) * control_.checkpoint_every);
    return next;
  }

  void checkpoint_if_due(std::int64_t step) {
    if (control_.checkpoint_every <= 0 || !control_.on_checkpoint || step % control_.checkpoint_every != 0) return;
    update_wall_time();
    control_.on_checkpoint(sim_, record_);
  }

  Simulation& sim_;
  const FramePlan& plan_;
  const RunControl& control_;
  Progress* progress_;
  RunRecord& record_;
  const std::int64_t chunk_;
  const double wall_before_;
  const std::int64_t resumed_at_;
  const std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace

std::int64_t frame_end_step(std::int64_t steps, int frames, int frame) {
  if (frames <= 0) return steps;
  // (frame + 1) * steps can exceed 64 bits only for absurd step counts that validate()
  // already refuses.
  return (std::int64_t(frame) + 1) * steps / frames;
}

FramePlan FramePlan::for_run(const RunParams& run, std::int64_t first_step) {
  // A frame ends on a later step than the one before it: no more frames than steps.
  return {first_step, first_step + run.steps, run.steps, std::clamp(run.frames, 1, std::max(run.steps, 1))};
}

int FramePlan::frame_count() const {
  const std::int64_t steps = end_step - first_step;
  if (steps == spacing_steps) return spacing_frames;
  if (spacing_steps <= 0 || steps <= 0) return 1;
  // The first frame whose spaced end reaches end_step is the last.
  const std::int64_t n = (steps * spacing_frames + spacing_steps - 1) / spacing_steps;
  return static_cast<int>(std::max<std::int64_t>(n, 1));
}

std::int64_t FramePlan::frame_end(int frame) const {
  if (spacing_steps <= 0) return end_step;
  return first_step + std::min(end_step - first_step, frame_end_step(spacing_steps, spacing_frames, frame));
}

RunRecord run_frames(Simulation& sim, std::span<FrameSink* const> sinks, Progress* progress) {
  return run_frames(sim, sinks, progress, FramePlan::for_run(sim.scene().run, sim.steps_done()), {});
}

RunRecord run_frames(Simulation& sim, std::span<FrameSink* const> sinks, Progress* progress,
                     const FramePlan& plan, const RunControl& control, RunRecord so_far) {
  RunRecord record = std::move(so_far);
  record.failure.reset();
  record.stopped = false;
  record.steps_planned = plan.end_step - plan.first_step;
  FrameLoop loop(sim, plan, control, progress, record);
  const int frames = plan.frame_count();
  for (FrameSink* sink : sinks) sink->on_start(sim);
  for (int f = static_cast<int>(record.frames.size()); f < frames; ++f) {
    const std::int64_t end = plan.frame_end(f);
    const Outcome outcome = loop.step_until(end);
    if (outcome != Outcome::Reached) {
      record.stopped = outcome == Outcome::Stopped;
      break;
    }
    Metrics metrics = measure(sim.world());
    record.frames.push_back(metrics);
    for (FrameSink* sink : sinks) sink->on_frame(sim, f, frames, metrics);
    if (progress) progress->frame_done(f, metrics);
    loop.after_frame(end);
    if (f + 1 < frames && loop.stop_requested()) {
      record.stopped = true;
      break;
    }
  }
  if (progress) progress->finish();
  record.steps_done = sim.steps_done() - plan.first_step;
  record.digest = sim.digest();
  record.dt = sim.dt();
  record.time = sim.time();
  loop.update_wall_time();
  for (FrameSink* sink : sinks) sink->on_finish(sim, record);
  return record;
}

}  // namespace papertear::io
