// Loads beyond the pull (issue #7): a rigid indenter pierced through a clamped sheet
// (core/contact.hpp) and a hand tear by two grips moving apart out of plane.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "core/checkpoint.hpp"
#include "core/contact.hpp"
#include "core/simulation.hpp"
#include "fracture/connectivity.hpp"
#include "fracture/metrics.hpp"
#include "tools/scene_file.hpp"

using namespace papertear;
using Catch::Matchers::Contains;

namespace {

// A small sheet clamped along its border, pierced at its middle by a ball on a rod of
// radius 3; it bursts within ~800 steps.
Scene small_pierce(const char* indenter = "sphere") {
  Scene s;
  s.sheet.cells = {30, 30, 3};
  s.load.kind = "pierce";
  s.load.indenter = indenter;
  s.load.indenter_radius = 3.0;
  s.load.speed = 0.1;
  s.load.ramp_time = 5.0;
  s.load.grip_cells = 1;
  s.load.grip_margin = 1;
  return s;
}

Scene small_tear() {
  Scene s;
  s.sheet.cells = {30, 30, 3};
  // Along the grain, as a hand tear down a sheet usually runs. Across it, the tear turns to
  // follow the grain within a few cells and tears a strip off the edge (README, model decisions).
  s.material.grain = 'y';
  s.load.kind = "tear";
  s.load.speed = 0.1;
  s.load.ramp_time = 5.0;
  s.load.grip_cells = 4;
  s.load.grip_margin = 2;
  s.load.notch = 4;
  return s;
}

// A torn in-plane face of the top layer, at its rest midpoint.
struct TornFace {
  double x, y;
};

std::vector<TornFace> top_torn_faces(const World& w) {
  const LatticeDims& d = w.topo.dims;
  std::vector<TornFace> out;
  const int k = d.nl - 1;
  for (int j = 0; j < d.ny; ++j)
    for (int i = 0; i < d.nx; ++i)
      for (int face : {1, 3}) {  // +x and +y: each interior face once
        if (d.neighbour(i, j, k, face) < 0 || faces_connected(w, d.cell_index(i, j, k), face)) continue;
        out.push_back(face == 1 ? TornFace{(i + 1) * d.hx, (j + 0.5) * d.hy} : TornFace{(i + 0.5) * d.hx, (j + 1) * d.hy});
      }
  return out;
}

// Which of 8 equal angular sectors around (x0, y0) hold a torn face at a distance in [r0, r1).
std::set<int> sectors_torn(const std::vector<TornFace>& faces, double x0, double y0, double r0, double r1) {
  std::set<int> sectors;
  for (const TornFace& f : faces) {
    const double r = std::hypot(f.x - x0, f.y - y0);
    if (r < r0 || r >= r1) continue;
    const double a = std::atan2(f.y - y0, f.x - x0) + std::numbers::pi;  // [0, 2π]
    sectors.insert(std::min(7, int(a / (std::numbers::pi / 4.0))));
  }
  return sectors;
}

}  // namespace

TEST_CASE("A pierced sheet ends with a hole whose torn faces surround the indenter's path", "[loads][pierce]") {
  const char* shape = GENERATE("sphere", "cone");
  INFO("indenter " << shape);
  Simulation sim(small_pierce(shape), {.threads = 2});
  const double x0 = 15.0, y0 = 15.0, radius = 3.0;

  std::vector<double> force;
  for (int i = 0; i < 24; ++i) {
    sim.step(50);
    force.push_back(measure(sim.world()).indenter_force);
  }
  // The sheet dents and resists more and more, then bursts: the force falls by a quarter
  // from its peak so far. A ball then slips through (the rod pushes only sideways); a cone
  // keeps widening the hole, so its force rises again.
  double peak = 0.0;
  std::size_t burst = 0;
  for (std::size_t i = 0; i < force.size() && burst == 0; ++i) {
    peak = std::max(peak, force[i]);
    if (force[i] < 0.75 * peak) burst = i;
  }
  CHECK(force.front() > 0.0);
  REQUIRE(burst > 0);
  CHECK(peak > 1.5 * force.front());
  if (std::string(shape) == "sphere") CHECK(force.back() < 0.1 * peak);

  const Indenter ind = *make_indenter(sim.world());
  const double tip_bottom = indenter_pose(ind, sim.time()).cz - radius;
  CHECK(tip_bottom < -5.0);  // the indenter's nose is well below the sheet

  const std::vector<TornFace> torn = top_torn_faces(sim.world());
  // The hole: torn faces all round the path, close to it...
  CHECK(sectors_torn(torn, x0, y0, 0.0, 2.0 * radius).size() == 8);
  // ...and a star: cracks running out beyond the indenter's reach in several directions.
  CHECK(sectors_torn(torn, x0, y0, 2.0 * radius, 100.0).size() >= 3);
  // No torn face outside the clamp's frame (the tabs never break).
  for (const TornFace& f : torn) {
    CHECK(f.x >= 2.0);
    CHECK(f.x <= 28.0);
  }
  // And the path is clear: no free node is left deep inside the indenter.
  const NodeStore& n = sim.world().nodes;
  const IndenterPose pose = indenter_pose(ind, sim.time());
  for (std::size_t i = 0; i < n.count; ++i) {
    if (n.pz[i] < pose.cz) continue;  // below the nose's centre: the ball's own region
    CHECK(std::hypot(n.px[i] - x0, n.py[i] - y0) > 0.8 * radius);
  }
}

