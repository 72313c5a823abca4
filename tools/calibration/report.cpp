#include "tools/calibration/report.hpp"

#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>

namespace papertear::calibration {
namespace {

// Sample standard deviation (0 for fewer than two seeds).
double spread(const std::vector<double>& v) {
  if (v.size() < 2) return 0.0;
  const double m = mean(v);
  double s = 0.0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / double(v.size() - 1));
}

std::string mean_sd(const std::vector<double>& v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.3f ± %.3f", mean(v), spread(v));
  return buf;
}

std::string ratio_cell(double r, bool ok) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.2f %s", r, ok ? "(in range)" : "(OUT OF RANGE)");
  return buf;
}

}  // namespace

bool tensile_in_range(const PresetCalibration& c) {
  const double r = c.tensile_ratio();
  return r >= kTensileRatioLow && r <= kTensileRatioHigh;
}
bool tear_in_range(const PresetCalibration& c) { return c.tear_ratio() > kTearRatioLow; }

std::string markdown_report(const std::vector<PresetCalibration>& results) {
  std::string out =
      "| preset | tensile MD | tensile CD | MD/CD (published 1.5–2.5) | tear MD | tear CD | CD/MD "
      "(published > 1) |\n| --- | --- | --- | --- | --- | --- | --- |\n";
  for (const PresetCalibration& c : results) {
    out += "| " + c.preset + " | " + mean_sd(c.tensile_md) + " | " + mean_sd(c.tensile_cd) + " | " +
           ratio_cell(c.tensile_ratio(), tensile_in_range(c)) + " | " + mean_sd(c.tear_md) + " | " +
           mean_sd(c.tear_cd) + " | " + ratio_cell(c.tear_ratio(), tear_in_range(c)) + " |\n";
  }
  return out;
}

std::string json_report(const std::vector<PresetCalibration>& results) {
  nlohmann::json presets = nlohmann::json::array();
  for (const PresetCalibration& c : results)
    presets.push_back({{"preset", c.preset},
                       {"tensile_md", c.tensile_md},
                       {"tensile_cd", c.tensile_cd},
                       {"tear_md", c.tear_md},
                       {"tear_cd", c.tear_cd},
                       {"tensile_ratio_md_cd", c.tensile_ratio()},
                       {"tear_ratio_cd_md", c.tear_ratio()},
                       {"tensile_in_range", tensile_in_range(c)},
                       {"tear_in_range", tear_in_range(c)}});
  nlohmann::json doc = {{"published",
                         {{"tensile_ratio_md_cd", {kTensileRatioLow, kTensileRatioHigh}},
                          {"tear_ratio_cd_md_above", kTearRatioLow}}},
                        {"presets", presets}};
  return doc.dump(2) + "\n";
}

}  // namespace papertear::calibration
