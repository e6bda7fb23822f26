// Measurements of a world: strain of the structural constraints and mechanical energy.
// Computed on demand, never inside the step.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "drape/sim/world.hpp"

namespace drape::sim {

// Strain of a constraint: e = |x_b - x_a| / restLength - 1 (0 at rest, 0.05 = 5 % stretched).
struct StrainStats {
  double max = 0.0;   // largest e over all structural constraints (most stretched)
  double mean = 0.0;  // mean of |e|
  std::size_t count = 0;
};

struct Energy {
  double kinetic = 0.0;        // J, sum of m v^2 / 2
  double gravitational = 0.0;  // J, sum of -m g . x (zero at the origin)
  double elastic = 0.0;        // J, force model: sum of ks (|dx| - r)^2 / 2; 0 for the position model
  double total() const { return kinetic + gravitational + elastic; }
};

// Momentum of the particles a force or constraint moves (not pinned, not held), every cloth together.
struct Momentum {
  Vec3 linear{0.0};   // kg m/s, sum of m v
  Vec3 angular{0.0};  // kg m^2/s, sum of m (x - centre) x v
  Vec3 centre{0.0};   // m, their centre of mass, which `angular` is taken about
};

StrainStats structuralStrain(const World& world);
Momentum momentum(const World& world);
// Mass-weighted mean of the cloth's positions, every particle counted (pinned too).
Vec3 centreOfMass(const Cloth& cloth);
Energy energy(const World& world);
// FNV-1a over the step count and every cloth's particle count, positions and previous positions,
// bit for bit: two worlds that will go on the same way hash the same (the determinism test keeps
// one per shipped scene and gesture; the bench compares thread counts by it).
std::uint64_t stateHash(const World& world);

// Per-vertex normals (area-weighted sum of adjacent triangle normals, normalised); particles on no
// triangle get the lattice plane's normal.
std::vector<Vec3> vertexNormals(const Cloth& cloth);
void vertexNormals(const Cloth& cloth, std::vector<Vec3>& normals);  // into an array reused frame to frame

}  // namespace drape::sim
