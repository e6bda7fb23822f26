// Tearing and cutting: severing triangle edges and splitting the particles whose fans fell apart.
// See drape/sim/topology.hpp for the model.
#pragma once

#include <cstdint>
#include <vector>

#include "drape/sim/topology.hpp"
#include "drape/sim/world.hpp"

namespace drape::sim::topology {

// Builds the neighbours, rest areas and constraint templates from the cloth's mesh, once.
void build(Cloth& cloth);

// The spacing the cloth was made with (its settings' mesh's, or its lattice's finer one; else the
// median stretch rest length; 0 if it has no stretch links), which Cloth::spacing keeps.
Real madeSpacing(const Cloth& cloth);

// Tearing through the triangles. Where a particle's triangles are stretched (C = F^T F of their
// deformation, averaged by area) with a principal stretch beyond `threshold`, its fan breaks along
// the line through it across that principal direction (at rest), as a cut does: new particles where
// the line crosses the fan's edges, the fan's triangles split, the mesh opened; from inside the
// cloth both ways, from a border (a crack's tip) the way into the cloth. One break per
// neighbourhood a pass; up to kTearPasses passes a step, the links near each fresh crack relaxed
// between them, so a crack runs as far in a step as the tension drives it. A link no triangle
// witnesses (a chain) breaks alone in its piece, the most strained one. At most `particleBudget`
// particles are made. Returns whether the mesh changed.
bool tear(Cloth& cloth, Real threshold, std::size_t particleBudget, std::vector<ParticleSplit>& splits,
          std::vector<ParticleInsert>& inserted);

// Cuts along the surface swept by the segment a-b moved along `depth` (both ways, without end), through
// the triangles: a particle within a fifth of the spacing of that surface is moved onto it (along an
// edge), every edge it crosses gets a new particle there (`inserted`), each crossed triangle is split
// in two or three along the cut, and the mesh is opened along it. A segment that ends inside a
// triangle leaves a tip there that the next segment of the same swipe (starting where this one
// ended) carries on from. Mass is conserved exactly. Returns whether the mesh changed.
bool cut(Cloth& cloth, Vec3 a, Vec3 b, Vec3 depth, std::size_t particleBudget, std::vector<ParticleSplit>& splits,
         std::vector<ParticleInsert>& inserted);

// Connected pieces: per particle, the number of its piece (0, 1, ... in order of the lowest
// particle), joined through triangles and constraints; empty if there is one piece (Cloth::piece).
// `count` receives the number of pieces.
std::vector<std::uint32_t> pieces(const ClothRest& rest, std::uint32_t& count);

}  // namespace drape::sim::topology
