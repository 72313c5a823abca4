// Progress of a run, written to a stream (the CLI uses stderr, keeping stdout for results):
// a redrawn bar with ETA on a terminal, one plain line per frame in logs and pipes, nothing
// with --quiet.
#pragma once
#include <chrono>
#include <cstdint>
#include <iosfwd>
#include <string>

#include "fracture/metrics.hpp"

namespace papertear::io {

enum class ProgressStyle { Silent, Lines, Bar };

// Bar when `fd` is a terminal, Lines when not, Silent when quiet.
ProgressStyle choose_progress_style(bool quiet, int fd);

// "42s", "3m07s", "1h02m".
std::string format_duration(double seconds);

class Progress {
 public:
  Progress(ProgressStyle style, std::ostream& out, std::int64_t total_steps, int total_frames);

  // Steps done so far in the whole run. Redraws the bar, at most ten times a second.
  void steps_done(std::int64_t steps);
  // A finished frame (0-based). In Lines style, one line per frame.
  void frame_done(int frame, const Metrics& metrics);
  // Ends the bar's line so that later output starts on a fresh one.
  void finish();

 private:
  using Clock = std::chrono::steady_clock;
  double elapsed() const;
  std::string eta(std::int64_t steps) const;
  void draw_bar(std::int64_t steps);

  ProgressStyle style_;
  std::ostream& out_;
  std::int64_t total_steps_;
  int total_frames_;
  int frames_done_ = 0;
  std::int64_t steps_done_ = 0;
  Clock::time_point start_ = Clock::now();
  Clock::time_point last_draw_{};
  bool bar_drawn_ = false;
};

}  // namespace papertear::io
