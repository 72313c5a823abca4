// Lines that steer a tear (fracture/lines.hpp): which bonds a polyline crosses, what a cut,
// a score and a perforation do, and the [[line]] scene tables.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>
#include <tuple>

#include "core/checkpoint.hpp"
#include "core/elasticity.hpp"
#include "core/invariants.hpp"
#include "core/simulation.hpp"
#include "fracture/lines.hpp"
#include "fracture/metrics.hpp"
#include "tests/standard_scenes.hpp"
#include "tools/scene_file.hpp"
#include "tools/summary.hpp"

using namespace papertear;

namespace {

using Bond = std::tuple<int, int, int>;  // i, j, axis
using Polyline = std::vector<std::array<double, 2>>;

std::set<Bond> crossed(const Polyline& points, int nx, int ny) {
  std::set<Bond> out;
  for (const BondCrossing& c : line_crossings(points, nx, ny)) out.insert({c.i, c.j, c.axis});
  return out;
}

// Every bond of an nx × ny sheet whose two cell centres `above` puts on different sides.
template <class Side>
std::set<Bond> bonds_between_sides(int nx, int ny, Side above) {
  std::set<Bond> out;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const bool here = above(i + 0.5, j + 0.5);
      if (i + 1 < nx && here != above(i + 1.5, j + 0.5)) out.insert({i, j, 0});
      if (j + 1 < ny && here != above(i + 0.5, j + 1.5)) out.insert({i, j, 1});
    }
  return out;
}

// Distance in the plane from (x, y) to the polyline.
double distance_to(const Polyline& line, double x, double y) {
  double best = INFINITY;
  for (std::size_t s = 0; s + 1 < line.size(); ++s) {
    const double ax = line[s][0], ay = line[s][1], dx = line[s + 1][0] - ax, dy = line[s + 1][1] - ay;
    const double t = std::clamp(((x - ax) * dx + (y - ay) * dy) / (dx * dx + dy * dy), 0.0, 1.0);
    best = std::min(best, std::hypot(x - ax - t * dx, y - ay - t * dy));
  }
  return best;
}

// Fraction of in-plane splits whose split node lies within one cell of the polyline.
double fraction_near(const World& w, const Polyline& line, std::size_t& inplane) {
  std::size_t near = 0;
  inplane = 0;
  for (const SplitEvent& e : w.events) {
    if (e.interlayer) continue;
    ++inplane;
    const auto v = w.topo.dims.vertex_ijk(w.nodes.vertex[e.node]);
    near += distance_to(line, v[0], v[1]) <= 1.0;
  }
  return inplane ? double(near) / double(inplane) : 0.0;
}

LineParams make_line(const char* kind, Polyline points) {
  LineParams l;
  l.kind = kind;
  l.points = std::move(points);
  return l;
}

// A 40 × 40 × 3 sheet pulled apart along x, notched at mid-edge (x = 20, y < 4).
Scene pull_scene() {
  Scene s = standard::small("copy");
  s.sheet.cells = {40, 40, 3};
  s.load.notch = 4;
  // About the default pull's strain rate (2 x speed / width ~ 1e-3 per µs). Pulled 8x faster,
  // the sheet is loaded faster than a crack can relieve it, and a band of bonds fails at once.
  s.load.speed = 0.02;
  return s;
}

// Steps until the sheet is in two pieces that are not fragments (or `max_steps`); returns
// the steps taken.
int tear_apart(Simulation& sim, int max_steps) {
  int steps = 0;
  auto parts = [&] {
    const Metrics m = measure(sim.world());
    return m.pieces - m.fragments;
  };
  while (steps < max_steps && parts() < 2) {
    sim.step(50);
    steps += 50;
  }
  return steps;
}

// In two: two pieces besides fragments, which hold under 0.5 % of the sheet. The staircase
// that stands for a slanted line on the grid may cut a chip, a cell column, out at a step.
struct InTwo : Catch::MatcherBase<Metrics> {
  bool match(const Metrics& m) const override {
    return m.pieces - m.fragments == 2 && m.fragment_fraction < 5e-3;
  }
  std::string describe() const override { return "is in two pieces besides fragments under 0.5 % of the cells"; }
};
InTwo in_two() { return {}; }

}  // namespace

TEST_CASE("a line along a grid line crosses exactly the bonds under it", "[lines]") {
  std::set<Bond> expected;
  for (int j = 0; j < 6; ++j) expected.insert({4, j, 0});
  CHECK(crossed({{5.0, 0.0}, {5.0, 6.0}}, 10, 6) == expected);
  CHECK(crossed({{5.0, 6.0}, {5.0, 0.0}}, 10, 6) == expected);  // either direction
  // Through a column of centres: counts as just right of it (the (ε, ε²) shift).
  CHECK(crossed({{4.5, 0.0}, {4.5, 6.0}}, 10, 6) == expected);
  std::set<Bond> rows;
  for (int i = 0; i < 10; ++i) rows.insert({i, 2, 1});
  CHECK(crossed({{0.0, 3.0}, {10.0, 3.0}}, 10, 6) == rows);
  CHECK(crossed({{10.0, 2.5}, {0.0, 2.5}}, 10, 6) == rows);  // a row of centres: just above
}

