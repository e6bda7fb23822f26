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

// Every stretch constraint longer than `threshold` times its rest length tears: the fan of one of
// its ends is severed across the pull (along the line through that end perpendicular to the
// constraint, at rest), and the particle splits. A constraint no triangle witnesses breaks.
// At most `particleBudget` particles are made. Returns whether the mesh changed.
bool tear(Cloth& cloth, Real threshold, std::size_t particleBudget, std::vector<ParticleSplit>& splits);

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
