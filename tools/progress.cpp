#include "tools/progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ostream>

namespace papertear::io {

ProgressStyle choose_progress_style(bool quiet, int fd) {
  if (quiet) return ProgressStyle::Silent;
  return isatty(fd) ? ProgressStyle::Bar : ProgressStyle::Lines;
}

std::string format_duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  char buf[32];
  auto s = static_cast<long long>(std::llround(seconds));
  if (seconds < 10)
    std::snprintf(buf, sizeof buf, "%.1fs", seconds);
  else if (s < 60)
    std::snprintf(buf, sizeof buf, "%llds", s);
  else if (s < 3600)
    std::snprintf(buf, sizeof buf, "%lldm%02llds", s / 60, s % 60);
  else
    std::snprintf(buf, sizeof buf, "%lldh%02lldm", s / 3600, (s / 60) % 60);
  return buf;
}

Progress::Progress(ProgressStyle style, std::ostream& out, std::int64_t total_steps,
                   int total_frames)
    : style_(style), out_(out), total_steps_(std::max<std::int64_t>(total_steps, 0)),
      total_frames_(total_frames) {}

double Progress::elapsed() const {
  return std::chrono::duration<double>(Clock::now() - start_).count();
}

// Assumes the remaining steps cost what the finished ones did on average; fracture makes
// late steps a little slower, so this is an estimate, not a promise.
std::string Progress::eta(std::int64_t steps) const {
  if (steps <= 0) return "?";
  return format_duration(elapsed() * double(total_steps_ - steps) / double(steps));
}

void Progress::steps_done(std::int64_t steps) {
  steps_done_ = steps;
  if (style_ != ProgressStyle::Bar) return;
  auto now = Clock::now();
  if (bar_drawn_ && now - last_draw_ < std::chrono::milliseconds(100) && steps < total_steps_)
    return;
  last_draw_ = now;
  draw_bar(steps);
}

void Progress::draw_bar(std::int64_t steps) {
  constexpr int kWidth = 30;
  double fraction = total_steps_ > 0 ? double(steps) / double(total_steps_) : 1.0;
  int filled = static_cast<int>(fraction * kWidth);
  std::string bar(std::size_t(filled), '#');
  bar.resize(kWidth, '.');
  char pct[8];
  std::snprintf(pct, sizeof pct, "%3d%%", static_cast<int>(fraction * 100.0));
  // \r returns to the line start, \x1b[K clears what a longer previous line left behind.
  out_ << '\r' << pct << " [" << bar << "] step " << steps << '/' << total_steps_ << "  frame "
       << frames_done_ << '/' << total_frames_ << "  " << format_duration(elapsed())
       << " elapsed, ETA " << eta(steps) << "\x1b[K" << std::flush;
  bar_drawn_ = true;
}

void Progress::frame_done(int frame, const Metrics& metrics) {
  frames_done_ = frame + 1;
  if (style_ != ProgressStyle::Lines) return;
  out_ << "frame " << frames_done_ << '/' << total_frames_ << "  step " << metrics.step << '/'
       << total_steps_ << "  splits " << metrics.splits_inplane + metrics.splits_interlayer
       << "  pieces " << metrics.pieces << "  elapsed " << format_duration(elapsed())
       << "  ETA " << eta(metrics.step) << '\n'
       << std::flush;
}

void Progress::finish() {
  if (style_ != ProgressStyle::Bar || !bar_drawn_) return;
  draw_bar(steps_done_);  // the last frame finished after the last redraw
  out_ << '\n' << std::flush;
  bar_drawn_ = false;
}

}  // namespace papertear::io
