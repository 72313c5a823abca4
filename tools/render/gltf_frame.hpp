// glTF's frame and the record of which moment of a run a mesh file shows, shared by the
// mesh writers (mesh_export.hpp, animation.hpp).
//
// glTF's frame: y up, metres. The simulation is z up in millimetres (core/elasticity.hpp),
// so a point (x, y, z) is written as (x, z, -y) * 0.001 (a right-handed rotation about x),
// and a .glb says so in asset.extras ("unit", "metres_per_unit").
#pragma once
#include <array>
#include <cstdint>

namespace papertear::render {

inline constexpr double kMetresPerUnit = 0.001;  // one lattice length unit is 1 mm

inline std::array<float, 3> to_gltf_position(const std::array<float, 3>& p) {
  constexpr float s = float(kMetresPerUnit);
  return {p[0] * s, p[2] * s, -p[1] * s};
}
inline std::array<float, 3> to_gltf_direction(const std::array<float, 3>& d) { return {d[0], d[2], -d[1]}; }

// Which moment of the run a file shows (asset.extras; OBJ: a header comment).
struct FrameInfo {
  int frame = 0;
  std::int64_t step = 0;
  double time = 0.0;  // simulated time, µs
  int fps = 15;       // the video's frame rate
  std::uint64_t digest = 0;
};

}  // namespace papertear::render
