#include "drape/bench/naive.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/geometric.hpp>

#include "drape/sim/cloth.hpp"

namespace drape::bench {

NaiveCloth::NaiveCloth(const sim::WorldSettings& world, int iterations)
    : gravity_(world.gravity), dt_(world.solver.dt), iterations_(iterations) {
  const sim::ClothSettings& cloth = world.cloths.at(0);
  const sim::ClothRest rest = sim::buildLattice(cloth.lattice);
  const sim::Real particleMass = cloth.mass / static_cast<sim::Real>(rest.particleCount());
  for (std::size_t i = 0; i < rest.particleCount(); ++i) {
    const sim::Vec3 x = rest.restPosition(i);
    particles_.push_back({x, x, 1.0 / particleMass});
  }
  // The constraints in lattice order, as meshConstraints lists them (the engine keeps its lists in
  // an order of its own, sim::orderConstraints).
  std::vector<glm::ivec2> nodes;
  for (int row = 0; row < rest.rows; ++row) {
    for (int column = 0; column < rest.columns; ++column) nodes.push_back({column, row});
  }
  const auto lattice = sim::meshConstraints(rest, rest.triangles, nodes);
  for (sim::ConstraintKind kind : sim::kConstraintKinds) {
    const sim::Real stiffness = cloth.material(kind).stiffness;
    if (stiffness == 0.0) continue;
    for (const sim::DistanceConstraint& c : lattice[static_cast<std::size_t>(kind)]) {
      constraints_.push_back({static_cast<int>(c.a), static_cast<int>(c.b), c.restLength, stiffness});
    }
    if (kind == sim::ConstraintKind::stretch) structural_ = constraints_.size();
  }
  for (const sim::Pin& pin : cloth.pins) {
    const int i = static_cast<int>(rest.index(pin.column, pin.row));
    particles_[static_cast<std::size_t>(i)].inverseMass = 0.0;
    pinIndex_.push_back(i);
    pinned_.push_back(particles_[static_cast<std::size_t>(i)].position);
  }
}

void NaiveCloth::step() {
  const sim::Vec3 gravityStep = gravity_ * (dt_ * dt_);
  for (Particle& p : particles_) {
    if (p.inverseMass == 0.0) continue;
    const sim::Vec3 x = p.position;
    p.position = x + (x - p.previous) + gravityStep;
    p.previous = x;
  }
  for (int iteration = 0; iteration < iterations_; ++iteration) {
    for (const Constraint& c : constraints_) {
      Particle& a = particles_[static_cast<std::size_t>(c.a)];
      Particle& b = particles_[static_cast<std::size_t>(c.b)];
      const sim::Real wSum = a.inverseMass + b.inverseMass;
      if (wSum == 0.0) continue;
      const sim::Vec3 d = b.position - a.position;
      const sim::Real length = glm::length(d);
      if (length == 0.0) continue;
      const sim::Vec3 correction = d * (c.stiffness * (length - c.rest) / (length * wSum));
      a.position += a.inverseMass * correction;
      b.position -= b.inverseMass * correction;
    }
    for (std::size_t k = 0; k < pinIndex_.size(); ++k) {
      particles_[static_cast<std::size_t>(pinIndex_[k])].position = pinned_[k];
    }
  }
}

double NaiveCloth::strain(std::size_t k) const {
  const Constraint& c = constraints_[k];
  const double length = glm::length(particles_[static_cast<std::size_t>(c.b)].position -
                                    particles_[static_cast<std::size_t>(c.a)].position);
  return length / c.rest - 1.0;
}

double NaiveCloth::strainMax() const {
  double worst = 0.0;
  for (std::size_t k = 0; k < structural_; ++k) worst = std::max(worst, strain(k));
  return worst;
}

double NaiveCloth::strainMean() const {
  double sum = 0.0;
  for (std::size_t k = 0; k < structural_; ++k) sum += std::abs(strain(k));
  return structural_ > 0 ? sum / static_cast<double>(structural_) : 0.0;
}

bool NaiveCloth::finite() const {
  return std::all_of(particles_.begin(), particles_.end(), [](const Particle& p) {
    return std::isfinite(p.position.x) && std::isfinite(p.position.y) && std::isfinite(p.position.z);
  });
}

std::size_t NaiveCloth::memoryBytes() const {
  return particles_.capacity() * sizeof(Particle) + constraints_.capacity() * sizeof(Constraint) +
         pinned_.capacity() * sizeof(sim::Vec3) + pinIndex_.capacity() * sizeof(int);
}

}  // namespace drape::bench
