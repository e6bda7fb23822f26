// The step as a pipeline of named stages (after Box2D v3's solver stages).
//
// The world assembles its pipeline once from its settings: a stage the scene does not use (wind
// pressure on a windless scene, constraint damping on undamped constraints, the other model's
// integrator) is simply absent and costs nothing. Every stage is timed into a Profile, and so is
// every part of a stage that does several jobs (projecting constraints: the plan, the tethers, each
// kind's constraints, the loose links, the contact planes, the layers' contacts; self-contact: the broad and the narrow
// phase, the sweeps, friction, the fail-safe), as the stage's parts.
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
  friction,            // Coulomb friction against colliders where no sweeps apply it (they do after each)
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
  // parts of projectConstraints
  plan,           // the solver's plan of a cloth, where its mesh or settings changed (batches, lines)
  tethers,        // each particle into reach of the pins (long-range attachments)
  bendStencils,   // a fabric's bending (its stencils, solved as one block)
  bend,           // the bend constraints (in batches with the lines stretch solver)
  shear,          // the shear constraints (likewise)
  stretch,        // the stretch constraints (whole lines at a time with the lines stretch solver)
  looseLinks,     // with the lines stretch solver: the stretch links on no line, one at a time
  contactPlanes,  // each particle back onto its collider contacts' planes, after each sweep
  layerContacts,  // the self-contacts the substep before pushed, held again after each sweep
  // parts of selfContact (friction, above, is its part too)
  broadPhase,    // the vertex-triangle and edge-edge pairs that may come within reach (a tree of boxes)
  narrowPhase,   // each pair's closest points, and whether it is near enough to push
  contactSweep,  // the pairs' constraints, swept
  sweepAfter,    // one more sweep of each cloth that pushed against itself, those held; the contacts pushed again
  failSafe,      // no step makes two triangles pass through each other
};

std::string_view name(Stage stage);

struct StageTiming {
  Stage stage;
  bool perSubstep;            // runs once per substep (else once per step)
  double lastSeconds = 0.0;   // wall time spent in the last step
  double totalSeconds = 0.0;  // wall time since the world was made
  // The stage's parts, in the order they first ran, each with its own time (a part that runs
  // inside another, as the tethers between the lines' steps, is taken out of the other's): they add
  // up to at most the stage's time; what is left is the stage's own glue.
  std::vector<StageTiming> parts;
};

using Profile = std::vector<StageTiming>;

}  // namespace drape::sim
