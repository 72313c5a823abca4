// Scene files: every key type, preset-then-override order, --set values, and the errors a
// person gets for a mistyped key, a syntax error, a wrong type or an impossible value.
#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "tools/scene_fields.hpp"
#include "tools/scene_file.hpp"
#include "tools/summary.hpp"
#include "tools/toml_keys.hpp"

namespace pt = papertear;
namespace io = papertear::io;
using Catch::Matchers::Contains;

namespace {

io::SceneFile parse(const std::string& text, std::vector<io::SetOverride> overrides = {}) {
  return io::parse_scene(text, "test.toml", overrides);
}

// The message of the SceneError that parsing `text` throws ("" if it does not throw).
std::string error_of(const std::string& text, std::vector<io::SetOverride> overrides = {}) {
  try {
    parse(text, overrides);
  } catch (const pt::SceneError& e) {
    return e.what();
  }
  return "";
}

std::string set_error(const std::string& argument) {
  try {
    io::default_scene_file(std::vector{io::parse_set_argument(argument)});
  } catch (const pt::SceneError& e) {
    return e.what();
  }
  return "";
}

pt::MaterialParams preset(const std::string& name) {
  pt::MaterialParams m;
  pt::apply_material_preset(m, name);
  return m;
}

// Counts an aggregate's members: the longest brace list of "anything" it accepts.
struct AnyField {
  template <class T>
  operator T() const;
};
template <class T, class... A>
constexpr std::size_t member_count() {
  if constexpr (requires { T{A{}..., AnyField{}}; })
    return member_count<T, A..., AnyField>();
  else
    return sizeof...(A);
}

std::size_t keys_in_section(const std::string& section) {
  std::size_t n = 0;
  for (const std::string& k : io::scene_keys()) n += k.starts_with(section + ".") ? 1 : 0;
  return n;
}

}  // namespace

TEST_CASE("scene_keys lists every Scene field once", "[scene]") {
  // Fails when a field is added to core/scene.hpp but not to tools/scene_fields.hpp.
  CHECK(keys_in_section("sheet") == member_count<pt::SheetParams>());
  CHECK(keys_in_section("material") == member_count<pt::MaterialParams>());
  CHECK(keys_in_section("load") == member_count<pt::LoadParams>());
  CHECK(keys_in_section("world") == member_count<pt::WorldParams>());
  CHECK(keys_in_section("run") == member_count<pt::RunParams>());
  CHECK(member_count<pt::Scene>() == 6);  // the five sections and the [[line]] list
  const auto& keys = io::scene_keys();
  CHECK(std::count(keys.begin(), keys.end(), "line") == 1);
  std::size_t line_fields = 0;
  const pt::LineParams line;
  io::visit_line_fields(line, [&](std::string_view, auto&&) { ++line_fields; });
  CHECK(line_fields == member_count<pt::LineParams>());
}

TEST_CASE("every key type is read from a scene file", "[scene]") {
  const io::SceneFile f = parse(R"(
[sheet]
cells = [12, 10, 3]
cell_size = [1, 1.5, 0.5]   # integers are accepted as numbers

[material]
grain = "y"
density = 650
E_md = 4125.5
block_width = 3

[load]
kind = "none"
axis = "y"
speed = 0.05
notch = 0

[world]
gravity = [0.0, 0.0, -0.5]
drag = 0.01

[run]
steps = 77
dt = 0.004
frames = 7
seed = 12345678901
max_splits_per_step = 5
)");
  const pt::Scene& s = f.scene;
  CHECK(s.sheet.cells == std::array<int, 3>{12, 10, 3});
  CHECK(s.sheet.cell_size == std::array<double, 3>{1.0, 1.5, 0.5});
  CHECK(s.material.density == 650.0);
  CHECK(s.material.grain == 'y');
  CHECK(s.material.E_md == 4125.5);
  CHECK(s.material.block_width == 3);
  CHECK(s.load.kind == "none");
  CHECK(s.load.axis == 'y');
  CHECK(s.load.speed == 0.05);
  CHECK(s.load.notch == 0);
  CHECK(s.world.gravity == std::array<double, 3>{0.0, 0.0, -0.5});
  CHECK(s.world.drag == 0.01);
  CHECK(s.run.steps == 77);
  CHECK(s.run.dt == 0.004);
  CHECK(s.run.frames == 7);
  CHECK(s.run.seed == 12345678901ull);
  CHECK(s.run.max_splits_per_step == 5);
  CHECK(f.path == "test.toml");
  // Keys left out keep their defaults.
  CHECK(s.material.E_cd == pt::MaterialParams{}.E_cd);
}