TEST_CASE("a diagonal crosses the bonds whose centres it separates, ties included", "[lines]") {
  // Edge to edge, so every bond with centres on both sides of the line is within the segment.
  CHECK(crossed({{0.0, 0.3}, {10.0, 7.8}}, 10, 9) ==
        bonds_between_sides(10, 9, [](double x, double y) { return y > 0.3 + 0.75 * x; }));
  CHECK(crossed({{0.0, 7.0}, {12.0, 1.0}}, 12, 8) ==
        bonds_between_sides(12, 8, [](double x, double y) { return y > 7.0 - 0.5 * x; }));
  // Through every centre (i + 0.5, i + 0.5): the shift leaves each centre above the line,
  // so the crossings form one unbroken staircase of 2 × 7 bonds.
  const std::set<Bond> stair = crossed({{0.0, 0.0}, {8.0, 8.0}}, 8, 8);
  CHECK(stair == bonds_between_sides(8, 8, [](double x, double y) { return y >= x; }));
  CHECK(stair.size() == 14);
}

TEST_CASE("a polyline's ends and corners: no bond beyond an end, none missed at a corner", "[lines]") {
  std::set<Bond> three{{4, 0, 0}, {4, 1, 0}, {4, 2, 0}};
  CHECK(crossed({{5.0, 0.0}, {5.0, 3.4}}, 10, 6) == three);
  std::set<Bond> four = three;
  four.insert({4, 3, 0});
  CHECK(crossed({{5.0, 0.0}, {5.0, 3.5}}, 10, 6) == four);  // an end on a row of centres reaches it
  CHECK(crossed({{5.0, 3.5}, {5.0, 0.0}}, 10, 6) == four);
  CHECK(crossed({{5.0, 1.0}, {5.0, 1.4}}, 10, 6).empty());  // between two rows of centres
  // An L: down the grid line x = 5, then along y = 3 to the right edge.
  std::set<Bond> ell = three;
  for (int i = 5; i < 10; ++i) ell.insert({i, 2, 1});
  const auto crossings = line_crossings(Polyline{{5.0, 0.0}, {5.0, 3.0}, {10.0, 3.0}}, 10, 6);
  CHECK(crossed({{5.0, 0.0}, {5.0, 3.0}, {10.0, 3.0}}, 10, 6) == ell);
  CHECK(crossings.size() == ell.size());  // each once
  CHECK(std::is_sorted(crossings.begin(), crossings.end(),
                       [](const BondCrossing& a, const BondCrossing& b) { return a.arc < b.arc; }));
  CHECK(crossings.back().arc == Approx(3.0 + 4.5));
}

TEST_CASE("a score lowers exactly the crossed faces in the layers it reaches", "[lines]") {
  Scene plain = standard::small("copy");
  plain.load.kind = "none";
  plain.sheet.cells = {12, 8, 3};
  Scene scored = plain;
  LineParams line = make_line("score", {{5.0, 0.0}, {5.0, 8.0}});
  line.strength = 0.25;
  line.depth = 2;
  scored.lines = {line};
  const Simulation a(plain, {.threads = 1}), b(scored, {.threads = 1});
  const Topology &ta = a.world().topo, &tb = b.world().topo;
  std::size_t changed = 0;
  for (std::uint32_t c = 0; c < ta.dims.cells(); ++c) {
    const auto [i, j, k] = ta.dims.cell_ijk(c);
    for (int f = 0; f < kFacesPerCell; ++f) {
      const bool hit = k >= 1 && ((i == 4 && f == 1) || (i == 5 && f == 0));
      const float before = ta.face_strain[c * kFacesPerCell + std::size_t(f)];
      const float after = tb.face_strain[c * kFacesPerCell + std::size_t(f)];
      INFO("cell " << i << "," << j << "," << k << " face " << f);
      CHECK(after == (hit ? float(double(before) * 0.25) : before));
      changed += hit;
    }
  }
  CHECK(changed == 2 * 8 * 2);  // both sides of 8 bonds in 2 layers
  CHECK(b.world().nodes.count == a.world().nodes.count);  // nothing opened
}

