// A host application on the installed package's papertear::io and papertear::render: reads a
// scene from TOML text with --set style overrides, runs it through the CLI's frame loop,
// writes summary.json and exports the surface mesh as glb. Exit status 0 means the installed
// headers, libraries and their dependencies work together.
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <tools/render/mesh_export.hpp>
#include <tools/render/surface.hpp>
#include <tools/run_frames.hpp>
#include <tools/scene_file.hpp>
#include <tools/scene_setup.hpp>
#include <tools/summary.hpp>

namespace {

std::string read_all(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

int check(const std::filesystem::path& dir) {
  using namespace papertear;
  const std::vector<io::SetOverride> sets = {io::parse_set_argument("run.steps=40"),
                                             io::parse_set_argument("run.frames=2")};
  io::SceneFile file = io::parse_scene("[sheet]\ncells = [10, 8, 2]\n[load]\nkind = \"pull\"\n", "host.toml", sets);
  Simulation sim = io::make_simulation(file, 2);
  const io::RunRecord record = io::run_frames(sim, {}, nullptr);
  std::filesystem::create_directories(dir);
  io::write_summary(dir, file.scene, {"host.toml", 2, Simulation::stable_dt_limit(file.scene)}, record);
  const nlohmann::json summary = nlohmann::json::parse(read_all(dir / "summary.json"));
  if (summary.at("digest") != io::digest_hex(sim.digest()) || summary.at("steps") != 40 ||
      summary.at("frames").size() != 2) {
    std::fprintf(stderr, "FAIL: summary.json does not describe the run: %s\n", summary.dump().c_str());
    return 1;
  }
  render::export_glb(render::build_surface_mesh(sim.world()), dir / "sheet.glb");
  const std::string glb = read_all(dir / "sheet.glb");
  if (glb.size() < 1000 || glb.compare(0, 4, "glTF") != 0) {
    std::fprintf(stderr, "FAIL: sheet.glb is not a glTF binary (%zu bytes)\n", glb.size());
    return 1;
  }
  std::printf("host: digest %s after %lld steps, glb %zu bytes\nOK\n", summary.at("digest").get<std::string>().c_str(),
              static_cast<long long>(record.steps_done), glb.size());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return check(argc > 1 ? argv[1] : "host-out");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "FAIL: %s\n", e.what());
    return 1;
  }
}
