// `papertear sweep SWEEP.toml`: a parameter study (tools/sweep_file.hpp). Four modes:
//   --out DIR            every point, several at once, then the collect step below
//   --index I --out DIR  point I alone (for a batch system's job array)
//   --count              the number of points
//   --collect DIR        DIR/points/*.json -> DIR/sweep.csv, DIR/sweep.json, DIR/plots/*.png
// Every point is checked (its scene resolved) before anything is written. Points are
// independent runs, each on its own Simulation, so running them in parallel changes no bit.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <mutex>
#include <thread>

#include <oneapi/tbb/info.h>

#include "tools/commands.hpp"
#include "tools/output_files.hpp"
#include "tools/progress.hpp"
#include "tools/run_checkpoints.hpp"
#include "tools/summary.hpp"
#include "tools/sweep_plots.hpp"
#include "tools/sweep_results.hpp"

namespace papertear::cli {
namespace {

using Clock = std::chrono::steady_clock;

// A sweep file read and every point resolved: what all modes start from.
struct LoadedSweep {
  io::SweepDefinition sweep;
  std::vector<io::SceneFile> scenes;  // per point
  std::uint64_t hash = 0;
};

LoadedSweep load(const SweepOptions& o) {
  LoadedSweep s;
  s.sweep = io::load_sweep(o.sweep_file);
  for (const io::SweepPoint& p : s.sweep.points) s.scenes.push_back(io::resolve_point(s.sweep, p));
  s.hash = io::sweep_hash(s.sweep, s.scenes);
  return s;
}

void check_mode(const SweepOptions& o) {
  if (!o.collect_dir.empty() && (!o.out_dir.empty() || o.index))
    throw SceneError("--collect DIR reads the point files in DIR: give it without --out and --index");
  if (o.count && (!o.out_dir.empty() || o.index || !o.collect_dir.empty()))
    throw SceneError("--count only prints the number of points: give it alone");
  if (!o.count && o.collect_dir.empty() && o.out_dir.empty())
    throw SceneError("sweep needs --out DIR for its results (or --count, or --collect DIR)");
}

std::string point_label(const io::Row& row, const std::vector<std::string>& keys) {
  std::string label = "seed " + row["seed"].dump();
  for (const std::string& k : keys) label += ", " + k + "=" + row[k].dump();
  return label;
}

// --- running points ---------------------------------------------------------------------

struct PointOutcome {
  io::Row row;
  bool stopped = false;  // interrupted: no result, no file
  double wall_seconds = 0.0;
};

PointOutcome run_point(const LoadedSweep& s, int index, int threads, const volatile std::sig_atomic_t* stop) {
  const io::SweepPoint& point = s.sweep.points[index];
  const Scene& scene = s.scenes[index].scene;
  const Clock::time_point start = Clock::now();
  PointOutcome out;
  try {
    Simulation sim(scene, {.threads = threads});  // refuses a run.dt above the stable limit
    io::RunControl control;
    control.stop = stop;
    const io::RunRecord record = io::run_frames(sim, {}, nullptr, io::FramePlan::for_run(scene.run, 0), control);
    out.stopped = record.stopped;
    out.row = io::point_row(s.sweep, point, scene, record);
  } catch (const std::exception& e) {
    out.row = io::failed_row(s.sweep, point, scene, e.what());
  }
  out.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return out;
}

// Points done / total on stderr: a redrawn line on a terminal, a line per point otherwise.
class SweepProgress {
 public:
  SweepProgress(bool quiet, int total, const std::vector<std::string>& keys)
      : style_(io::choose_progress_style(quiet, STDERR_FILENO)), total_(total), keys_(keys) {}

