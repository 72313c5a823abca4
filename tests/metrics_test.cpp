// The tear metrics (fracture/metrics.hpp): pieces and fragments, and the cracks of the top
// layer, measured on sheets cut by hand (fracture/lines.hpp) whose answers follow from the
// geometry, and on random cuts and a real tear for what must hold whatever the shape.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "core/simulation.hpp"
#include "fracture/metrics.hpp"
#include "tests/standard_scenes.hpp"
#include "tools/run_checkpoints.hpp"
#include "tools/summary.hpp"

using namespace papertear;

namespace {

using Polyline = std::vector<std::array<double, 2>>;

LineParams cut(Polyline points, int depth = 0) {
  LineParams l;
  l.kind = "cut";
  l.points = std::move(points);
  l.depth = depth;
  return l;
}

// An unloaded sheet with no notch: only the cuts open anything.
Scene sheet(int nx, int ny, int nl, std::vector<LineParams> lines, std::array<double, 3> size = {1.0, 1.0, 1.0}) {
  Scene s = standard::small("copy");
  s.load.kind = "none";
  s.load.notch = 0;
  s.sheet.cells = {nx, ny, nl};
  s.sheet.cell_size = size;
  s.lines = std::move(lines);
  return s;
}

Metrics measure_scene(const Scene& s) { return measure(Simulation(s, {.threads = 1}).world()); }

// A closed outline along grid lines around cells [i0, i1) x [j0, j1).
Polyline box(double i0, double j0, double i1, double j1) {
  return {{i0, j0}, {i1, j0}, {i1, j1}, {i0, j1}, {i0, j0}};
}

// What must hold for any sheet: sizes add up, largest first, roughness >= 1 with a tear.
void check_consistent(const Metrics& m, const Scene& s) {
  const auto& c = s.sheet.cells;
  const std::int64_t cells = std::int64_t(c[0]) * c[1] * c[2];
  REQUIRE(m.piece_cells.size() == std::size_t(m.pieces));
  CHECK(std::accumulate(m.piece_cells.begin(), m.piece_cells.end(), std::int64_t(0)) == cells);
  CHECK(std::is_sorted(m.piece_cells.rbegin(), m.piece_cells.rend()));
  CHECK(m.fragments <= m.pieces);
  CHECK(m.fragment_fraction >= 0.0);
  CHECK(m.fragment_fraction < 1.0);
  if (m.torn_edge_length == 0.0) {
    CHECK(m.edge_roughness == 0.0);
    CHECK(m.tear_length == 0.0);
    CHECK(m.splits_per_tear_length == 0.0);
    return;
  }
  CHECK(m.edge_roughness >= 1.0);
  CHECK(m.tear_length > 0.0);
  CHECK(m.tear_length <= std::hypot(c[0] * s.sheet.cell_size[0], c[1] * s.sheet.cell_size[1]));
  CHECK(m.splits_per_tear_length == double(m.splits_inplane) / m.tear_length);
}

}  // namespace

TEST_CASE("an intact sheet has one piece and no tear", "[metrics]") {
  const Scene s = sheet(12, 8, 2, {});
  const Metrics m = measure_scene(s);
  CHECK(m.pieces == 1);
  CHECK(m.piece_cells == std::vector<std::int64_t>{12 * 8 * 2});
  CHECK(m.fragments == 0);
  CHECK(m.fragment_fraction == 0.0);
  CHECK(m.torn_edge_length == 0.0);
  CHECK(m.edge_roughness == 0.0);
  CHECK(m.tear_length == 0.0);
  CHECK(m.splits_per_tear_length == 0.0);
}

