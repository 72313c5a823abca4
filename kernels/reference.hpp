// The reference implementation: the same elastic model written plainly — scalar, double
// precision, array of structs, one explicit list of springs. It is the tests' oracle for the
// SIMD/TBB kernels and the benchmarks' baseline. It reads the topology of a World (so it
// also works on a torn sheet) but never edits it: fracture is not part of the reference.
//
// Semantics, identical to the solver (core/solver.hpp):
//  * springs: the 28 springs of every cell (kSpringSlots, rest/stiffness/damping from the
//    world's SpringTable, stiffness and damping scaled by the cell's factor) and every
//    block-lattice spring with non-zero stiffness or damping;
//  * force of a spring a→b: d = x_b - x_a, L = |d|, f_a = (k (L - L0) + c (Δv·d)/L) d/L;
//  * acceleration of a free node: F/m + gravity - drag * v; gripped nodes: 0;
//  * at the start of each step, gripped nodes get velocity grip.velocity * grip_ramp(t);
//  * classic RK4 with the world's dt; time advances by dt per step.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "core/world.hpp"

namespace papertear {

class ReferenceModel {
 public:
  struct Node {
    std::array<double, 3> p, v;
    double mass;
    bool free;
    std::uint8_t grip;  // 0 free, g > 0: grip g - 1
  };
  struct Spring {
    std::uint32_t a, b;
    double rest, k, c;
  };

  explicit ReferenceModel(const World& world);

  void step(int n = 1);
  // Total spring force on every node at the current state (no gravity or drag).
  std::vector<std::array<double, 3>> spring_forces() const;
  double kinetic_energy() const;
  double elastic_energy() const;

  const std::vector<Node>& nodes() const { return nodes_; }
  const std::vector<Spring>& springs() const { return springs_; }
  double time() const { return time_; }

 private:
  using Vec3 = std::array<double, 3>;
  // A whole-system state (p, v) or its rate (dp/dt, dv/dt), one entry per node.
  struct State {
    std::vector<Vec3> p, v;
  };

  void add_spring(std::uint32_t a, std::uint32_t b, double rest, double k, double c);
  void set_grip_velocities();
  void read_state(State& out) const;
  void add_spring_forces(const State& s, std::vector<Vec3>& f) const;
  void rates_at(const State& s, State& out) const;
  static void advance(const State& y, double h, const State& rate, State& out);  // y + h rate

  std::vector<Node> nodes_;
  std::vector<Spring> springs_;
  std::vector<std::array<double, 3>> grip_velocity_;
  LoadParams load_;
  std::array<double, 3> gravity_{};
  double drag_ = 0.0;
  double dt_ = 0.0;
  double time_ = 0.0;
  // RK4 scratch, kept between steps so that a step does not allocate (the benchmarks time
  // the arithmetic, not the allocator).
  State y_, stage_;
  std::array<State, 4> k_;
};

}  // namespace papertear