TEST_CASE("run.dt is a number or the word auto", "[scene]") {
  CHECK(parse("run.dt = \"auto\"").scene.run.dt == 0.0);
  CHECK(parse("run.dt = 0.01").scene.run.dt == 0.01);
  CHECK_THAT(error_of("run.dt = \"fast\""), Contains("run.dt") && Contains("\"auto\""));
  CHECK_THAT(error_of("run.dt = true"), Contains("run.dt") && Contains("a number or"));
}

TEST_CASE("material.preset applies first and the other material keys override it", "[scene]") {
  const pt::MaterialParams washi = preset("washi");
  REQUIRE(washi.fiber_length != pt::MaterialParams{}.fiber_length);  // the test needs a change
  for (const char* text : {"[material]\nE_zd = 3.5\npreset = \"washi\"\n",
                           "[material]\npreset = \"washi\"\nE_zd = 3.5\n"}) {
    const pt::MaterialParams m = parse(text).scene.material;
    CHECK(m.preset == "washi");
    CHECK(m.E_zd == 3.5);                          // the key wins over the preset
    CHECK(m.fiber_length == washi.fiber_length);   // the rest comes from the preset
    CHECK(m.strain_inter == washi.strain_inter);
  }
  SECTION("a preset given with --set still yields to the file's material keys") {
    const pt::MaterialParams m =
        parse("[material]\nstrain_surface = 0.5\n", {{"material.preset", "coated"}}).scene.material;
    CHECK(m.preset == "coated");
    CHECK(m.strain_surface == 0.5);
    CHECK(m.strain_intra == preset("coated").strain_intra);
  }
  SECTION("an unknown preset names the key and its line") {
    CHECK_THAT(error_of("[material]\npreset = \"cardboard\"\n"),
               Contains("test.toml:2:") && Contains("material.preset") && Contains("cardboard"));
  }
}

TEST_CASE("set overrides are TOML values and bare words are strings", "[scene]") {
  const std::vector<io::SetOverride> overrides = {
      io::parse_set_argument("sheet.cells=[30, 20,4]"),
      io::parse_set_argument("run.steps=200"),
      io::parse_set_argument("material.density=2.5e2"),
      io::parse_set_argument("material.grain=y"),
      io::parse_set_argument("material.preset = kraft"),
      io::parse_set_argument("load.kind=\"none\""),
      io::parse_set_argument("run.dt=auto"),
  };
  CHECK(overrides[4].key == "material.preset");
  CHECK(overrides[4].value == "kraft");
  const pt::Scene s = parse("run.dt = 0.001\nrun.steps = 5\n", overrides).scene;
  CHECK(s.sheet.cells == std::array<int, 3>{30, 20, 4});
  CHECK(s.run.steps == 200);  // the command line wins over the file
  CHECK(s.material.density == 250.0);
  CHECK(s.material.grain == 'y');
  CHECK(s.material.preset == "kraft");
  CHECK(s.material.fiber_length == preset("kraft").fiber_length);
  CHECK(s.load.kind == "none");
  CHECK(s.run.dt == 0.0);
}

TEST_CASE("set override errors name the argument", "[scene]") {
  CHECK_THAT(set_error("run.steps"), Contains("--set run.steps") && Contains("key=value"));
  CHECK_THAT(set_error("run.steps="), Contains("empty"));
  CHECK_THAT(set_error("=5"), Contains("key"));
  CHECK_THAT(set_error("run..steps=5"), Contains("dotted key"));
  CHECK_THAT(set_error("sheet.cells=[1,2"), Contains("--set sheet.cells=[1,2") && Contains("TOML"));
  CHECK_THAT(set_error("run.steps=12abc"), Contains("not a TOML value"));
  CHECK_THAT(set_error("run.steps=abc"),
             Contains("--set run.steps=abc") && Contains("expected an integer") && Contains("\"abc\""));
  CHECK_THAT(set_error("run.steps=1\nrun.frames=2"), Contains("single TOML value"));
  CHECK_THAT(set_error("run.stpes=5"), Contains("did you mean 'run.steps'"));
  CHECK_THAT(error_of("sheet.cells = [6, 6, 2]", {{"sheet.cells.x", "5"}}),
             Contains("--set sheet.cells.x=5") && Contains("'sheet.cells' is not a table"));
  CHECK_THAT(set_error("sheet.cells=[0,6,2]"),
             Contains("--set sheet.cells=[0,6,2]") && Contains("sheet.cells"));
}

