#include "drape/analysis/stability.hpp"

#include <algorithm>
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

namespace {

// The chain (21 particles, 1 m, pinned at one end, released horizontally) or the sheet (16 x 16,
// 1 m, held by two corners, flat), 1 kg, every constraint kind at `material`.
sim::WorldSettings system(PositionSystem which, sim::KindMaterial material) {
  sim::WorldSettings settings;
  sim::ClothSettings cloth;
  cloth.mass = 1.0;
  if (which == PositionSystem::chain) {
    cloth.lattice = {21, 1, 1.0, 1.0, sim::Vec3{0.0, 2.0, 0.0}, sim::LatticePlane::xy};
    cloth.pins = {{0, 0, std::nullopt}};
  } else {
    cloth.lattice = {16, 16, 1.0, 1.0, sim::Vec3{-0.5, 2.0, -0.5}, sim::LatticePlane::xz};
    cloth.pins = {{0, 0, std::nullopt}, {15, 0, std::nullopt}};
  }
  for (sim::ConstraintKind kind : sim::kConstraintKinds) cloth.material(kind) = material;
  if (which == PositionSystem::chain) cloth.material(sim::ConstraintKind::bend) = {0.0, 0.0};
  settings.cloths.push_back(cloth);
  return settings;
}

// The energy scale is the potential energy released by a 1 m drop, m g (1 m): diverged if the guard
// trips or the mechanical energy ever rises more than 10 scales above its start; damped if the
// kinetic energy at the end is below 1e-3 scales; stable otherwise.
OscillatorRun classify(const sim::WorldSettings& settings, std::int64_t steps) {
  sim::World world(settings);
  const double scale = 1.0 * 9.81 * 1.0;
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

}  // namespace

OscillatorRun runPositionModel(PositionSystem which, double stiffness, double dt, std::int64_t steps) {
  sim::WorldSettings settings = system(which, {stiffness, 0.0});
  settings.solver.dt = dt;
  settings.solver.iterations = 10;
  return classify(settings, steps);
}

OscillatorRun runForceModel(PositionSystem which, sim::Integrator integrator, double stiffness, double dt,
                            std::int64_t steps) {
  sim::WorldSettings settings = system(which, {stiffness, 0.0});
  settings.solver.model = sim::Model::force;
  settings.solver.integrator = integrator;
  settings.solver.dt = dt;
  return classify(settings, steps);
}

double highestOmegaBound(PositionSystem which, double stiffness) {
  // Springs at the busiest particle: the chain's 2 neighbours; the sheet's 4 structural, 4 shear
  // and 4 bend neighbours.
  const double particles = which == PositionSystem::chain ? 21.0 : 256.0;
  const double springs = which == PositionSystem::chain ? 2.0 : 12.0;
  return std::sqrt(2.0 * springs * stiffness / (1.0 / particles));
}

std::optional<double> largestStableDt(PositionSystem which, sim::Integrator integrator, double stiffness, double dtMin,
                                      double dtMax, double ratio, std::int64_t steps) {
  std::optional<double> largest;
  for (double dt = dtMin; dt <= dtMax * (1.0 + 1e-12); dt *= ratio) {
    if (runForceModel(which, integrator, stiffness, dt, steps).verdict == Stability::diverged) break;
    largest = dt;
  }
  return largest;
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
