// Mesh export (tools/render/mesh_export.hpp): .glb read back with TinyGLTF, .obj with a
// small reader here; both must give back the display mesh's vertices, triangles and the
// node each vertex belongs to.
#include <catch2/catch.hpp>

#include <tiny_gltf.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "core/lattice_builder.hpp"
#include "core/simulation.hpp"
#include "core/scene.hpp"
#include "tools/render/render.hpp"
#include "tools/render/video.hpp"
#include "tools/run_frames.hpp"
#include "tests/gltf_files.hpp"

using namespace papertear;
using namespace papertear::render;
namespace fs = std::filesystem;
using papertear::testing::read_floats;

namespace {

// A fresh directory under the system's temporary folder, removed afterwards.
struct TempDir {
  fs::path path;
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "papertear-export-XXXXXX").string();
    REQUIRE(::mkdtemp(pattern.data()) != nullptr);
    path = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

// A sheet whose right half (i >= nx/2) has been split off and moved away, so that torn faces
// and their fibres are part of the mesh and some nodes are copies of others.
World torn_sheet(int nx, int ny, int nl) {
  Scene scene;
  scene.sheet.cells = {nx, ny, nl};
  World w;
  build_lattice(scene, w);
  const LatticeDims& d = w.topo.dims;
  const std::size_t before = w.nodes.count;
  std::vector<std::uint32_t> copy(before, 0);
  for (std::uint32_t n = 0; n < before; ++n) {
    if (d.vertex_ijk(n)[0] != nx / 2) continue;
    const std::size_t id = w.nodes.count;
    w.nodes.resize(id + 1);
    w.nodes.px[id] = w.nodes.px[n];
    w.nodes.py[id] = w.nodes.py[n];
    w.nodes.pz[id] = w.nodes.pz[n];
    w.nodes.vertex[id] = n;
    copy[n] = std::uint32_t(id);
  }
  std::vector<char> moved(w.nodes.count, 0);
  for (std::uint32_t c = 0; c < d.cells(); ++c) {
    if (d.cell_ijk(c)[0] < nx / 2) continue;
    for (int q = 0; q < 8; ++q) {
      std::uint32_t& n = w.topo.cell_nodes[std::size_t(c) * 8 + std::size_t(q)];
      if (n < before && d.vertex_ijk(n)[0] == nx / 2) n = copy[n];
      if (!moved[n]) w.nodes.px[n] += 2.0f;
      moved[n] = 1;
    }
  }
  return w;
}

// What the OBJ reader found.
struct ObjContents {
  std::vector<std::array<float, 3>> v;
  std::size_t vt = 0, vn = 0;
  std::vector<std::array<std::uint32_t, 2>> node;  // (original, current) per '#node' line
  std::vector<std::array<long, 3>> faces;          // position indices, 1-based
  std::set<std::string> materials_used;
  std::string mtllib;
};

ObjContents read_obj(const fs::path& path) {
  ObjContents obj;
  std::ifstream in(path);
  REQUIRE(in);
  std::string line, word, current_material;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    s >> word;
    if (word == "v") {
      std::array<float, 3> p{};
      s >> p[0] >> p[1] >> p[2];
      obj.v.push_back(p);
    } else if (word == "#node") {
      std::array<std::uint32_t, 2> n{};
      s >> n[0] >> n[1];
      REQUIRE(obj.node.size() + 1 == obj.v.size());  // right after its 'v' line
      obj.node.push_back(n);
    } else if (word == "vt") {
      ++obj.vt;
    } else if (word == "vn") {
      ++obj.vn;
    } else if (word == "f") {
      std::array<long, 3> f{};
      std::string corner;
      for (long& index : f) {
        s >> corner;
        index = std::stol(corner.substr(0, corner.find('/')));
      }
      obj.faces.push_back(f);
      obj.materials_used.insert(current_material);
    } else if (word == "usemtl") {
      s >> current_material;
    } else if (word == "mtllib") {
      s >> obj.mtllib;
    }
  }
  return obj;
}

}  // namespace

