// The step as a pipeline of named stages (after Box2D v3's solver stages).
//
// The world assembles its pipeline once from its settings: a stage the scene does not use (wind
// pressure on a windless scene, constraint damping on undamped constraints, the other model's
// integrator) is simply absent and costs nothing. Every stage is timed into a Profile.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

namespace drape::sim {

enum class Stage : std::uint8_t {
  // every model, first in each substep
  fingers,  // carry the particles fingers hold along the fingers' paths
  // position model, once per substep
  windPressure,        // aerodynamic force on triangles -> per-particle acceleration
  verletIntegrate,     // x' = x + (x - x_prev) decay + a h^2
  projectConstraints,  // Gauss-Seidel sweeps over stretch, shear, bend constraints
  dampConstraints,     // remove a fraction of relative velocity along each damped constraint
  clampTravel,         // self-collision: cap the velocity carried into the next substep
  collide,             // find contact planes along each particle's motion; project onto them
  friction,            // Coulomb friction against colliders, after the sweeps
  selfCollide,         // push apart particles of a cloth that come too close
  selfContact,         // keep triangles apart and never through each other (self_contact.hpp)
  // force model, once per substep: forces are evaluated inside the integrator
  explicitEuler,
  symplecticEuler,
  verletForces,
  midpoint,
  rk4,
  collideForces,  // contacts with velocity response
  // every model, once per step
  guard,  // stop at the first non-finite or runaway position
  tear,   // split the mesh where a stretch constraint is past the tearing threshold
};

std::string_view name(Stage stage);

struct StageTiming {
  Stage stage;
  bool perSubstep;            // runs once per substep (else once per step)
  double lastSeconds = 0.0;   // wall time spent in the last step
  double totalSeconds = 0.0;  // wall time since the world was made
};

using Profile = std::vector<StageTiming>;

}  // namespace drape::sim
