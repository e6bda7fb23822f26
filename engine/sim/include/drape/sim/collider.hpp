// Colliders: the solid things cloth rests on and drapes over.
//
// Every shape is described by a signed distance (negative inside) and its gradient, in the
// collider's own frame; a kinematic collider moves with a constant velocity and spins with a
// constant angular velocity about its position. A static triangle mesh is a thin shell with an
// unsigned distance, looked up through a uniform grid. Response follows the seed: a particle
// that comes within its thickness of a surface is projected out along the surface normal, and its
// tangential motion is reduced by Coulomb friction (Macklin et al. 2014, "Unified Particle
// Physics", position form).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "drape/sim/types.hpp"

namespace drape::sim {

enum class ColliderShape : std::uint8_t { plane, sphere, capsule, box, mesh };

struct TriangleMesh {
  std::vector<Vec3> vertices;  // m, in the collider's frame
  std::vector<glm::uvec3> triangles;
};

struct Friction {
  Real staticCoefficient = 0.5;   // mu_s: no sliding while tangential motion < mu_s * penetration
  Real kineticCoefficient = 0.4;  // mu_k: sliding motion is reduced by mu_k * penetration
};

struct ColliderSettings {
  ColliderShape shape = ColliderShape::plane;
  Vec3 position{0.0};                          // m: plane point, sphere/box/capsule centre, mesh origin
  glm::dquat orientation{1.0, 0.0, 0.0, 0.0};  // of the collider's frame in the world
  Vec3 normal{0.0, 1.0, 0.0};                  // plane, in its frame (the solid is on the other side)
  Real radius = 0.5;                           // m, sphere and capsule
  Vec3 halfAxis{0.5, 0.0, 0.0};                // m, capsule: its segment runs from -halfAxis to +halfAxis
  Vec3 halfExtents{0.5};                       // m, box
  // m, box: the radius its edges and corners are rounded to (0: sharp), at most its smallest half
  // extent. A cloth refined far past the radius wraps a rounded edge; over a sharp one the link
  // between the particle on top and the one on the side cuts through the corner, and its pull
  // presses the particle on top into the face, which friction then holds however hard the link
  // pulls (docs/design.md).
  Real rounding = 0.0;
  std::shared_ptr<const TriangleMesh> mesh;
  Friction friction;
  Vec3 velocity{0.0};         // m/s, kinematic motion of the position
  Vec3 angularVelocity{0.0};  // rad/s, kinematic spin about the position
};

// Where a point stands relative to a collider's surface.
struct SurfaceDistance {
  Real distance;  // m, signed: < 0 inside a solid (a mesh has no inside: always >= 0)
  Vec3 normal;    // unit, pointing away from the solid at the nearest surface point
};

// A collider at run time: its settings, its pose at the current time, and (mesh) a grid.
class Collider {
 public:
  explicit Collider(ColliderSettings settings);

  const ColliderSettings& settings() const { return settings_; }
  // Moves the collider to where its motion puts it at time t; the pose it had is kept as the
  // previous one (the start of the substep).
  void setTime(Real t);
  // Where a point that was at p, carried along with the collider from its previous pose to its
  // current one, is now: contacts sweep x_prev carried this way to x, so a moving collider cannot
  // jump past a particle between two substeps.
  Vec3 carried(Vec3 p) const;
  bool moving() const;
  Vec3 centre() const { return centre_; }                  // m, where the position is now
  glm::dquat orientation() const { return orientation_; }  // of its frame now

  // Signed distance and normal at p; anything farther than `reach` may be reported as `reach`.
  SurfaceDistance distance(Vec3 p, Real reach) const;
  // Velocity of the collider's material at world point p (for friction against moving surfaces).
  Vec3 surfaceVelocity(Vec3 p) const;
  // Bytes it keeps beside its settings: a mesh's grid, bounded by the mesh's triangle count.
  std::size_t gridBytes() const { return (cellStart_.capacity() + cellTriangles_.capacity()) * sizeof(std::uint32_t); }

 private:
  SurfaceDistance local(Vec3 p, Real reach) const;
  void buildGrid();

  ColliderSettings settings_;
  Vec3 centre_;
  glm::dquat orientation_;
  Vec3 previousCentre_;
  glm::dquat previousOrientation_;
  // Mesh grid: triangles per cell, cells of `cellSize_` from `gridOrigin_`.
  Vec3 gridOrigin_{0.0};
  Real cellSize_ = 1.0;
  glm::ivec3 gridCells_{0};
  std::vector<std::uint32_t> cellStart_;
  std::vector<std::uint32_t> cellTriangles_;
};

// Closest point on triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5).
Vec3 closestPointOnTriangle(Vec3 p, Vec3 a, Vec3 b, Vec3 c);

}  // namespace drape::sim