TEST_CASE("a cut polyline separates the sheet into two pieces before the first step", "[lines]") {
  Scene s = standard::small("copy");
  s.load.kind = "none";
  s.load.notch = 0;
  s.sheet.cells = {20, 12, 2};
  s.lines = {make_line("cut", {{8.0, 0.0}, {8.0, 5.5}, {13.3, 12.0}})};
  const Simulation whole(s, {.threads = 1});
  CHECK(measure(whole.world()).pieces == 2);
  CHECK(check_invariants(whole.world()).empty());
  CHECK(whole.world().events.empty());  // part of the initial sheet, not a tear
  double mass = 0.0;
  for (std::size_t n = 0; n < whole.world().nodes.count; ++n) mass += whole.world().nodes.mass[n];
  CHECK(mass == Approx(20.0 * 12.0 * 2.0 * cell_mass(s.material, whole.world().topo.dims)));
  // Stopping short of the far edge leaves one piece; a cut through the top layer only
  // separates nothing either.
  s.lines[0].points.back() = {12.0, 10.0};
  CHECK(measure(Simulation(s, {.threads = 1}).world()).pieces == 1);
  s.lines[0].points.back() = {13.3, 12.0};
  s.lines[0].depth = 1;
  const Simulation top(s, {.threads = 1});
  CHECK(measure(top.world()).pieces == 1);
  CHECK(check_invariants(top.world()).empty());
  s.lines.clear();
  CHECK(top.world().nodes.count > Simulation(s, {.threads = 1}).world().nodes.count);
}

TEST_CASE("a scored line makes the tear follow it (most splits within a cell of the line)", "[lines]") {
  const Polyline path{{20.0, 4.0}, {24.0, 20.0}, {30.0, 40.0}};
  Scene control = pull_scene();
  Scene scored = control;
  scored.lines = {make_line("score", path)};
  // A deep score: below tip_strength, so its bonds give way before the tear running from the
  // notch reaches them. A shallow one (the default 0.5) only guides a tear already on it: a
  // running crack opens at its tip (fracture_pass.hpp) and cannot turn onto a slanted line.
  scored.lines[0].strength = 0.2;
  Simulation with_line(scored, {.threads = 2}), without(control, {.threads = 2});
  const int steps = tear_apart(with_line, 4000);
  tear_apart(without, 4000);
  std::size_t n_line = 0, n_control = 0;
  const double near_line = fraction_near(with_line.world(), path, n_line);
  const double near_control = fraction_near(without.world(), path, n_control);
  INFO("steps " << steps << ": " << n_line << " splits, " << near_line << " near the line; control "
                << n_control << " splits, " << near_control << " near it");
  CHECK_THAT(measure(with_line.world()), in_two());
  CHECK(n_line >= 30);
  CHECK(near_line >= 0.8);
  CHECK(near_control < 0.5);
}

TEST_CASE("a perforated line holds at first and tears along its holes", "[lines]") {
  const Polyline path{{16.0, 0.0}, {26.0, 40.0}};
  Scene s = pull_scene();
  s.load.notch = 0;
  LineParams perforation = make_line("perforation", path);
  // Holes 2 cells long every 4 cells, the lands between them at the default half strength.
  s.lines = {perforation};
  Scene plain = s;
  plain.lines.clear();
  const std::size_t intact_nodes = Simulation(plain, {.threads = 1}).world().nodes.count;
  Simulation sim(s, {.threads = 2});
  CHECK(measure(sim.world()).pieces == 1);
  CHECK(sim.world().nodes.count > intact_nodes);  // the holes are open
  CHECK(check_invariants(sim.world()).empty());
  const int steps = tear_apart(sim, 4000);
  std::size_t n = 0;
  const double near = fraction_near(sim.world(), path, n);
  INFO("steps " << steps << ": " << n << " splits, " << near << " near the line");
  CHECK_THAT(measure(sim.world()), in_two());
  CHECK(n >= 20);
  CHECK(near >= 0.8);
  // duty 0 leaves no holes, duty 1 cuts the line through.
  s.lines[0].duty = 0.0;
  CHECK(Simulation(s, {.threads = 1}).world().nodes.count == intact_nodes);
  s.lines[0].duty = 1.0;
  CHECK(measure(Simulation(s, {.threads = 1}).world()).pieces == 2);
}

