// The pierce load (load.kind = "pierce"): a rigid indenter pushed along -z through the
// sheet, in contact with the nodes through a penalty force (MODEL.md §7, future work).
//
// Shape: a round-nosed body, the Minkowski sum of a sharp cone (apex `tip`, axis +z,
// half-angle α) and a ball of radius R. With α = 0 ("sphere") it is a ball on a rod of the
// same radius, like the plunger of a ball-burst test, so the hole stays held open once the
// ball is through; with α > 0 ("cone") it is a cone with a rounded tip that widens the hole
// as it goes. The signed distance of a point is its distance to the sharp cone minus R, so
// one formula serves both.
//
// Contact: a node of mass m inside the body feels f = m · max(0, k δ − c v_n) n along the
// outward normal n, with δ the depth, v_n the normal speed relative to the indenter,
// k = contact_stiffness · (stiffest edge spring) per cell mass and c = damping · k like every spring. The
// penalty is per unit mass because a node stands for its share of material: a node of a
// split, lighter, is pushed less, so the contact's frequency √k is the same on every node
// whatever the tearing does, and core/timestep.hpp's bound on ω² simply grows by k (the
// rigid indenter adds to a node's own diagonal block only). The force never pulls: the
// indenter pushes, it does not stick.
//
// Motion: the tip starts just touching the top surface (z = layers · hz) and moves down at
// load.speed, ramped up linearly over load.ramp_time like the grips; each RK4 stage sees the
// indenter where it is at that stage's time.
//
// Race freedom: the force kernel reads one node's stage state and writes that node's force
// only, so any partition into chunks gives the same bits.
#pragma once
#include <cstddef>
#include <optional>

#include "core/world.hpp"

namespace papertear {

struct Indenter {
  double x = 0.0, y = 0.0;  // axis position
  double tip_z0 = 0.0;      // the tip ball's centre at t = 0
  float radius = 1.0f;
  float sin_a = 0.0f, cos_a = 1.0f;  // the cone's half-angle (0: a ball on a rod)
  float stiffness = 0.0f, damping = 0.0f;  // per unit mass of the node
  double speed = 0.0, ramp_time = 0.0;
};

// Where the indenter is at time t: its tip ball's centre and its velocity along z.
struct IndenterPose {
  float cx = 0.0f, cy = 0.0f, cz = 0.0f;
  float vz = 0.0f;
};

// The scene's indenter, or nothing unless load.kind is "pierce".
std::optional<Indenter> make_indenter(const World& world);
IndenterPose indenter_pose(const Indenter& indenter, double t);
// How far the indenter has moved down by time t (the integral of its ramped speed).
double indenter_travel(const Indenter& indenter, double t);

struct ContactInputs {
  const float *sx, *sy, *sz, *svx, *svy, *svz;  // the stage state
  const float* mass;
};

// Adds the contact force to nodes [begin, end) of fx, fy, fz.
void add_contact_forces(std::size_t begin, std::size_t end, const Indenter& indenter,
                        const IndenterPose& pose, const ContactInputs& in, float* fx, float* fy,
                        float* fz);

// The contact force on the stage state at stage time t, added to world.scratch.f*
// (parallel over fixed node chunks).
void apply_contact(World& world, const Indenter& indenter, double t);

// The force the sheet exerts on the indenter along its motion (+: the sheet resists), from
// the nodes' state (p, v) at world.time; a serial sum in node order.
double indenter_force(const World& world);

}  // namespace papertear
