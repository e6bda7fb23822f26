#include "drape/analysis/analytic.hpp"

#include <algorithm>
#include <cmath>

#include "drape/sim/metrics.hpp"
#include "drape/sim/world.hpp"

namespace drape::analysis {

namespace {

sim::ClothSettings chain(int links, double length, double mass, sim::Vec3 origin) {
  sim::ClothSettings c;
  c.lattice = {links + 1, 1, length, 1.0, origin, sim::LatticePlane::xy};
  c.mass = mass;
  c.material(sim::ConstraintKind::stretch) = {1.0, 0.0};
  c.material(sim::ConstraintKind::shear) = {0.0, 0.0};
  c.material(sim::ConstraintKind::bend) = {0.0, 0.0};
  return c;
}

}  // namespace

double freeFallError(int substeps) {
  sim::WorldSettings settings;
  settings.solver.substeps = substeps;
  settings.cloths.push_back(chain(0, 1.0, 1.0, sim::Vec3{0.0, 100.0, 0.0}));
  sim::World world(settings);
  double worst = 0.0;
  for (int step = 0; step < 120; ++step) {
    world.step();
    const double t = world.time();
    worst = std::max(worst, std::abs(world.cloths()[0].state.position[0].y - (100.0 - 0.5 * 9.81 * t * t)));
  }
  return worst;
}

double catenaryError(int links, int iterations, double* strain, bool lines) {
  const double length = 1.2, span = 1.0, top = 1.0;
  sim::WorldSettings settings;
  settings.solver.substeps = 4;
  settings.solver.iterations = iterations;
  settings.solver.stretchSolver = lines ? sim::StretchSolver::lines : sim::StretchSolver::gaussSeidel;
  settings.air.drag = 2.0;
  sim::ClothSettings c = chain(links, length, 0.5, sim::Vec3{-length / 2, top, 0.0});
  c.pins = {{0, 0, sim::Vec3{-span / 2, top, 0.0}}, {links, 0, sim::Vec3{span / 2, top, 0.0}}};
  settings.cloths.push_back(c);
  sim::World world(settings);
  world.run(600);
  double a = 0.5;  // Newton on f(a) = 2 a sinh(s / 2a) - L
  for (int i = 0; i < 50; ++i) {
    const double u = span / (2 * a);
    a -= (2 * a * std::sinh(u) - length) / (2 * std::sinh(u) - 2 * u * std::cosh(u));
  }
  const double offset = top - a * std::cosh(span / (2 * a));
  double worst = 0.0;
  for (const sim::Vec3& x : world.cloths()[0].state.position) {
    worst = std::max(worst, std::abs(x.y - (a * std::cosh(x.x / a) + offset)));
  }
  if (strain) *strain = sim::structuralStrain(world).max;
  return worst;
}

double pendulumError(int substeps) {
  const double g = 9.81, length = 1.0;
  sim::WorldSettings settings;
  settings.solver.dt = 1.0 / 600.0;
  settings.solver.substeps = substeps;
  settings.solver.iterations = 1;
  sim::ClothSettings c = chain(1, length, 2.0, sim::Vec3{0.0, 2.0, 0.0});  // pin at (0, 2), bob at (1, 2)
  c.pins = {{0, 0, std::nullopt}};
  settings.cloths.push_back(c);
  sim::World world(settings);
  double previous = 1.0, previousTime = 0.0;
  while (world.time() < 2.0) {
    world.step();
    const double x = world.cloths()[0].state.position[1].x;
    if (x <= 0.0) {  // crossed the bottom: interpolate the time
      const double crossing = previousTime + (world.time() - previousTime) * previous / (previous - x);
      const double exact = std::sqrt(length / g) * std::comp_ellint_1(std::sin(3.14159265358979323846 / 4));
      return std::abs(crossing - exact);
    }
    previous = x;
    previousTime = world.time();
  }
  return INFINITY;
}

}  // namespace drape::analysis