TEST_CASE("a .glb loads back with its vertices, triangles and original nodes", "[export]") {
  const World w = torn_sheet(10, 6, 3);
  const SurfaceMesh mesh = build_surface_mesh(w);
  const Image print = default_print(64);
  TempDir dir;
  const fs::path file = dir.path / "sheet.glb";
  export_glb(mesh, file, {.print = &print});

  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  REQUIRE(loader.LoadBinaryFromFile(&model, &err, &warn, file.string()));
  INFO(err << warn);
  // The sheet (print, paper and torn faces) and the frayed fibres, each a mesh of its own.
  REQUIRE(model.meshes.size() == 2);
  CHECK(model.meshes[0].name == "sheet");
  CHECK(model.meshes[1].name == "fibres");
  REQUIRE(model.nodes.size() == 2);
  const auto& prims = model.meshes[0].primitives;
  REQUIRE(prims.size() == 3);  // print, paper, torn faces
  std::size_t triangles = 0;
  for (const auto& m : model.meshes)
    for (const auto& p : m.primitives) {
      triangles += model.accessors[std::size_t(p.indices)].count / 3;
      CHECK(p.attributes.count("NORMAL") == (m.name == "sheet" ? 1u : 0u));  // fibres: flat-shaded
      CHECK(p.attributes.count("TEXCOORD_0") == 1);
    }
  CHECK(model.accessors[std::size_t(prims[0].attributes.at("POSITION"))].count == mesh.sheet_vertices);
  CHECK(mesh.sheet_triangles < mesh.triangle_count());
  // The fibres share their vertices, and keep every corner where it was.
  const auto& fibres = model.meshes[1].primitives.at(0);
  const std::vector<float> fpos = read_floats(model, fibres.attributes.at("POSITION"));
  CHECK(fpos.size() / 3 < (mesh.vertex_count() - mesh.sheet_vertices) / 2);
  const tinygltf::Accessor& fi = model.accessors[std::size_t(fibres.indices)];
  REQUIRE(fi.count == 3 * (mesh.triangle_count() - mesh.sheet_triangles));
  const auto* findex = reinterpret_cast<const std::uint32_t*>(
      model.buffers[0].data.data() + model.bufferViews[std::size_t(fi.bufferView)].byteOffset);
  for (std::size_t t = mesh.sheet_triangles; t < mesh.triangle_count(); ++t)
    for (std::size_t c = 0; c < 3; ++c) {
      const std::uint32_t v = findex[3 * (t - mesh.sheet_triangles) + c];
      const std::array<float, 3>& p = mesh.position[mesh.triangles[t][c]];
      CHECK(fpos[3 * v] == p[0] * 0.001f);
      CHECK(fpos[3 * v + 2] == -p[1] * 0.001f);
    }
  CHECK(triangles == mesh.triangle_count());
  const std::vector<float> original = read_floats(model, prims[0].attributes.at("_ORIGINAL_NODE"));
  const std::vector<float> node = read_floats(model, prims[0].attributes.at("_NODE"));
  REQUIRE(original.size() == mesh.sheet_vertices);
  const std::vector<float> ids = read_floats(model, prims[0].attributes.at("TEXCOORD_1"));  // for Blender
  REQUIRE(ids.size() == 2 * mesh.sheet_vertices);
  bool saw_copy = false;
  for (std::size_t v = 0; v < mesh.sheet_vertices; ++v) {
    CHECK(original[v] == float(mesh.original_node[v]));
    CHECK(node[v] == float(mesh.node[v]));
    CHECK(ids[2 * v] == node[v]);
    CHECK(ids[2 * v + 1] == original[v]);
    saw_copy |= node[v] != original[v];
  }
  CHECK(saw_copy);
  // glTF's frame: y up, metres; simulation (x, y, z) mm -> (x, z, -y) * 0.001.
  const std::vector<float> pos = read_floats(model, prims[0].attributes.at("POSITION"));
  const std::vector<float> normal = read_floats(model, prims[0].attributes.at("NORMAL"));
  bool saw_height = false;
  for (std::size_t v = 0; v < mesh.sheet_vertices; ++v) {
    CHECK(pos[3 * v] == mesh.position[v][0] * 0.001f);
    CHECK(pos[3 * v + 1] == mesh.position[v][2] * 0.001f);
    CHECK(pos[3 * v + 2] == -mesh.position[v][1] * 0.001f);
    CHECK(normal[3 * v + 1] == mesh.normal[v][2]);
    saw_height |= pos[3 * v + 1] != 0.0f;
  }
  CHECK(saw_height);
  REQUIRE(model.asset.extras.IsObject());
  CHECK(model.asset.extras.Get("unit").Get<std::string>() == "m");
  CHECK(model.asset.extras.Get("metres_per_unit").GetNumberAsDouble() == 0.001);
  // The print travels inside the file, as a PNG.
  REQUIRE(model.images.size() == 1);
  CHECK(model.images[0].width == 64);
  CHECK(model.materials[std::size_t(prims[0].material)].pbrMetallicRoughness.baseColorTexture.index == 0);
}

