// Plots of a sweep: for every swept key with two or more values and every headline metric,
// DIR/plots/<metric>_vs_<key>.png with one point per run (a colour per seed) and the mean
// over the runs at each value of the key (so with several swept keys, the mean is over the
// other keys too: the key's main effect). Numeric keys are placed by value; others (presets,
// arrays) side by side in the order they first appear. Only completed runs are plotted.
// Drawn by gnuplot (Debian's gnuplot-nox); without it there are no plots, only a warning.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "tools/sweep_results.hpp"

namespace papertear::io {

// The metrics plotted against each swept key.
const std::vector<std::string>& headline_metrics();

struct PlotOutcome {
  std::vector<std::filesystem::path> written;
  std::string warning;  // non-empty: why some or all plots were not drawn
};

// Draws the plots into dir/plots (each file written under a temporary name and renamed).
PlotOutcome write_sweep_plots(const std::filesystem::path& dir, const std::vector<std::string>& keys,
                              const std::vector<Row>& rows);

}  // namespace papertear::io
