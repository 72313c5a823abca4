// The calibration report: simulated MD/CD ratios of every preset beside the ranges published
// for machine-made paper (docs/calibration.md quotes the sources).
#pragma once
#include <string>
#include <vector>

#include "tools/calibration/standard_tests.hpp"

namespace papertear::calibration {

// Published ranges the presets are tuned to (docs/calibration.md).
inline constexpr double kTensileRatioLow = 1.5, kTensileRatioHigh = 2.5;  // MD / CD strength
inline constexpr double kTearRatioLow = 1.0;                              // CD / MD tear (above)

bool tensile_in_range(const PresetCalibration& c);
bool tear_in_range(const PresetCalibration& c);

std::string markdown_report(const std::vector<PresetCalibration>& results);
std::string json_report(const std::vector<PresetCalibration>& results);

}  // namespace papertear::calibration
