// `papertear calibrate`: runs the standard tensile and Elmendorf-style tear tests for the
// material presets, along and across the grain, and reports the MD/CD ratios beside the
// published ranges (docs/calibration.md).
#include <cstdio>

#include "core/atomic_file.hpp"
#include "tools/calibration/report.hpp"
#include "tools/commands.hpp"

namespace papertear::cli {

int calibrate_command(const CalibrateOptions& options) {
  std::vector<std::string> presets = options.presets;
  if (presets.empty())
    for (const char* p : material_preset_names()) presets.emplace_back(p);
  std::vector<std::uint64_t> seeds;
  for (int s = 1; s <= options.seeds; ++s) seeds.push_back(std::uint64_t(s));
  try {
    Scene probe;
    for (const std::string& p : presets) apply_material_preset(probe.material, p);  // names check
    if (!options.out_dir.empty()) check_output_dir_option(options.out_dir);
  } catch (const std::exception& e) {
    print_error(e.what());
    return kExitBadInput;
  }
  const calibration::Size size = options.quick ? calibration::Size::quick : calibration::Size::standard;
  std::vector<calibration::PresetCalibration> results;
  try {
    for (const std::string& p : presets) {
      if (!options.quiet) std::fprintf(stderr, "calibrating %s (%zu seeds)...\n", p.c_str(), seeds.size());
      results.push_back(calibration::calibrate_preset(p, size, seeds, resolved_threads(options.threads)));
    }
  } catch (const BlowUpError& e) {
    print_error(e.what());
    return kExitBlowUp;
  } catch (const SceneError& e) {  // a preset whose standard specimen cannot be built
    print_error(e.what());
    return kExitBadInput;
  }
  const std::string table = calibration::markdown_report(results);
  std::fputs(table.c_str(), stdout);
  if (options.out_dir.empty()) return kExitOk;
  try {
    std::filesystem::create_directories(options.out_dir);
    write_file_atomically(std::filesystem::path(options.out_dir) / "calibration.md", table);
    write_file_atomically(std::filesystem::path(options.out_dir) / "calibration.json",
                          calibration::json_report(results));
  } catch (const std::exception& e) {
    print_error(e.what());
    return kExitOutput;
  }
  return kExitOk;
}

}  // namespace papertear::cli