TEST_CASE("A pierce run gives the same digest on 1 and 2 threads", "[loads][pierce][determinism]") {
  const Scene s = small_pierce();
  Simulation one(s, {.threads = 1}), two(s, {.threads = 2});
  one.step(600);  // through the burst: contact and splits both at work
  two.step(600);
  REQUIRE(!one.world().events.empty());
  CHECK(one.digest() == two.digest());
}

TEST_CASE("The contact stiffness lowers the stable time step, and auto dt stays stable", "[loads][pierce]") {
  Scene pierce = small_pierce();
  Scene free = pierce;
  free.load.kind = "none";
  const double with_contact = Simulation::stable_dt_limit(pierce), without = Simulation::stable_dt_limit(free);
  CHECK(with_contact < without);
  pierce.load.contact_stiffness = 200.0;  // far stiffer than the springs
  CHECK(Simulation::stable_dt_limit(pierce) < 0.5 * without);
  Simulation sim(pierce, {.threads = 2});
  CHECK_NOTHROW(sim.step(400));
  CHECK(measure(sim.world()).indenter_force > 0.0);
}

TEST_CASE("A pulled sheet feels no indenter", "[loads]") {
  Scene pull;
  pull.sheet.cells = {12, 8, 2};
  Simulation sim(pull, {.threads = 1});
  sim.step(20);
  CHECK_FALSE(make_indenter(sim.world()).has_value());
  CHECK(measure(sim.world()).indenter_force == 0.0);
}

TEST_CASE("A hand tear starts at the notch and runs down the sheet", "[loads][tear]") {
  Simulation sim(small_tear(), {.threads = 2});
  const LatticeDims& d = sim.world().topo.dims;
  const std::size_t notch_splits = sim.world().events.size();  // the notch is cut by splits
  int first_row = -1;
  for (int i = 0; i < 40 && first_row < 0; ++i) {
    sim.step(10);
    const auto& events = sim.world().events;
    if (events.size() > notch_splits) {
      const auto v = d.vertex_ijk(sim.world().nodes.vertex[events[notch_splits].node]);
      first_row = v[1];
      // The first split is at the notch's tip, between the grips.
      CHECK(std::abs(v[0] - d.nx / 2) <= 3);
      CHECK(v[1] <= 4 + 3);
    }
  }
  REQUIRE(first_row >= 0);
  sim.step(400);
  // The tear has run from the gripped edge to past the middle of the sheet.
  const std::vector<TornFace> torn = top_torn_faces(sim.world());
  double deepest = 0.0;
  for (const TornFace& f : torn) deepest = std::max(deepest, f.y);
  CHECK(deepest > 0.5 * d.ny * d.hy);
  // The bonds that open are the in-plane ones across the tear's line: along the top layer's
  // tear (but the notch), through at least half of the node layers. (The top layer's front
  // runs ahead of the lower layers' in this mode-III tear, so not through all of them yet.)
  const Metrics m = measure(sim.world());
  INFO("deepest " << deepest << " mm, in-plane splits " << m.splits_inplane);
  CHECK(double(m.splits_inplane) >= 0.5 * double(d.nl + 1) * (deepest / d.hy - double(sim.scene().load.notch)));
}