TEST_CASE("an .obj loads back with its vertices, triangles and original nodes", "[export]") {
  const World w = torn_sheet(8, 5, 2);
  const SurfaceMesh mesh = build_surface_mesh(w);
  TempDir dir;
  const fs::path file = dir.path / "sheet.obj";
  export_obj(mesh, file, {.print_file = "print.png"});

  const ObjContents obj = read_obj(file);
  REQUIRE(obj.v.size() == mesh.vertex_count());
  CHECK(obj.vt == mesh.vertex_count());
  CHECK(obj.vn == mesh.vertex_count());
  REQUIRE(obj.node.size() == mesh.vertex_count());
  CHECK(obj.faces.size() == mesh.triangle_count());
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    CHECK(obj.node[v][0] == mesh.original_node[v]);
    CHECK(obj.node[v][1] == mesh.node[v]);
    // glTF's frame (y up, metres); shortest round-trip formatting is exact.
    const std::array<float, 3> p = mesh.position[v];
    CHECK(obj.v[v] == std::array<float, 3>{p[0] * 0.001f, p[2] * 0.001f, -p[1] * 0.001f});
  }
  for (const auto& f : obj.faces)
    for (long index : f) CHECK((index >= 1 && std::size_t(index) <= mesh.vertex_count()));
  CHECK(obj.materials_used == std::set<std::string>{"print", "paper", "fibre"});
  CHECK(obj.mtllib == "sheet.mtl");
  std::ifstream mtl(dir.path / "sheet.mtl");
  std::stringstream text;
  text << mtl.rdbuf();
  CHECK_THAT(text.str(), Catch::Contains("newmtl fibre") && Catch::Contains("map_Kd print.png"));
}

TEST_CASE("a mesh names its frame, step, time, fps and digest", "[export]") {
  const World w = torn_sheet(6, 4, 1);
  const SurfaceMesh mesh = build_surface_mesh(w);
  TempDir dir;
  const FrameInfo info{3, 120, 22.5, 24, 0x00ab3eaf0b63a742ull};
  export_glb(mesh, dir.path / "f.glb", {.frame = info});
  export_obj(mesh, dir.path / "f.obj", {.frame = info});
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  REQUIRE(loader.LoadBinaryFromFile(&model, &err, &warn, (dir.path / "f.glb").string()));
  const tinygltf::Value& x = model.asset.extras;
  CHECK(x.Get("frame").GetNumberAsInt() == 3);
  CHECK(x.Get("step").GetNumberAsDouble() == 120.0);
  CHECK(x.Get("time_us").GetNumberAsDouble() == 22.5);
  CHECK(x.Get("fps").GetNumberAsInt() == 24);
  CHECK(x.Get("digest").Get<std::string>() == "00ab3eaf0b63a742");
  std::ifstream obj(dir.path / "f.obj");
  std::stringstream text;
  text << obj.rdbuf();
  CHECK_THAT(text.str(), Catch::Contains("# frame 3 step 120 time_us 22.5 fps 24 digest 00ab3eaf0b63a742\n"));
}

TEST_CASE("exports leave no temporary files behind", "[export]") {
  const World w = torn_sheet(6, 4, 2);
  const SurfaceMesh mesh = build_surface_mesh(w);
  TempDir dir;
  export_glb(mesh, dir.path / "a.glb");
  export_obj(mesh, dir.path / "a.obj");
  write_png(dir.path / "a.png", default_print(32));
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir.path)) names.insert(entry.path().filename().string());
  CHECK(names == std::set<std::string>{"a.glb", "a.mtl", "a.obj", "a.png"});
  CHECK(read_png(dir.path / "a.png").rgb == default_print(32).rgb);
  CHECK_THROWS(export_glb(mesh, dir.path / "missing" / "b.glb"));
}