TEST_CASE("unknown keys are refused with the nearest known key", "[scene]") {
  CHECK_THAT(error_of("[sheet]\ncels = [6, 6, 2]\n"),
             Contains("test.toml:2:") && Contains("unknown key 'sheet.cels'") &&
                 Contains("did you mean 'sheet.cells'"));
  CHECK_THAT(error_of("[rnu]\nsteps = 5\n"), Contains("did you mean 'run.steps'"));
  CHECK_THAT(error_of("steps = 5\n"), Contains("did you mean 'run.steps'"));
  CHECK_THAT(error_of("[material]\nE_mdd = 2.0\n"), Contains("did you mean 'material.E_md'"));
  CHECK_THAT(error_of("[rendr]\nwidth = 640\n"), Contains("did you mean 'render.width'"));
  CHECK_THAT(error_of("[physics]\ngravity = 1\n"), Contains("did you mean 'world.gravity'"));
  CHECK_THAT(error_of("[physics]\nmass = 1\n"),
             Contains("unknown key 'physics.mass'") && Contains("sections are: sheet"));
  CHECK_THAT(error_of("sheet = 5\n"), Contains("sheet") && Contains("expected a table"));
}

TEST_CASE("a TOML syntax error gives file and line and column", "[scene]") {
  const std::string message = error_of("[material]\ndensity = 800.0\ncells = [6, 6, 2\n");
  CHECK_THAT(message, Contains("test.toml:3:") && Contains("syntax error"));
  CHECK_THAT(error_of("[run]\nsteps = 10\nsteps = 20\n"), Contains("test.toml:3:"));
}

TEST_CASE("a value of the wrong type names the key and the expected type", "[scene]") {
  CHECK_THAT(error_of("[material]\ndensity = \"heavy\"\n"),
             Contains("test.toml:2:") && Contains("material.density") &&
                 Contains("expected a number, got a string (\"heavy\")"));
  CHECK_THAT(error_of("sheet.cells = [6, 6]"), Contains("sheet.cells") && Contains("array of 3 integers"));
  CHECK_THAT(error_of("sheet.cells = [6, 6.5, 2]"),
             Contains("sheet.cells[1]") && Contains("expected an integer"));
  CHECK_THAT(error_of("run.steps = 2.5"), Contains("run.steps") && Contains("expected an integer"));
  CHECK_THAT(error_of("run.steps = 99999999999"), Contains("run.steps") && Contains("out of range"));
  CHECK_THAT(error_of("run.seed = -1"), Contains("run.seed") && Contains("negative"));
  CHECK_THAT(error_of("material.grain = \"xy\""), Contains("material.grain") && Contains("one-letter"));
  CHECK_THAT(error_of("load.kind = 3"), Contains("load.kind") && Contains("expected a string"));
}

TEST_CASE("NaN and infinity are refused", "[scene]") {
  CHECK_THAT(error_of("material.E_md = nan"), Contains("material.E_md") && Contains("finite"));
  CHECK_THAT(error_of("material.density = inf"), Contains("material.density") && Contains("finite"));
  CHECK_THAT(error_of("world.gravity = [0.0, -inf, 0.0]"),
             Contains("world.gravity[1]") && Contains("finite"));
}

TEST_CASE("zero or negative cell counts are refused where they are written", "[scene]") {
  CHECK_THAT(error_of("[sheet]\ncells = [0, 10, 2]\n"), Contains("test.toml:2:") && Contains("sheet.cells"));
  CHECK_THAT(error_of("[sheet]\ncells = [10, -3, 2]\n"), Contains("sheet.cells"));
  CHECK_THAT(error_of("[sheet]\ncells = [10, 10, 0]\n"), Contains("sheet.cells"));
  CHECK_THAT(error_of("run.frames = 0"), Contains("run.frames"));
}

