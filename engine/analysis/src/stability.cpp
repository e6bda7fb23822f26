#include "drape/analysis/stability.hpp"

#include <cmath>

#include "drape/sim/metrics.hpp"
#include "drape/sim/world.hpp"

namespace drape::analysis {

std::string_view name(Stability stability) {
  switch (stability) {
    case Stability::stable: return "stable";
    case Stability::damped: return "damped";
    case Stability::diverged: return "diverged";
  }
  return "?";
}

OscillatorRun runOscillator(sim::Integrator integrator, double stiffness, double dt, std::int64_t steps) {
  sim::WorldSettings settings;
  settings.solver.model = sim::Model::force;
  settings.solver.integrator = integrator;
  settings.solver.dt = dt;
  settings.gravity = sim::Vec3{0.0};
  sim::ClothSettings spring;
  spring.lattice = {1, 2, 1.0, 1.0, sim::Vec3{0.0, 2.0, 0.0}, sim::LatticePlane::xy};
  spring.mass = 2.0;  // 1 kg each; the pinned one does not move
  spring.material(sim::ConstraintKind::stretch) = {stiffness, 0.0};
  spring.material(sim::ConstraintKind::shear) = {0.0, 0.0};
  spring.material(sim::ConstraintKind::bend) = {0.0, 0.0};
  spring.pins = {{0, 0, sim::Vec3{0.0, 2.1, 0.0}}};  // 0.1 m stretched
  settings.cloths.push_back(spring);
  sim::World world(settings);

  const double start = sim::energy(world).total();
  OscillatorRun run;
  for (std::int64_t i = 0; i < steps; ++i) {
    if (world.step() == sim::StepStatus::diverged) {
      run.verdict = Stability::diverged;
      run.maxEnergyRatio = run.endEnergyRatio = INFINITY;
      return run;
    }
    const double ratio = sim::energy(world).total() / start;
    run.maxEnergyRatio = std::max(run.maxEnergyRatio, ratio);
    run.endEnergyRatio = ratio;
    if (!(ratio <= kDivergedEnergyFactor)) {
      run.verdict = Stability::diverged;
      return run;
    }
  }
  run.verdict = run.endEnergyRatio < kDampedEnergyFactor ? Stability::damped : Stability::stable;
  return run;
}

std::string_view name(PositionSystem system) { return system == PositionSystem::chain ? "chain" : "sheet"; }

OscillatorRun runPositionModel(PositionSystem system, double stiffness, double dt, std::int64_t steps) {
  sim::WorldSettings settings;
  settings.solver.dt = dt;
  settings.solver.iterations = 10;
  sim::ClothSettings cloth;
  cloth.mass = 1.0;
  if (system == PositionSystem::chain) {
    cloth.lattice = {21, 1, 1.0, 1.0, sim::Vec3{0.0, 2.0, 0.0}, sim::LatticePlane::xy};
    cloth.pins = {{0, 0, std::nullopt}};
  } else {
    cloth.lattice = {16, 16, 1.0, 1.0, sim::Vec3{-0.5, 2.0, -0.5}, sim::LatticePlane::xz};
    cloth.pins = {{0, 0, std::nullopt}, {15, 0, std::nullopt}};
  }
  for (sim::ConstraintKind kind : sim::kConstraintKinds) cloth.material(kind) = {stiffness, 0.0};
  if (system == PositionSystem::chain) cloth.material(sim::ConstraintKind::bend) = {0.0, 0.0};
  settings.cloths.push_back(cloth);
  sim::World world(settings);
  const double scale = cloth.mass * 9.81 * 1.0;
  const double start = sim::energy(world).total();
  OscillatorRun run;
  run.maxEnergyRatio = run.endEnergyRatio = 0.0;  // here: (E - E0) / scale, and kinetic / scale at the end
  for (std::int64_t i = 0; i < steps; ++i) {
    if (world.step() == sim::StepStatus::diverged) {
      run.verdict = Stability::diverged;
      run.maxEnergyRatio = INFINITY;
      return run;
    }
    const sim::Energy e = sim::energy(world);
    run.maxEnergyRatio = std::max(run.maxEnergyRatio, (e.total() - start) / scale);
    run.endEnergyRatio = e.kinetic / scale;
    if (!(run.maxEnergyRatio <= kDivergedEnergyFactor)) {
      run.verdict = Stability::diverged;
      return run;
    }
  }
  run.verdict = run.endEnergyRatio < 1e-3 ? Stability::damped : Stability::stable;
  return run;
}

std::optional<double> theoreticalStableOmegaDt(sim::Integrator integrator) {
  switch (integrator) {
    case sim::Integrator::symplecticEuler:
    case sim::Integrator::verlet: return 2.0;
    case sim::Integrator::rk4: return 2.0 * std::sqrt(2.0);
    case sim::Integrator::explicitEuler:
    case sim::Integrator::midpoint: return std::nullopt;
  }
  return std::nullopt;
}

std::optional<double> largestStableDt(sim::Integrator integrator, double stiffness, double dtMin, double dtMax,
                                      double ratio, std::int64_t steps) {
  std::optional<double> largest;
  for (double dt = dtMin; dt <= dtMax * (1.0 + 1e-12); dt *= ratio) {
    if (runOscillator(integrator, stiffness, dt, steps).verdict == Stability::diverged) break;
    largest = dt;
  }
  return largest;
}

}  // namespace drape::analysis
