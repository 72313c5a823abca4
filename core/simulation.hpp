// The embedding API. A Simulation owns its whole state; there is no global state, so any
// number of them can live in one process. Results are bit-for-bit the same on any thread
// count: see kernels/parallel.hpp for why.
//
//   papertear::Scene scene;                 // defaults: a thin 120 × 80 × 3 copy sheet
//   scene.sheet.cells = {30, 30, 5};
//   papertear::Simulation sim(scene, {.threads = 2});
//   sim.step(100);
//   std::uint64_t h = sim.digest();
#pragma once
#include <cstdint>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>

#include <oneapi/tbb/task_arena.h>

#include "core/scene.hpp"
#include "core/world.hpp"


namespace papertear {

// The state became non-finite or ran away; names the step and the first bad node.
struct BlowUpError : std::runtime_error {
  BlowUpError(const std::string& what, std::int64_t step_, std::uint32_t node_)
      : std::runtime_error(what), step(step_), node(node_) {}
  std::int64_t step;
  std::uint32_t node;
};

struct SimulationOptions {
  int threads = 0;                      // 0: all hardware threads
  tbb::task_arena* arena = nullptr;     // a caller's arena (then `threads` is ignored)
};

// Read-only views of the node columns (valid until the next step()).
struct NodeView {
  std::size_t count;
  std::span<const float> px, py, pz, vx, vy, vz, mass;
  std::span<const std::uint32_t> vertex;  // the lattice vertex each node sits at
};

struct TopologyView {
  LatticeDims dims;
  std::span<const std::uint32_t> cell_nodes;  // 8 per cell, corner q = dx | dy<<1 | dz<<2
};

struct Energies {
  double kinetic = 0.0;
  double elastic = 0.0;  // fine and coarse springs
};

class Simulation {
 public:
  // Builds the lattice, fibre blocks and grips; throws SceneError for an invalid scene or a
  // time step above the stable limit (the message gives the limit).
  explicit Simulation(const Scene& scene, SimulationOptions options = {});
  // Resumes from a saved world (checkpoints).
  Simulation(World world, SimulationOptions options);
  ~Simulation();
  Simulation(Simulation&&) noexcept;
  Simulation& operator=(Simulation&&) noexcept;

  // Advances n steps: RK4 then the serial fracture pass, each step. Throws BlowUpError.
  void step(int n = 1);

  std::int64_t steps_done() const;
  double time() const;
  double dt() const;
  const Scene& scene() const;

  NodeView nodes() const;
  TopologyView topology() const;
  const World& world() const;  // everything, read-only (renderers, metrics, checkpoints)

  // 64-bit hash of the raw bits of positions, velocities and the cell→corner→node table.
  std::uint64_t digest() const;
  Energies energies() const;

  // The largest stable RK4 step for a scene, from the stiffest spring sum per node mass.
  static double stable_dt_limit(const Scene& scene);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace papertear