TEST_CASE("the renderer sections are passed through with their sources", "[scene]") {
  const io::SceneFile f = parse("[render]\nwidth = 640\n[camera]\nfov = 30.0\n[sheet]\ncells = [8, 8, 2]\n",
                                {{"render.height", "360"}});
  REQUIRE(f.render_config.contains("render"));
  CHECK(f.render_config.at_path("render.width").value<std::int64_t>() == 640);
  CHECK(f.render_config.at_path("render.height").value<std::int64_t>() == 360);
  CHECK(f.render_config.at_path("camera.fov").value<double>() == 30.0);
  CHECK(!f.render_config.contains("sheet"));
  // The renderer reports its errors at the place they were written, like the scene does.
  CHECK(io::where(*f.render_config.at_path("render.width").node()) == "test.toml:2:9");
  CHECK(io::where(*f.render_config.at_path("render.height").node()) == "--set render.height=360");
  CHECK_THAT(error_of("render = 3"), Contains("render") && Contains("expected a table"));
}

TEST_CASE("a missing scene file is named", "[scene]") {
  try {
    io::load_scene_file("no/such/scene.toml");
    FAIL("no error");
  } catch (const pt::SceneError& e) {
    CHECK_THAT(e.what(), Contains("no/such/scene.toml") && Contains("not found"));
  }
}

TEST_CASE("the example scenes load and paper.toml is the default scene", "[scene]") {
  const std::filesystem::path dir = std::filesystem::path(PAPERTEAR_SOURCE_DIR) / "tools" / "scenes";
  const io::SceneFile paper = io::load_scene_file((dir / "paper.toml").string());
  INFO("tools/scenes/paper.toml spells out the defaults of core/scene.hpp: update it with them");
  CHECK(io::scene_to_json(paper.scene) == io::scene_to_json(pt::Scene{}));

  const io::SceneFile coated = io::load_scene_file((dir / "coated.toml").string());
  CHECK(coated.scene.material.preset == "coated");
  CHECK(coated.scene.material.strain_surface == preset("coated").strain_surface);
  const io::SceneFile washi = io::load_scene_file((dir / "washi.toml").string());
  CHECK(washi.scene.material.fiber_length == preset("washi").fiber_length);
  const io::SceneFile across = io::load_scene_file((dir / "across_grain.toml").string());
  CHECK(across.scene.material.grain == 'y');
  CHECK(across.scene.load.axis == 'x');
  const io::SceneFile scored = io::load_scene_file((dir / "scored.toml").string());
  REQUIRE(scored.scene.lines.size() == 1);
  CHECK(scored.scene.lines[0].kind == "score");
  CHECK(scored.scene.lines[0].points.front() == std::array<double, 2>{45.0, 4.0});  // the notch's tip
}

TEST_CASE("scene_to_toml writes a scene that reads back the same", "[scene]") {
  pt::Scene s;
  s.sheet.cells = {14, 9, 3};
  s.sheet.cell_size = {1.0, 0.75, 0.5};
  s.material.grain = 'y';
  s.material.G_md_zd = 62.5;
  s.load.kind = "none";
  s.world.gravity = {0.0, 0.0, -1.0};
  s.run.dt = 0.003;
  s.run.seed = 99;
  std::ostringstream text;
  text << io::scene_to_toml(s);
  const pt::Scene back = io::parse_scene(text.str(), "written.toml").scene;
  CHECK(io::scene_to_json(back) == io::scene_to_json(s));
  CHECK(io::scene_to_json(back)["run"]["dt"] == 0.003);
  CHECK(io::scene_to_json(pt::Scene{})["run"]["dt"] == "auto");
}

TEST_CASE("key suggestions: edit distance and nearest key", "[scene]") {
  CHECK(io::edit_distance("", "abc") == 3);
  CHECK(io::edit_distance("steps", "steps") == 0);
  CHECK(io::edit_distance("stpes", "steps") == 1);  // a swap is one typo
  CHECK(io::edit_distance("kitten", "sitting") == 3);
  const std::vector<std::string> known = {"sheet.cells", "run.steps", "render"};
  CHECK(io::nearest_key("sheet.cels", known) == "sheet.cells");
  CHECK(io::nearest_key("rnu.steps", known) == "run.steps");
  CHECK(io::nearest_key("rendr.width", known) == "render.width");
  CHECK(io::nearest_key("steps", known) == "run.steps");
  CHECK(!io::nearest_key("gravity", known).has_value());
}