TEST_CASE("the run's render sinks write frames and meshes as [output] asks", "[export]") {
  Scene scene;
  scene.sheet.cells = {12, 10, 2};
  scene.run.frames = 2;
  Simulation sim(scene, {.threads = 1});
  const toml::table config = toml::parse(R"(
    [render]
    width = 48
    height = 32
    samples = 1
    [output]
    prefix = "shot"
    mesh = "both"
    mesh_frames = "last"
    video = false
    animation = false
  )");
  TempDir dir;
  auto sinks = make_render_sinks(config, {}, dir.path);
  REQUIRE(sinks.size() == 1);
  CHECK(fs::is_empty(dir.path));  // constructing writes nothing
  sinks[0]->on_start(sim);
  sinks[0]->on_frame(sim, 0, 2, Metrics{});
  sinks[0]->on_frame(sim, 1, 2, Metrics{});
  auto names_in = [](const fs::path& d) {
    std::set<std::string> names;
    for (const auto& entry : fs::directory_iterator(d)) names.insert(entry.path().filename().string());
    return names;
  };
  CHECK(names_in(dir.path) == std::set<std::string>{"frames", "mesh"});
  CHECK(names_in(dir.path / "frames") == std::set<std::string>{"shot_0000.png", "shot_0001.png"});
  // Meshes for the last frame only (as asked), the print once for the .mtl.
  CHECK(names_in(dir.path / "mesh") ==
        std::set<std::string>{"shot_0001.glb", "shot_0001.obj", "shot_0001.mtl", "shot_print.png"});
  CHECK(read_png(dir.path / "frames" / "shot_0001.png").width == 48);
}

TEST_CASE("a bad [output] table is named", "[export]") {
  auto error_of = [](const char* text) -> std::string {
    try {
      make_render_sinks(toml::parse(text), {}, "unused");
    } catch (const SceneError& e) {
      return e.what();
    }
    return "";
  };
  CHECK_THAT(error_of("[output]\nmesh = \"fbx\""), Catch::Contains("output.mesh"));
  CHECK_THAT(error_of("[output]\nmesh_frame = \"all\""), Catch::Contains("output.mesh_frames"));
  CHECK_THAT(error_of("[output]\nprefix = \"a/b\""), Catch::Contains("output.prefix"));
  CHECK_THAT(error_of("[output]\npng = 1"), Catch::Contains("output.png"));
  CHECK_THAT(error_of("[output]\nanimation = \"yes\""), Catch::Contains("output.animation"));
  CHECK(make_render_sinks(toml::parse("[output]\npng = false\nmesh = \"none\"\nanimation = false"), {}, "unused")
            .empty());
}

TEST_CASE("without ffmpeg the video is skipped with one notice, with it video.mp4 appears", "[export]") {
  Scene scene;
  scene.sheet.cells = {4, 4, 1};
  scene.load.kind = "none";
  Simulation sim(scene, {.threads = 1});
  TempDir dir;
  fs::create_directories(dir.path / "frames");
  fs::create_directories(dir.path / "bin");
  CHECK_FALSE(find_on_path("ffmpeg", (dir.path / "bin").string()).has_value());

  std::ostringstream log;
  VideoSink absent(dir.path / "frames", "frame", dir.path, 15, (dir.path / "bin").string(), log);
  absent.on_finish(sim, io::RunRecord{});
  const std::string notice = log.str();
  CHECK_THAT(notice, Catch::Contains("ffmpeg is not on the PATH"));
  CHECK(std::count(notice.begin(), notice.end(), '\n') == 1);
  CHECK_FALSE(fs::exists(dir.path / "video.mp4"));

  // A stand-in ffmpeg that writes its last argument: the sink's temporary file is renamed.
  const fs::path fake = dir.path / "bin" / "ffmpeg";
  std::ofstream(fake) << "#!/bin/sh\nfor a; do last=$a; done\necho video > \"$last\"\n";
  fs::permissions(fake, fs::perms::owner_all);
  REQUIRE(find_on_path("ffmpeg", "/nonexistent:" + (dir.path / "bin").string()) == fake);
  std::ostringstream quiet;
  VideoSink present(dir.path / "frames", "frame", dir.path, 15, (dir.path / "bin").string(), quiet);
  present.on_finish(sim, io::RunRecord{});
  CHECK(quiet.str().empty());
  CHECK(fs::exists(dir.path / "video.mp4"));
  CHECK_FALSE(fs::exists(dir.path / ".video.mp4.partial"));
}
