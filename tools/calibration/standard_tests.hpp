// Standard paper tests run on the lattice, to calibrate the material presets against real
// paper (docs/calibration.md):
//  * a tensile test in the spirit of ISO 1924-2 / TAPPI T494: a strip pulled apart along its
//    length until it breaks; the tensile strength is the peak force per unit width;
//  * a tear test in the spirit of Elmendorf (ISO 1974 / TAPPI T414): a notched specimen torn
//    out of plane (load.kind = "tear"); the tear resistance is the energy the tear consumed
//    (the grips' work less what the pieces still hold), per unit of tear distance.
// Each runs along (MD) and across (CD) the grain. Paper's convention: an MD tensile strip is
// pulled along the grain; an MD tear runs along the grain.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "core/scene.hpp"

namespace papertear::calibration {

enum class Direction { MD, CD };
const char* name(Direction d);

double mean(const std::vector<double>& values);  // 0 for none

// Specimen sizes in cells: `standard` for the report, `quick` for tests.
enum class Size { quick, standard };

Scene tensile_scene(const std::string& preset, Direction direction, Size size, std::uint64_t seed);
Scene tear_scene(const std::string& preset, Direction direction, Size size, std::uint64_t seed);

struct TensileResult {
  double peak_force = 0.0;       // peak pull on the grip
  double strength = 0.0;         // peak force per unit width (lattice units)
  double strain_at_peak = 0.0;   // grip separation / free length at the peak
  std::int64_t steps = 0;
};

struct TearResult {
  double work = 0.0;           // the grips' work on the specimen until it came apart
  double stored = 0.0;         // elastic + kinetic energy still in the pieces at that moment
  bool torn_through = false;   // the specimen came apart in two within the step limit
  double tear_distance = 0.0;  // from the notch tip to the far edge
  double torn_length = 0.0;    // torn in-plane faces of the top layer (wandering and fraying)
  double resistance = 0.0;     // (work - stored) per unit tear distance (0 if not torn through)
  std::int64_t steps = 0;
};

// Run until the specimen has broken (force fallen well below its peak) or the step limit.
TensileResult run_tensile(const Scene& scene, int threads);
// Run the tear until the specimen is in two pieces (or the step limit).
TearResult run_tear(const Scene& scene, int threads);

// One preset's four measurements, averaged over seeds, and the two ratios paper is known by.
struct PresetCalibration {
  std::string preset;
  std::vector<double> tensile_md, tensile_cd;  // per seed
  std::vector<double> tear_md, tear_cd;        // per seed
  double tensile_ratio() const;  // mean MD / mean CD strength (published ~1.5 to 2.5)
  double tear_ratio() const;     // mean CD / mean MD tear resistance (published > 1)
};

PresetCalibration calibrate_preset(const std::string& preset, Size size, const std::vector<std::uint64_t>& seeds,
                                   int threads);

}  // namespace papertear::calibration
