// Contacts between particles and colliders, and self-collision between particles of a cloth.
//
// Each substep, `detect` finds for every free particle the collider surface its motion from
// x_prev to x comes within `thickness` of: by sphere tracing the signed distance along that
// segment, so a fast particle meets a thin collider instead of tunnelling through it. The contact
// is kept as a plane (n . x >= offset) that constraint projection re-enforces after every sweep,
// so constraints and contacts agree. `friction` then applies Coulomb friction in position form.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/geometric.hpp>

#include "drape/sim/collider.hpp"
#include "drape/sim/settings.hpp"
#include "drape/sim/state.hpp"
#include "drape/sim/world.hpp"
#include "parallel/workers.hpp"
#include "solver/solver_scratch.hpp"

namespace drape::sim::contact {

// (With `workers`, detect, project and friction share the particles among them: each particle's
// contact is its own, so the result is the same whatever their number.)
void detect(Cloth& cloth, const std::vector<Collider>& colliders, SolverScratch& scratch, Workers* workers = nullptr);
void project(Cloth& cloth, SolverScratch& scratch, Workers* workers = nullptr);
// Static while the tangential motion relative to the surface is below mu_s times the penetration
// resolved this substep (by the first projection and by every re-projection after a sweep), else reduced by mu_k times
// it: on a slope a particle sticks when tan(theta) < mu_s and slides with a = g (sin(theta) - mu_k cos(theta))
// otherwise. Called after every sweep's projection, not once at the substep's end: the friction's whole correction
// this substep is kept (contactRub) and replaced, not added to, so that it answers to the motion the particle would
// have made without friction and stays within mu times the penetration resolved so far, however many calls. The
// sweeps after it then see a stuck particle where it sticks, and do not pull on it a correction the friction takes
// back at the end (which left the links over a table's edge 30-50 % long at 64 x 64).
void friction(Cloth& cloth, const std::vector<Collider>& colliders, Real h, SolverScratch& scratch,
              Workers* workers = nullptr);
// Force model: project onto the contact planes, remove the normal velocity into the surface, and
// reduce the tangential velocity by Coulomb friction with the impulse that took.
void respondWithVelocities(Cloth& cloth, const std::vector<Collider>& colliders, Real h, SolverScratch& scratch);

// Self-collision: no particle within `distance` of another (or of their rest distance, if that is
// smaller), found with a spatial hash; their relative tangential motion damped by `friction`.
// clampTravel runs at the end of a substep and caps the velocity carried into the next one (by
// moving x_prev, not x, so it never undoes what the constraints just did): no particle then
// travels more than maxTravel in a substep on its own momentum, too little to pass through a layer.
void clampTravel(Cloth& cloth, Real maxTravel);
// Works across all cloths of the world, so two cloths collide with each other too.
void selfCollide(std::vector<ClothRecord>& cloths, const SelfCollisionSettings& settings, SelfCollisionScratch& scratch,
                 Workers& workers);

// A self-contact whose free corners would each move more than 1 / kContactLeverage times as far
// as its points part pushes nothing: a free corner of weight 0.004 in a triangle whose other corners
// and the vertex fingers hold would be flung 250 times the gap. The fail-safe keeps such a pair
// apart instead.
inline constexpr Real kContactLeverage = 0.25;

// How hard a self-contact's two points (weights c over corners v, with inverse masses w) are to
// part: sum_k c_k^2 w_k, the masses sharing the move; 0 where kContactLeverage says it pushes
// nothing. Parting them by g moves corner k by c_k w_k g / that along the normal.
template <class Contact>
Real partingWeight(const std::vector<Real>& w, const Contact& p) {
  Real denominator = 0.0, most = 0.0;
  for (int k = 0; k < 4; ++k) {
    denominator += p.c[k] * p.c[k] * w[p.v[k]];
    most = std::max(most, std::abs(p.c[k]) * w[p.v[k]]);
  }
  return denominator > kContactLeverage * most ? denominator : 0.0;
}

// Whether a self-contact's two points (its weights c over corners v, self_contact.hpp's Contact or a
// SolverScratch::LayerContact) still face each other across its normal at `x`: their offset along
// the surface within the size of the primitives (else one slid off the other's side, or a finger
// flung it far, and the half-space it was measured in says nothing about them).
template <class Contact>
bool facing(const std::vector<Vec3>& x, const Contact& p) {
  Vec3 offset{0.0};
  for (int k = 0; k < 4; ++k) offset += x[p.v[k]] * p.c[k];
  const Vec3 along = offset - p.normal * glm::dot(p.normal, offset);
  Real size = 0.0;
  for (int i = 0; i < 4; ++i) {
    for (int j = i + 1; j < 4; ++j) {
      const Vec3 d = x[p.v[i]] - x[p.v[j]];
      const bool within = p.edges ? (j < 2 || i >= 2) : i >= 1;  // two corners of one primitive
      if (within) size = std::max(size, glm::dot(d, d));
    }
  }
  return glm::dot(along, along) <= size + p.target * p.target;
}

}  // namespace drape::sim::contact
