// The naive baseline: the textbook position-based cloth loop (Jakobsen 2001, the seed's model),
// written as a textbook writes it: an array of particle structs, an array of constraint structs,
// Verlet, then a fixed number of Gauss-Seidel sweeps over every constraint in the order the
// lattice made them, and pins put back after every sweep. No substeps, no tethers, one thread.
// It exists to be measured against.
#pragma once

#include <vector>

#include "drape/sim/settings.hpp"

namespace drape::bench {

class NaiveCloth {
 public:
  // The first cloth of `world` (a lattice), its pins, gravity and dt; `iterations` sweeps a step.
  NaiveCloth(const sim::WorldSettings& world, int iterations);

  void step();
  // Structural strain as sim::structuralStrain defines it: max of |x_b - x_a| / r - 1, mean of |.|.
  double strainMax() const;
  double strainMean() const;
  bool finite() const;
  std::size_t particleCount() const { return particles_.size(); }
  std::size_t constraintCount() const { return constraints_.size(); }
  std::size_t structuralCount() const { return structural_; }
  std::size_t memoryBytes() const;
  int iterations() const { return iterations_; }

 private:
  struct Particle {
    sim::Vec3 position;
    sim::Vec3 previous;
    sim::Real inverseMass;
  };
  struct Constraint {
    int a, b;
    sim::Real rest;
    sim::Real stiffness;
  };
  std::vector<Particle> particles_;
  std::vector<Constraint> constraints_;  // stretch first (structural_ of them), then shear, bend
  std::vector<sim::Vec3> pinned_;        // where each pinned particle stays
  std::vector<int> pinIndex_;
  std::size_t structural_ = 0;
  double strain(std::size_t k) const;  // of constraint k: |x_b - x_a| / rest - 1
  sim::Vec3 gravity_;
  sim::Real dt_;
  int iterations_;
};

}  // namespace drape::bench