TEST_CASE("a straight cut across the sheet has roughness exactly 1 and two pieces", "[metrics]") {
  for (const std::array<double, 3> size : {std::array<double, 3>{1.0, 1.0, 1.0}, {2.0, 0.5, 1.0}, {0.3, 0.7, 1.0}}) {
    INFO("cell size " << size[0] << " x " << size[1]);
    // Along y at x = 8 (faces between cell columns 7 and 8), then along x at y = 5.
    const Metrics across_x = measure_scene(sheet(20, 12, 2, {cut({{8.0, 0.0}, {8.0, 12.0}})}, size));
    CHECK(across_x.pieces == 2);
    CHECK(across_x.piece_cells == std::vector<std::int64_t>{12 * 12 * 2, 8 * 12 * 2});
    CHECK(across_x.fragments == 0);
    CHECK(across_x.edge_roughness == 1.0);
    CHECK(across_x.tear_length == double(12) * size[1]);
    CHECK(across_x.torn_edge_length == double(12) * size[1]);

    const Metrics across_y = measure_scene(sheet(20, 12, 2, {cut({{0.0, 5.0}, {20.0, 5.0}})}, size));
    CHECK(across_y.pieces == 2);
    CHECK(across_y.piece_cells == std::vector<std::int64_t>{20 * 7 * 2, 20 * 5 * 2});
    CHECK(across_y.edge_roughness == 1.0);
    CHECK(across_y.tear_length == double(20) * size[0]);
  }
}

TEST_CASE("a staircase cut has path / chord = (a hx + b hy) / hypot(a hx, b hy)", "[metrics]") {
  // b unit steps up, each followed by `run` cells to the right except the last: the path has
  // a = run (b - 1) cells along x and b along y, between (2, 0) and (2 + a, b).
  for (const int run : {1, 2, 3}) {
    for (const std::array<double, 3> size : {std::array<double, 3>{1.0, 1.0, 1.0}, {0.5, 2.0, 1.0}}) {
      const int b = 10, a = run * (b - 1);
      Polyline stairs = {{2.0, 0.0}};
      for (int s = 0; s < b; ++s) {
        const double x = 2.0 + run * s;
        stairs.push_back({x, s + 1.0});
        if (s + 1 < b) stairs.push_back({x + run, s + 1.0});
      }
      const Scene scene = sheet(a + 4, b, 2, {cut(stairs)}, size);
      const Metrics m = measure_scene(scene);
      const double path = a * size[0] + b * size[1], chord = std::hypot(a * size[0], b * size[1]);
      INFO("run " << run << ", cell size " << size[0] << " x " << size[1]);
      CHECK(m.pieces == 2);
      CHECK(m.torn_edge_length == path);
      CHECK(m.tear_length == chord);
      CHECK(m.edge_roughness == Approx(path / chord).epsilon(1e-14));
      if (run == 1 && size[0] == size[1]) CHECK(m.edge_roughness == Approx((a + b) / std::hypot(a, b)));
      check_consistent(m, scene);
    }
  }
}

TEST_CASE("cells cut loose are fragments; piece sizes come largest first", "[metrics]") {
  // 20 x 20 x 2 = 800 cells: a straight cut at x = 12 through all layers, a 2-cell patch cut
  // out of the left part and a single cell out of the right part (both through 2 layers).
  const Scene s = sheet(20, 20, 2, {cut(box(3, 5, 5, 6)), cut({{12.0, 0.0}, {12.0, 20.0}}), cut(box(16, 10, 17, 11))});
  const Metrics m = measure_scene(s);
  CHECK(m.pieces == 4);
  CHECK(m.piece_cells == std::vector<std::int64_t>{480 - 4, 320 - 2, 4, 2});
  CHECK(m.fragments == 2);
  CHECK(m.fragment_fraction == 6.0 / 800.0);
  // The sheet is in two: only the crack between the two halves is the tear.
  CHECK(m.torn_edge_length == 20.0 + 6.0 + 4.0);
  CHECK(m.edge_roughness == 1.0);
  CHECK(m.tear_length == 20.0);
  check_consistent(m, s);
}