TEST_CASE("[[line]] tables: read, written and read back equal, echoed in the summary", "[lines][scene]") {
  const char* text = R"(
[sheet]
cells = [30, 20, 4]

[[line]]
kind = "score"
points = [[15, 0], [17.5, 10.25], [12, 20]]
strength = 0.3
depth = 2

[[line]]
kind = "perforation"
points = [[2, 2], [28, 18]]
pitch = 3
duty = 0.25
)";
  const Scene scene = io::parse_scene(text, "lines.toml").scene;
  REQUIRE(scene.lines.size() == 2);
  CHECK(scene.lines[0].kind == "score");
  CHECK(scene.lines[0].points == Polyline{{15.0, 0.0}, {17.5, 10.25}, {12.0, 20.0}});
  CHECK(scene.lines[0].strength == 0.3);
  CHECK(scene.lines[0].depth == 2);
  CHECK(scene.lines[1].pitch == 3.0);
  CHECK(scene.lines[1].duty == 0.25);
  CHECK(scene.lines[1].strength == LineParams{}.strength);  // defaults fill what is not written
  std::ostringstream written;
  written << io::scene_to_toml(scene);
  const Scene back = io::parse_scene(written.str(), "written.toml").scene;
  CHECK(back.lines == scene.lines);
  CHECK(io::scene_to_toml(back) == io::scene_to_toml(scene));
  const nlohmann::json json = io::scene_to_json(scene);
  REQUIRE(json["line"].size() == 2);
  CHECK(json["line"][0]["points"][1][1] == 10.25);
  CHECK(json["line"][1]["kind"] == "perforation");
  CHECK(io::scene_to_json(Scene{})["line"] == nlohmann::json::array());
  // The default scene writes no line, and an inline array from --set works like [[line]].
  CHECK(!io::scene_to_toml(Scene{}).contains("line"));
  const io::SetOverride set = io::parse_set_argument(R"(line=[{kind="cut", points=[[1,1],[5,5]]}])");
  const Scene overridden = io::default_scene_file(std::span(&set, 1)).scene;
  REQUIRE(overridden.lines.size() == 1);
  CHECK(overridden.lines[0].kind == "cut");
}

TEST_CASE("lines survive a checkpoint and the resumed run matches", "[lines][checkpoint]") {
  Scene s = pull_scene();
  s.sheet.cells = {24, 16, 3};
  s.load.notch = 3;
  LineParams line = make_line("perforation", {{12.0, 3.0}, {15.5, 16.0}});
  line.strength = 0.7;
  line.depth = 2;
  line.pitch = 3.0;
  line.duty = 0.4;
  s.lines = {line, make_line("score", {{12.0, 3.0}, {9.0, 16.0}})};
  Simulation first(s, {.threads = 2});
  first.step(100);
  Simulation resumed(deserialize_world(serialize_world(first.world())), {.threads = 1});
  CHECK(resumed.scene().lines == s.lines);
  CHECK(resumed.world().topo.face_strain == first.world().topo.face_strain);
  first.step(150);
  resumed.step(150);
  CHECK(resumed.digest() == first.digest());
}

TEST_CASE("bad lines are refused naming the line and its key", "[lines][scene]") {
  auto error = [](const std::string& line) {
    try {
      io::parse_scene("[sheet]\ncells = [20, 10, 3]\n[[line]]\n" + line, "s.toml");
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  using Catch::Matchers::Contains;
  const std::string two = "points = [[1, 1], [5, 5]]\n";
  CHECK_THAT(error("kind = \"fold\"\n" + two), Contains("line[0].kind: must be \"cut\", \"score\" or \"perforation\""));
  CHECK_THAT(error("points = [[1, 1]]\n"), Contains("line[0].points: needs at least 2 points"));
  CHECK_THAT(error(""), Contains("line[0].points: needs at least 2 points"));
  CHECK_THAT(error("points = [[1, 1], [21, 5]]\n"), Contains("line[0].points: point 1"));
  CHECK_THAT(error("points = [[1, -0.5], [2, 5]]\n"), Contains("outside the sheet"));
  CHECK_THAT(error("points = [[1, 1, 1], [2, 5]]\n"), Contains("line[0].points[0]: expected a point [x, y]"));
  CHECK_THAT(error("points = [[1, \"a\"], [2, 5]]\n"), Contains("line[0].points[0][1]: expected a number"));
  CHECK_THAT(error(two + "strength = 0\n"), Contains("line[0].strength: must be in (0, 1]"));
  CHECK_THAT(error(two + "strength = 1.5\n"), Contains("line[0].strength: must be in (0, 1]"));
  CHECK_THAT(error(two + "pitch = 0\n"), Contains("line[0].pitch: must be greater than 0"));
  CHECK_THAT(error(two + "duty = 1.5\n"), Contains("line[0].duty: must be in [0, 1]"));
  CHECK_THAT(error(two + "depth = -1\n"), Contains("line[0].depth: must be 0 (all layers) to 3"));
  CHECK_THAT(error(two + "depth = 4\n"), Contains("line[0].depth"));
  CHECK_THAT(error(two + "strenght = 0.5\n"), Contains("unknown key 'line[0].strenght' (did you mean 'line[0].strength'?)"));
  // The second line is named by its index, with the place it was written.
  CHECK_THAT(error(two + "[[line]]\n" + two + "duty = -1\n"), Contains("s.toml:7:8: line[1].duty"));
  CHECK_THROWS_WITH(io::parse_scene("line = 3\n", "s.toml"), Contains("line: expected an array of tables"));
}
