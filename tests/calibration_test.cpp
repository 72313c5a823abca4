// The standard paper tests (tools/calibration) and the presets' calibration against the
// MD/CD ratios published for machine-made paper (docs/calibration.md).
#include <catch2/catch.hpp>

#include "tools/calibration/report.hpp"

using namespace papertear;
using namespace papertear::calibration;

namespace {

double mean_strength(const std::string& preset, Direction d) {
  double sum = 0.0;
  for (std::uint64_t seed : {1u, 2u}) sum += run_tensile(tensile_scene(preset, d, Size::quick, seed), 2).strength;
  return sum / 2.0;
}

}  // namespace

TEST_CASE("tensile test: the strip breaks, and strength does not depend on the strip's width",
          "[calibration]") {
  Scene narrow = tensile_scene("copy", Direction::CD, Size::quick, 1);
  Scene wide = narrow;
  wide.sheet.cells[1] *= 2;
  const TensileResult a = run_tensile(narrow, 2), b = run_tensile(wide, 2);
  // Broken through: the loop stopped on the force drop, well before its step limit.
  CHECK(a.steps < narrow.run.steps);
  CHECK(b.steps < wide.run.steps);
  CHECK(b.peak_force > 1.6 * a.peak_force);  // twice the width carries about twice the force
  CHECK(b.strength == Approx(a.strength).epsilon(0.2));
  CHECK(a.strain_at_peak > 0.5 * narrow.material.strain_inter);  // breaks near the bond strain
}

TEST_CASE("tensile strength MD/CD of every preset is in the published range (1.5 to 2.5)",
          "[calibration]") {
  for (const char* preset : material_preset_names()) {
    INFO(preset);
    const double ratio = mean_strength(preset, Direction::MD) / mean_strength(preset, Direction::CD);
    CHECK(ratio >= kTensileRatioLow);
    CHECK(ratio <= kTensileRatioHigh);
  }
}
