// The hook through which a run hands out its frames. The run loop (tools/run_frames.hpp)
// cuts run.steps into run.frames frames; after each frame it measures the world and calls
// every sink. The renderer writes PNG frames and meshes through this interface; the CLI
// creates its sinks in tools/cli_frame_sinks.cpp.
//
// Contract for a sink:
//  * its constructor checks its configuration and throws papertear::SceneError for bad
//    input, but writes nothing: the CLI creates the output directory only after every
//    sink has been constructed, so bad input leaves no files behind;
//  * check() runs before the output directory is created, with the simulation built: what
//    needs the sheet (a camera fitted to it) is checked there, so that it fails before
//    the first step and not at the first frame;
//  * on_start() runs once the output directory exists, before the first step;
//  * on_frame() gets the simulation paused after the frame's last step (read-only views
//    are valid until the call returns) and that frame's metrics;
//  * on_finish() runs once at the end, also after a blow-up (then record.failure is set and
//    the state may hold non-finite values: do not render it).
// Exceptions thrown by a sink end the run and are reported as output errors.
#pragma once

#include "core/simulation.hpp"
#include "fracture/metrics.hpp"

namespace papertear::io {

struct RunRecord;

class FrameSink {
 public:
  virtual ~FrameSink() = default;
  virtual void check(const Simulation& sim) const { (void)sim; }
  virtual void on_start(const Simulation& sim) { (void)sim; }
  // `frame` counts from 0 to frames - 1, the frames of the run's plan (run.frames, or more
  // when a resumed run goes on past it: resume --steps).
  virtual void on_frame(const Simulation& sim, int frame, int frames, const Metrics& metrics) = 0;
  virtual void on_finish(const Simulation& sim, const RunRecord& record) {
    (void)sim;
    (void)record;
  }
};

}  // namespace papertear::io
