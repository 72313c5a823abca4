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

TEST_CASE("tear test: the specimen comes apart from the notch, consuming part of the grips' work",
          "[calibration]") {
  const Scene scene = tear_scene("copy", Direction::MD, Size::quick, 1);
  const TearResult r = run_tear(scene, 2);
  CHECK(r.torn_through);
  CHECK(r.steps < scene.run.steps);
  CHECK(r.work > 0.0);
  CHECK(r.tear_distance == Approx(scene.sheet.cells[1] - scene.load.notch));
  // The torn faces at least span the tear distance (the path wanders and frays; top layer).
  CHECK(r.torn_length >= r.tear_distance);
  // The tear consumed energy: the pieces hold less than the grips put in.
  CHECK(r.stored > 0.0);
  CHECK(r.stored < r.work);
  CHECK(r.resistance == Approx((r.work - r.stored) / r.tear_distance));
}

TEST_CASE("tear resistance CD/MD of every preset is above 1, as published for machine-made paper",
          "[calibration]") {
  for (const char* preset : material_preset_names()) {
    INFO(preset);
    std::vector<std::uint64_t> seeds{1, 2, 3};
    double md = 0.0, cd = 0.0;
    for (std::uint64_t seed : seeds) {
      const TearResult a = run_tear(tear_scene(preset, Direction::MD, Size::quick, seed), 2);
      const TearResult b = run_tear(tear_scene(preset, Direction::CD, Size::quick, seed), 2);
      REQUIRE(a.torn_through);
      REQUIRE(b.torn_through);
      md += a.resistance;
      cd += b.resistance;
    }
    CHECK(cd / md > kTearRatioLow);
  }
}