TEST_CASE("before the sheet is in two, roughness is the length-weighted mean over all cracks", "[metrics]") {
  // Top layer only: a straight cut 6 long from the edge, and one cell's outline (length 4,
  // its far ends opposite corners, so chord sqrt 2). The longest crack is the main one.
  const Scene s = sheet(20, 20, 2, {cut({{10.0, 0.0}, {10.0, 6.0}}, 1), cut(box(3, 3, 4, 4), 1)});
  const Metrics m = measure_scene(s);
  CHECK(m.pieces == 1);
  CHECK(m.torn_edge_length == 10.0);
  CHECK(m.edge_roughness == Approx((6.0 * 1.0 + 4.0 * (4.0 / std::sqrt(2.0))) / 10.0));
  CHECK(m.tear_length == 6.0);
  check_consistent(m, s);
}

TEST_CASE("splits per tear length divides the in-plane splits by the main crack's chord", "[metrics]") {
  World w = Simulation(sheet(20, 12, 2, {cut({{8.0, 0.0}, {8.0, 12.0}})}), {.threads = 1}).world();
  for (bool interlayer : {false, false, false, true, true}) w.events.push_back(SplitEvent{.interlayer = interlayer});
  const Metrics m = measure(w);
  CHECK(m.splits_inplane == 3);
  CHECK(m.splits_per_tear_length == 3.0 / 12.0);
}

TEST_CASE("roughness is never below 1 on random cut polylines", "[metrics]") {
  std::mt19937 random(20240611u);  // raw outputs only: the same sequence on every library
  auto pick = [&](int n) { return int(random() % std::uint32_t(n)); };
  const std::array<std::array<double, 3>, 3> sizes = {{{1.0, 1.0, 1.0}, {0.3, 0.7, 1.0}, {2.0, 0.5, 1.0}}};
  for (int trial = 0; trial < 24; ++trial) {
    const int nx = 8 + pick(17), ny = 8 + pick(17);
    std::vector<LineParams> lines;
    for (int l = 1 + pick(3); l > 0; --l) {
      Polyline points;
      for (int p = 2 + pick(4); p > 0; --p) points.push_back({pick(4 * nx + 1) / 4.0, pick(4 * ny + 1) / 4.0});
      lines.push_back(cut(points, pick(3)));
    }
    const Scene s = sheet(nx, ny, 2, lines, sizes[std::size_t(trial % 3)]);
    INFO("trial " << trial << ": " << nx << " x " << ny << ", " << lines.size() << " lines");
    const Metrics m = measure_scene(s);
    check_consistent(m, s);
  }
}

TEST_CASE("the metrics stay consistent through a real tear", "[metrics]") {
  Scene s = standard::small("washi");
  Simulation sim(s, {.threads = 2});
  for (int i = 0; i < 8; ++i) {
    sim.step(100);
    INFO("step " << sim.steps_done());
    check_consistent(measure(sim.world()), s);
  }
}

TEST_CASE("the new metrics reach summary.json and survive the run state of a checkpoint", "[metrics]") {
  const Metrics m = measure_scene(sheet(20, 20, 2, {cut(box(3, 5, 5, 6)), cut({{12.0, 0.0}, {12.0, 20.0}})}));
  const nlohmann::json j = io::metrics_to_json(m);
  CHECK(j.at("piece_cells") == nlohmann::json::array({476, 320, 4}));
  CHECK(j.at("fragments") == 1);
  CHECK(j.at("fragment_fraction") == 4.0 / 800.0);
  CHECK(j.at("tear_length") == 20.0);
  CHECK(j.at("splits_per_tear_length") == 0.0);
  CHECK(j.at("edge_roughness") == 1.0);
  io::RunState state;
  state.record.frames = {m, Metrics{}};
  const io::RunState back = io::decode_run_state(io::encode_run_state(state));
  REQUIRE(back.record.frames.size() == 2);
  CHECK(io::metrics_to_json(back.record.frames[0]) == j);
  CHECK(back.record.frames[1].piece_cells.empty());
}
