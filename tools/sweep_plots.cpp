#include "tools/sweep_plots.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <optional>
#include <sstream>

#include "tools/output_files.hpp"

namespace papertear::io {
namespace {

// More seeds than this share one colour: a legend of fifty seeds helps nobody.
constexpr std::size_t kMaxSeedSeries = 10;

std::optional<std::filesystem::path> find_gnuplot() {
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "");
  for (std::string dir; std::getline(dirs, dir, ':');) {
    if (dir.empty()) continue;
    std::filesystem::path candidate = std::filesystem::path(dir) / "gnuplot";
    if (access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return std::nullopt;
}

// A gnuplot string literal: single quotes, in which only '' needs escaping.
std::string gp_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

std::string label_of(const Row& v) { return v.is_string() ? v.get<std::string>() : v.dump(); }

std::string number(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// Where each value of a key goes on the x axis.
struct Axis {
  bool numeric = true;
  std::vector<std::string> labels;  // categorical: the values in order of first appearance
  std::size_t distinct = 0;
  double x(const Row& v) const {
    if (numeric) return v.get<double>();
    return double(std::find(labels.begin(), labels.end(), label_of(v)) - labels.begin());
  }
};

Axis make_axis(const std::string& key, const std::vector<const Row*>& rows) {
  Axis axis;
  std::vector<std::string> seen;
  for (const Row* r : rows) {
    const Row& v = (*r)[key];
    axis.numeric = axis.numeric && v.is_number();
    if (std::find(seen.begin(), seen.end(), label_of(v)) == seen.end()) seen.push_back(label_of(v));
  }
  axis.distinct = seen.size();
  if (!axis.numeric) axis.labels = seen;
  return axis;
}

struct Sample {
  double x, y;
};

// The runs per seed (or all together when there are many seeds) and the mean at each x.
std::string data_blocks(const std::string& key, const std::string& metric, const Axis& axis,
                        const std::vector<const Row*>& rows, std::string& plot_clauses) {
  std::vector<std::string> seeds;
  std::map<std::string, std::vector<Sample>> by_seed;
  std::map<double, std::pair<double, int>> sums;
  for (const Row* r : rows) {
    if (!(*r)[metric].is_number()) continue;
    const double x = axis.x((*r)[key]), y = (*r)[metric].get<double>();
    const std::string seed = (*r)["seed"].dump();
    if (!by_seed.count(seed)) seeds.push_back(seed);
    by_seed[seed].push_back({x, y});
    sums[x].first += y;
    sums[x].second += 1;
  }
  const bool per_seed = seeds.size() <= kMaxSeedSeries;
  std::ostringstream blocks;
  std::vector<std::string> clauses;
  auto series = [&](const std::string& name, const std::vector<std::string>& members, const std::string& title) {
    blocks << "$" << name << " << EOD\n";
    for (const std::string& s : members)
      for (const Sample& p : by_seed[s]) blocks << number(p.x) << " " << number(p.y) << "\n";
    blocks << "EOD\n";
    clauses.push_back("$" + name + " using 1:2 with points pt 7 ps 1.1 title " + gp_quote(title));
  };
  if (per_seed)
    for (std::size_t i = 0; i < seeds.size(); ++i) series("seed" + std::to_string(i), {seeds[i]}, "seed " + seeds[i]);
  else
    series("runs", seeds, "runs (" + std::to_string(seeds.size()) + " seeds)");
  blocks << "$mean << EOD\n";
  for (const auto& [x, sum] : sums) blocks << number(x) << " " << number(sum.first / sum.second) << "\n";
  blocks << "EOD\n";
  clauses.push_back("$mean using 1:2 with linespoints lw 2 pt 5 lc rgb 'black' title 'mean'");
  plot_clauses.clear();
  for (std::size_t i = 0; i < clauses.size(); ++i) plot_clauses += (i ? ", " : "") + clauses[i];
  return blocks.str();
}

std::string plot_script(const std::string& key, const std::string& metric, const Axis& axis,
                        const std::vector<const Row*>& rows, const std::filesystem::path& output) {
  std::string clauses;
  const std::string blocks = data_blocks(key, metric, axis, rows, clauses);
  std::ostringstream s;
  s << "reset\n" << blocks;
  s << "set terminal pngcairo noenhanced size 900,600 font ',11'\n";
  s << "set output " << gp_quote(output.string()) << "\n";
  s << "set title " << gp_quote(metric + " vs " + key) << "\n";
  s << "set xlabel " << gp_quote(key) << "\nset ylabel " << gp_quote(metric) << "\n";
  s << "set grid\nset key outside right top\nset offsets graph 0.05, graph 0.05, graph 0.05, graph 0.05\n";
  if (!axis.numeric) {
    s << "set xtics (";
    for (std::size_t i = 0; i < axis.labels.size(); ++i)
      s << (i ? ", " : "") << gp_quote(axis.labels[i]) << " " << i;
    s << ")\nset xrange [-0.5:" << number(double(axis.labels.size()) - 0.5) << "]\n";
  }
  s << "plot " << clauses << "\n";
  return s.str();
}

std::string file_stem(const std::string& metric, const std::string& key) {
  std::string name = metric + "_vs_" + key;
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '.' && c != '-') c = '_';
  return name;
}

bool run_gnuplot(const std::filesystem::path& gnuplot, const std::string& script) {
  std::string command = "'";
  for (char c : gnuplot.string()) command += c == '\'' ? std::string("'\\''") : std::string(1, c);
  command += "'";  // its messages go to our stderr; stdout stays ours
  FILE* pipe = popen(command.c_str(), "w");
  if (!pipe) return false;
  const bool wrote = std::fwrite(script.data(), 1, script.size(), pipe) == script.size();
  const int status = pclose(pipe);
  return wrote && status != -1 && WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

}  // namespace

const std::vector<std::string>& headline_metrics() {
  static const std::vector<std::string> metrics = {"edge_roughness", "separation_roughness", "peeled_area",
                                                   "peak_grip_force", "torn_edge_length"};
  return metrics;
}

PlotOutcome write_sweep_plots(const std::filesystem::path& dir, const std::vector<std::string>& keys,
                              const std::vector<Row>& rows) {
  PlotOutcome outcome;
  std::vector<const Row*> done;
  for (const Row& r : rows)
    if (row_completed(r)) done.push_back(&r);
  std::string script;
  std::vector<std::pair<std::filesystem::path, std::filesystem::path>> files;  // temporary, final
  const std::filesystem::path plots = dir / "plots";
  for (const std::string& key : keys) {
    const Axis axis = make_axis(key, done);
    if (axis.distinct < 2) continue;
    for (const std::string& metric : headline_metrics()) {
      const std::string stem = file_stem(metric, key);
      files.push_back({plots / ("." + stem + ".tmp-" + std::to_string(getpid()) + ".png"), plots / (stem + ".png")});
      script += plot_script(key, metric, axis, done, files.back().first);
    }
  }
  if (files.empty()) return outcome;
  const std::optional<std::filesystem::path> gnuplot = find_gnuplot();
  if (!gnuplot) {
    outcome.warning = "gnuplot not found: no plots drawn (install Debian's gnuplot-nox)";
    return outcome;
  }
  create_output_dir(plots);
  const bool ok = run_gnuplot(*gnuplot, script);
  for (const auto& [temporary, final_path] : files) {
    std::error_code ec;
    if (ok && std::filesystem::is_regular_file(temporary, ec)) {
      std::filesystem::rename(temporary, final_path, ec);
      if (!ec) outcome.written.push_back(final_path);
    }
    std::filesystem::remove(temporary, ec);
  }
  if (!ok) outcome.warning = "gnuplot failed: no plots drawn";
  return outcome;
}

}  // namespace papertear::io
