#include "drape/analysis/convergence.hpp"

#include <cmath>

#include "drape/sim/world.hpp"

namespace drape::analysis {

Convergence oscillatorConvergence(sim::Integrator integrator, double dtLargest, int halvings) {
  constexpr double kOmega = 10.0, kT = 1.0, kG = 9.81, kTop = 2.0, kRest = 1.0;
  Convergence result;
  for (int k = 0; k < halvings; ++k) {
    const double dt = dtLargest / std::pow(2.0, k);
    sim::WorldSettings settings;
    settings.solver.model = sim::Model::force;
    settings.solver.integrator = integrator;
    settings.solver.dt = dt;
    sim::ClothSettings spring;
    spring.lattice = {1, 2, 1.0, kRest, sim::Vec3{0.0, kTop, 0.0}, sim::LatticePlane::xy};
    spring.mass = 2.0;
    spring.material(sim::ConstraintKind::stretch) = {kOmega * kOmega, 0.0};
    spring.material(sim::ConstraintKind::shear) = {0.0, 0.0};
    spring.material(sim::ConstraintKind::bend) = {0.0, 0.0};
    spring.pins = {{0, 0, std::nullopt}};
    settings.cloths.push_back(spring);
    sim::World world(settings);
    world.run(static_cast<std::int64_t>(std::llround(kT / dt)));
    const double exact = kTop - kRest - kG / (kOmega * kOmega) * (1.0 - std::cos(kOmega * world.time()));
    result.points.push_back({dt, std::abs(world.cloths()[0].state.position[1].y - exact)});
  }
  // Least-squares slope in log-log.
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (const ConvergencePoint& p : result.points) {
    const double x = std::log(p.dt), y = std::log(std::max(p.error, 1e-300));
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
  }
  const double n = static_cast<double>(result.points.size());
  result.order = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  return result;
}

}  // namespace drape::analysis