TEST_CASE("Bad indenter and load keys are refused naming the key", "[loads][scene]") {
  auto refusal = [](Scene s) -> std::string {
    try {
      validate(s);
    } catch (const SceneError& e) {
      return e.what();
    }
    return "";
  };
  Scene s = small_pierce();
  CHECK_NOTHROW(validate(s));
  {
    Scene bad = s;
    bad.load.indenter = "pyramid";
    CHECK_THAT(refusal(bad), Contains("load.indenter:") && Contains("pyramid"));
  }
  for (double r : {0.0, -1.0, std::nan("")}) {
    Scene bad = s;
    bad.load.indenter_radius = r;
    CHECK_THAT(refusal(bad), Contains("load.indenter_radius:"));
  }
  for (double a : {0.0, 90.0, 120.0}) {
    Scene bad = s;
    bad.load.indenter_angle = a;
    CHECK_THAT(refusal(bad), Contains("load.indenter_angle:"));
  }
  for (std::array<double, 2> at : {std::array<double, 2>{1.5, 0.5}, {0.5, -0.1}, {std::nan(""), 0.5}}) {
    Scene bad = s;
    bad.load.indenter_at = at;
    CHECK_THAT(refusal(bad), Contains("load.indenter_at:"));
  }
  {
    Scene bad = s;
    bad.load.contact_stiffness = 0.0;
    CHECK_THAT(refusal(bad), Contains("load.contact_stiffness:"));
  }
  {
    Scene bad = s;
    bad.load.grip_cells = 15;  // the clamp would cover the 30-cell sheet
    CHECK_THAT(refusal(bad), Contains("load.grip_cells:"));
  }
  {
    Scene bad = small_tear();
    bad.load.grip_margin = 12;  // grips 12 cells off the middle of 30 do not fit
    CHECK_THAT(refusal(bad), Contains("load.grip_margin:"));
  }
  {
    Scene bad = s;
    bad.load.kind = "poke";
    CHECK_THAT(refusal(bad), Contains("load.kind:") && Contains("pierce") && Contains("tear"));
  }
  // From a scene file: a position with three numbers, a radius that is a string.
  CHECK_THROWS_WITH(io::parse_scene("[load]\nindenter_at = [0.5, 0.5, 0.5]\n", "s.toml"),
                    Contains("load.indenter_at") && Contains("array of 2"));
  CHECK_THROWS_WITH(io::parse_scene("[load]\nindenter_radius = \"big\"\n", "s.toml"),
                    Contains("load.indenter_radius"));
  CHECK_THROWS_WITH(io::parse_scene("[load]\nkind = \"pierce\"\nindenter = \"cube\"\n", "s.toml"),
                    Contains("load.indenter"));
}

TEST_CASE("The indenter keys survive a checkpoint and a scene file", "[loads][checkpoint]") {
  Scene s = small_pierce("cone");
  s.load.indenter_radius = 2.5;
  s.load.indenter_angle = 22.5;
  s.load.indenter_at = {0.375, 0.625};
  s.load.contact_stiffness = 7.25;
  Simulation sim(s, {.threads = 1});
  sim.step(30);
  const World back = deserialize_world(serialize_world(sim.world()));
  const LoadParams& l = back.scene.load;
  CHECK(l.kind == "pierce");
  CHECK(l.indenter == "cone");
  CHECK(l.indenter_radius == 2.5);
  CHECK(l.indenter_angle == 22.5);
  CHECK(l.indenter_at == std::array<double, 2>{0.375, 0.625});
  CHECK(l.contact_stiffness == 7.25);
  // The restored run steps on with the same bits as the original.
  Simulation resumed(back, {.threads = 2});
  sim.step(50);
  resumed.step(50);
  CHECK(resumed.digest() == sim.digest());
  // And the scene file writer reads back the same keys.
  std::ostringstream text;
  text << io::scene_to_toml(s);
  const io::SceneFile file = io::parse_scene(text.str(), "written.toml");
  CHECK(file.scene.load.indenter_at == s.load.indenter_at);
  CHECK(file.scene.load.indenter_angle == s.load.indenter_angle);
}