  void point_done(const PointOutcome& p) {
    std::lock_guard lock(mutex_);
    ++done_;
    const double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
    const std::string left = io::format_duration(elapsed / done_ * (total_ - done_));
    if (style_ == io::ProgressStyle::Bar) {
      std::cerr << "\rsweep: " << done_ << "/" << total_ << " points done, " << left << " left   " << std::flush;
    } else if (style_ == io::ProgressStyle::Lines) {
      std::cerr << "sweep: " << done_ << "/" << total_ << " points done: point " << p.row["index"].dump() << " ("
                << point_label(p.row, keys_) << ") " << p.row["status"].get<std::string>() << " in "
                << io::format_duration(p.wall_seconds) << std::endl;
    }
  }
  void finish() {
    if (style_ == io::ProgressStyle::Bar && done_ > 0) std::cerr << std::endl;
  }

 private:
  io::ProgressStyle style_;
  int total_;
  const std::vector<std::string>& keys_;
  int done_ = 0;
  Clock::time_point start_ = Clock::now();
  std::mutex mutex_;
};

struct PoolResult {
  int written = 0;
  std::vector<std::string> write_errors;
};

// Runs every point on `jobs` threads, each point on a Simulation of `threads` workers, and
// writes each point's file as soon as it is done.
PoolResult run_all_points(const LoadedSweep& s, const std::filesystem::path& dir, int jobs, int threads,
                          const volatile std::sig_atomic_t* stop, SweepProgress& progress) {
  const int count = static_cast<int>(s.sweep.points.size());
  std::atomic<int> next{0};
  std::mutex mutex;
  PoolResult result;
  auto worker = [&] {
    for (int i = next++; i < count && !*stop; i = next++) {
      PointOutcome p = run_point(s, i, threads, stop);
      if (p.stopped) return;
      try {
        io::write_point_file(dir, s.hash, count, p.row, p.wall_seconds, threads);
        std::lock_guard lock(mutex);
        ++result.written;
      } catch (const std::exception& e) {
        std::lock_guard lock(mutex);
        result.write_errors.push_back(e.what());
      }
      progress.point_done(p);
    }
  };
  std::vector<std::thread> pool;
  for (int j = 0; j < std::min(jobs, count); ++j) pool.emplace_back(worker);
  for (std::thread& t : pool) t.join();
  progress.finish();
  return result;
}

int default_jobs(int threads) { return std::max(1, tbb::info::default_concurrency() / std::max(1, threads)); }

// --- collecting -------------------------------------------------------------------------

void report_failures(const std::vector<io::Row>& rows, const std::vector<std::string>& keys) {
  for (const io::Row& r : rows)
    if (!io::row_completed(r))
      print_error("point " + r["index"].dump() + " (" + point_label(r, keys) + ") " +
                  r["status"].get<std::string>() + ": " + r.value("error", std::string()));
}

// DIR/points -> sweep.csv, sweep.json and the plots. Shared by the whole sweep and --collect.
int collect(const LoadedSweep& s, const std::filesystem::path& dir) {
  const int count = static_cast<int>(s.sweep.points.size());
  std::vector<io::Row> rows;
  try {
    if (!std::filesystem::is_directory(dir / "points"))
      throw SceneError((dir / "points").string() + ": no such directory: nothing to collect (run the "
                       "points with --index I --out " + dir.string() + " first)");
    rows = io::read_point_files(dir, s.hash, count);
  } catch (const SceneError& e) {
    print_error(e.what());
    return kExitBadInput;
  }
  try {
    io::write_file_atomically(dir / "sweep.csv", io::rows_csv(rows));
    io::write_file_atomically(dir / "sweep.json", io::rows_json(s.sweep, s.hash, rows));
  } catch (const std::exception& e) {
    print_error(e.what());
    return kExitOutput;
  }
  const io::PlotOutcome plots = io::write_sweep_plots(dir, s.sweep.keys, rows);
  if (!plots.warning.empty()) std::cerr << "papertear: warning: " << plots.warning << std::endl;
  const auto completed = std::count_if(rows.begin(), rows.end(), io::row_completed);
  report_failures(rows, s.sweep.keys);
  std::printf("sweep: %d points, %lld completed, %lld failed\n", count, static_cast<long long>(completed),
              static_cast<long long>(count - completed));
  std::printf("csv: %s\njson: %s\n", (dir / "sweep.csv").c_str(), (dir / "sweep.json").c_str());
  if (!plots.written.empty()) std::printf("plots: %zu in %s\n", plots.written.size(), (dir / "plots").c_str());
  std::fflush(stdout);
  return completed == count ? kExitOk : kExitBlowUp;
}

// --- the modes ---------------------------------------------------------------------------

int run_one(const LoadedSweep& s, const SweepOptions& o, const std::filesystem::path& dir) {
  const int threads = resolved_threads(o.threads);
  io::InterruptGuard interrupt;
  PointOutcome p = run_point(s, *o.index, threads, interrupt.flag());
  if (p.stopped) {
    std::cerr << "papertear: point " << *o.index << " interrupted; nothing written" << std::endl;
    return kExitInterrupted + interrupt.signal_number();
  }
  try {
    io::write_point_file(dir, s.hash, static_cast<int>(s.sweep.points.size()), p.row, p.wall_seconds, threads);
  } catch (const std::exception& e) {
    print_error(e.what());
    return kExitOutput;
  }
  const bool ok = io::row_completed(p.row);
  if (!ok) report_failures({p.row}, s.sweep.keys);
  std::printf("point %d of %zu (%s): %s in %s\n", *o.index, s.sweep.points.size(),
              point_label(p.row, s.sweep.keys).c_str(), p.row["status"].get<std::string>().c_str(),
              io::format_duration(p.wall_seconds).c_str());
  std::printf("file: %s\n", io::point_file(dir, *o.index).c_str());
  if (p.row.contains("digest")) std::printf("digest: %s\n", p.row["digest"].get<std::string>().c_str());
  std::fflush(stdout);
  return ok ? kExitOk : kExitBlowUp;
}

int run_whole(const LoadedSweep& s, const SweepOptions& o, const std::filesystem::path& dir) {
  const int threads = o.threads > 0 ? o.threads : 1;
  const int jobs = o.jobs > 0 ? o.jobs : default_jobs(threads);
  const int count = static_cast<int>(s.sweep.points.size());
  if (!o.quiet)
    std::cerr << "sweep: " << count << " points, " << std::min(jobs, count) << " at a time on " << threads
              << (threads == 1 ? " thread" : " threads") << " each" << std::endl;
  io::InterruptGuard interrupt;
  SweepProgress progress(o.quiet, count, s.sweep.keys);
  const PoolResult pool = run_all_points(s, dir, jobs, threads, interrupt.flag(), progress);
  for (const std::string& e : pool.write_errors) print_error(e);
  if (interrupt.signal_number() != 0) {
    std::cerr << "papertear: sweep interrupted: " << pool.written << " of " << count << " point files written to "
              << (dir / "points").string() << "; run the missing points with --index I, then --collect "
              << dir.string() << std::endl;
    return kExitInterrupted + interrupt.signal_number();
  }
  if (!pool.write_errors.empty()) return kExitOutput;
  return collect(s, dir);
}

}  // namespace

int sweep_command(const SweepOptions& o) {
  std::optional<LoadedSweep> s;
  std::filesystem::path dir = o.collect_dir.empty() ? o.out_dir : o.collect_dir;
  try {
    check_mode(o);
    s.emplace(load(o));
    const int count = static_cast<int>(s->sweep.points.size());
    if (o.index && (*o.index < 0 || *o.index >= count))
      throw SceneError("--index " + std::to_string(*o.index) + " is out of range: the sweep has " +
                       std::to_string(count) + " points, 0.." + std::to_string(count - 1));
    if (!o.out_dir.empty()) {
      check_output_dir_option(dir);
      io::create_output_dir(dir / "points");
    }
  } catch (const std::exception& e) {
    print_error(e.what());
    return kExitBadInput;
  }
  if (o.count) {
    std::printf("%zu\n", s->sweep.points.size());
    return kExitOk;
  }
  if (!o.collect_dir.empty()) return collect(*s, dir);
  if (o.index) return run_one(*s, o, dir);
  return run_whole(*s, o, dir);
}

}  // namespace papertear::cli
