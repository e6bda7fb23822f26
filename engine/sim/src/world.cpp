#include "drape/sim/world.hpp"

#include <atomic>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "contacts.hpp"
#include "force_model.hpp"
#include "position_model.hpp"

namespace drape::sim {

namespace {

bool finite(Real value) { return std::isfinite(value); }
bool finite(Vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

void require(bool condition, const std::string& what) {
  if (!condition) throw std::invalid_argument(what);
}

void validate(const WorldSettings& s) {
  const SolverSettings& solver = s.solver;
  require(std::isfinite(solver.dt) && solver.dt > 0.0, "solver.dt must be a positive number of seconds");
  require(solver.substeps >= 1 && solver.substeps <= kMaxSubsteps, "solver.substeps is out of range");
  require(solver.dt / solver.substeps >= 1e-9, "the substep dt / substeps must be at least 1e-9 s");
  require(solver.iterations >= 0 && solver.iterations <= kMaxIterations, "solver.iterations is out of range");
  require(finite(solver.damping) && solver.damping >= 0.0, "solver.damping must be finite and >= 0");
  require(finite(s.gravity), "gravity must be finite");
  require(finite(s.air.velocity), "wind velocity must be finite");
  require(finite(s.air.drag) && s.air.drag >= 0.0, "wind drag must be finite and >= 0");
  require(finite(s.air.pressure) && s.air.pressure >= 0.0, "wind pressure must be finite and >= 0");
  long long particles = 0;
  for (const ClothSettings& cloth : s.cloths) {
    particles += static_cast<long long>(cloth.lattice.columns) * cloth.lattice.rows;
    require(finite(cloth.mass) && cloth.mass > 0.0, "cloth mass must be positive");
    const Real clothParticles = static_cast<Real>(cloth.lattice.columns) * cloth.lattice.rows;
    require(std::isfinite(clothParticles / cloth.mass) && cloth.mass / clothParticles > 0.0,
            "cloth mass per particle must be a positive number with a finite inverse");
    require(finite(cloth.lattice.origin), "cloth origin must be finite");
    require(finite(cloth.initialVelocity), "cloth velocity must be finite");
    for (const KindMaterial& m : cloth.materials) {
      require(finite(m.stiffness) && m.stiffness >= 0.0 && finite(m.damping) && m.damping >= 0.0,
              "constraint stiffness and damping must be finite and >= 0");
      if (solver.model == Model::position) {
        require(m.stiffness <= 1.0 && m.damping <= 1.0, "position-model stiffness and damping must be in 0..1");
      }
    }
    for (const Pin& pin : cloth.pins) {
      require(pin.column >= 0 && pin.column < cloth.lattice.columns && pin.row >= 0 && pin.row < cloth.lattice.rows,
              "pin outside the lattice");
      require(!pin.position || finite(*pin.position), "pin position must be finite");
    }
  }
  require(particles <= kMaxParticles, "too many particles");
  for (const ClothSettings& cloth : s.cloths) {
    require(finite(cloth.thickness) && cloth.thickness > 0.0, "cloth thickness must be positive");
    for (const KindMaterial& m : cloth.materials) {
      require(finite(m.compliance) && m.compliance >= 0.0, "constraint compliance must be finite and >= 0");
    }
  }
  const SelfCollisionSettings& self = s.selfCollision;
  require(finite(self.distance) && self.distance > 0.0 && finite(self.friction) && self.friction >= 0.0 &&
              self.friction <= 1.0 && finite(self.maxTravel) && self.maxTravel > 0.0,
          "self-collision distance must be positive, friction in 0..1, maxTravel positive");
  for (const ColliderSettings& c : s.colliders) {
    require(finite(c.position) && finite(c.velocity) && finite(c.angularVelocity), "collider numbers must be finite");
    require(finite(c.friction.staticCoefficient) && c.friction.staticCoefficient >= 0.0 &&
                finite(c.friction.kineticCoefficient) && c.friction.kineticCoefficient >= 0.0,
            "collider friction must be finite and >= 0");
    switch (c.shape) {
      case ColliderShape::plane:
        require(finite(c.normal) && glm::length(c.normal) > 0.0, "plane normal must not be zero");
        break;
      case ColliderShape::sphere:
      case ColliderShape::capsule:
        require(finite(c.radius) && c.radius > 0.0, "collider radius must be positive");
        break;
      case ColliderShape::box:
        require(finite(c.halfExtents) && glm::all(glm::greaterThan(c.halfExtents, Vec3{0.0})),
                "box half extents must be positive");
        break;
      case ColliderShape::mesh: require(c.mesh && !c.mesh->triangles.empty(), "mesh collider has no triangles"); break;
    }
  }
}

bool used(const KindMaterial& m) { return m.stiffness > 0.0 || m.damping > 0.0; }

Stage integratorStage(Integrator integrator) {
  switch (integrator) {
    case Integrator::explicitEuler: return Stage::explicitEuler;
    case Integrator::symplecticEuler: return Stage::symplecticEuler;
    case Integrator::verlet: return Stage::verletForces;
    case Integrator::midpoint: return Stage::midpoint;
    case Integrator::rk4: return Stage::rk4;
  }
  return Stage::rk4;
}

Cloth makeCloth(const ClothSettings& settings, Model model) {
  Cloth cloth;
  cloth.settings = settings;
  cloth.rest = buildLattice(settings.lattice, {used(settings.material(ConstraintKind::stretch)),
                                               used(settings.material(ConstraintKind::shear)),
                                               used(settings.material(ConstraintKind::bend))});
  const std::size_t n = cloth.rest.particleCount();
  cloth.particleMass = settings.mass / static_cast<Real>(n);
  ParticleState& s = cloth.state;
  s.position = cloth.rest.restPositions;
  s.inverseMass.assign(n, 1.0 / cloth.particleMass);
  for (const Pin& pin : settings.pins) {
    const ParticleIndex p = cloth.rest.index(pin.column, pin.row);
    s.inverseMass[p] = 0.0;
    if (pin.position) s.position[p] = *pin.position;
  }
  s.previousPosition = s.position;
  if (model == Model::force) {
    s.velocity.assign(n, settings.initialVelocity);
    for (std::size_t i = 0; i < n; ++i) {
      if (s.inverseMass[i] == 0.0) s.velocity[i] = Vec3{0.0};
    }
  }
  return cloth;
}

}  // namespace

std::uint64_t nextTopologyVersion() {
  // Process-wide so that two worlds never share a version; it never influences the simulation.
  static std::atomic<std::uint64_t> counter{0};
  return ++counter;
}

World::World(WorldSettings settings) : settings_(std::move(settings)), topologyVersion_(nextTopologyVersion()) {
  validate(settings_);
  const Model model = settings_.solver.model;
  bool anyTriangles = false, anyProjected = false, anyDamped = false;
  for (const ClothSettings& clothSettings : settings_.cloths) {
    cloths_.push_back(makeCloth(clothSettings, model));
    const Cloth& cloth = cloths_.back();
    anyTriangles = anyTriangles || !cloth.rest.triangles.empty();
    for (ConstraintKind kind : kConstraintKinds) {
      if (cloth.rest.of(kind).empty()) continue;
      anyProjected = anyProjected || clothSettings.material(kind).stiffness > 0.0;
      anyDamped = anyDamped || clothSettings.material(kind).damping > 0.0;
    }
  }
  scratch_.resize(cloths_.size());
  if (settings_.solver.tethers && model == Model::position) {
    for (std::size_t c = 0; c < cloths_.size(); ++c) {
      const Cloth& cloth = cloths_[c];
      for (std::size_t p = 0; p < cloth.state.position.size(); ++p) {
        if (cloth.state.inverseMass[p] != 0.0) continue;
        for (std::size_t i = 0; i < cloth.state.position.size(); ++i) {
          if (cloth.state.inverseMass[i] == 0.0) continue;
          // As far from the pin as it is at rest (Euclidean: never shorter than the path in the cloth).
          const Real length = glm::length(cloth.rest.restPositions[i] - cloth.rest.restPositions[p]);
          scratch_[c].tethers.push_back({static_cast<ParticleIndex>(i), static_cast<ParticleIndex>(p), length});
        }
      }
      anyProjected = anyProjected || !scratch_[c].tethers.empty();
    }
  }
  for (const ColliderSettings& collider : settings_.colliders) colliders_.emplace_back(collider);
  const bool anyColliders = !colliders_.empty();
  const bool selfCollision = settings_.selfCollision.enabled && model == Model::position;

  const auto add = [this](Stage stage, bool perSubstep) { profile_.push_back({stage, perSubstep}); };
  if (model == Model::position) {
    if (settings_.air.pressure > 0.0 && anyTriangles) add(Stage::windPressure, true);
    add(Stage::verletIntegrate, true);
    // Self-collision before the sweeps: its pushes are then reconciled with the constraints
    // (after them, a push in a dense pile could stretch an edge by up to the collision distance).
    if (selfCollision) add(Stage::selfCollide, true);
    if (anyColliders) add(Stage::collide, true);
    if (anyProjected && settings_.solver.iterations > 0) add(Stage::projectConstraints, true);
    if (anyColliders) add(Stage::friction, true);
    if (selfCollision) add(Stage::clampTravel, true);
    if (anyDamped) add(Stage::dampConstraints, true);
  } else {
    add(integratorStage(settings_.solver.integrator), true);
    if (anyColliders) add(Stage::collideForces, true);
  }
  add(Stage::guard, false);
}

bool World::hasStage(Stage stage) const {
  for (const StageTiming& timing : profile_) {
    if (timing.stage == stage) return true;
  }
  return false;
}

Vec3 World::velocity(int cloth, ParticleIndex particle) const {
  const ParticleState& s = cloths_.at(static_cast<std::size_t>(cloth)).state;
  if (!s.velocity.empty()) return s.velocity.at(particle);
  return (s.position.at(particle) - s.previousPosition.at(particle)) / static_cast<Real>(substepDt());
}

void World::startHistory() {
  const Real h = static_cast<Real>(substepDt());
  for (std::size_t c = 0; c < cloths_.size(); ++c) {
    if (settings_.solver.model == Model::position) {
      if (hasStage(Stage::windPressure)) scratch_[c].acceleration.assign(cloths_[c].state.position.size(), Vec3{0.0});
      position::startHistory(cloths_[c], settings_.gravity + settings_.air.drag * settings_.air.velocity,
                             settings_.solver.damping + settings_.air.drag, h);
    } else {
      force::startHistory(cloths_[c], settings_, h, scratch_[c]);
    }
  }
  historyStarted_ = true;
}

void World::runStage(Stage stage) {
  const Real h = static_cast<Real>(substepDt());
  // Work over the whole world first: colliders move once per substep, and self-collision spans
  // every cloth at once.
  if (stage == Stage::collide || stage == Stage::collideForces) moveColliders();
  if (stage == Stage::selfCollide) {
    contact::selfCollide(cloths_, settings_.selfCollision, selfCollisionScratch_);
    return;
  }
  for (std::size_t c = 0; c < cloths_.size(); ++c) {
    Cloth& cloth = cloths_[c];
    SolverScratch& scratch = scratch_[c];
    switch (stage) {
      case Stage::windPressure: position::accumulateWindPressure(cloth, settings_.air, h, scratch.acceleration); break;
      case Stage::verletIntegrate:
        position::integrate(cloth, settings_, h, scratch.acceleration.empty() ? nullptr : &scratch.acceleration);
        break;
      case Stage::projectConstraints:
        position::projectConstraints(cloth, settings_.solver.iterations, h, settings_.solver.xpbd, scratch,
                                     !colliders_.empty());
        break;
      case Stage::dampConstraints: position::dampConstraints(cloth); break;
      case Stage::clampTravel:
        contact::clampTravel(cloth, settings_.selfCollision.maxTravel * settings_.selfCollision.distance);
        break;
      case Stage::collide: contact::detect(cloth, colliders_, scratch); break;
      case Stage::friction: contact::friction(cloth, colliders_, h, scratch); break;
      case Stage::collideForces: contact::respondWithVelocities(cloth, colliders_, h, scratch); break;
      case Stage::explicitEuler:
      case Stage::symplecticEuler:
      case Stage::verletForces:
      case Stage::midpoint:
      case Stage::rk4: force::step(settings_.solver.integrator, cloth, settings_, h, scratch); break;
      case Stage::selfCollide:  // world-wide, above
      case Stage::guard: break;
    }
  }
}

void World::moveColliders() {
  // Contacts are made against where the colliders are at the end of the current substep.
  const Real end = (static_cast<Real>(stepCount_) + static_cast<Real>(substep_ + 1) / settings_.solver.substeps) *
                   settings_.solver.dt;
  for (Collider& collider : colliders_) {
    if (collider.moving()) collider.setTime(end);
  }
}

std::optional<Divergence> World::findBadParticle() const {
  for (std::size_t c = 0; c < cloths_.size(); ++c) {
    const ParticleState& s = cloths_[c].state;
    for (std::size_t i = 0; i < s.position.size(); ++i) {
      const Vec3 x = s.position[i];
      const bool bad = !finite(x) ||
                       !(glm::abs(x.x) <= kRunawayDistance && glm::abs(x.y) <= kRunawayDistance &&
                         glm::abs(x.z) <= kRunawayDistance) ||
                       (!s.velocity.empty() && !(glm::length(s.velocity[i]) <= kRunawaySpeed)) ||
                       !finite(s.previousPosition[i]);
      if (bad) return Divergence{stepCount_ + 1, static_cast<int>(c), static_cast<ParticleIndex>(i)};
    }
  }
  return std::nullopt;
}

StepStatus World::step() {
  using Clock = std::chrono::steady_clock;
  if (divergence_) return StepStatus::diverged;
  if (!historyStarted_) startHistory();
  // Only what a step changes is kept (inverse masses do not change within a step).
  lastGood_.resize(cloths_.size());
  for (std::size_t c = 0; c < cloths_.size(); ++c) {
    const ParticleState& s = cloths_[c].state;
    lastGood_[c].position = s.position;
    lastGood_[c].previousPosition = s.previousPosition;
    lastGood_[c].velocity = s.velocity;
  }

  for (StageTiming& timing : profile_) timing.lastSeconds = 0.0;
  for (int substep = 0; substep < settings_.solver.substeps; ++substep) {
    substep_ = substep;
    for (StageTiming& timing : profile_) {
      if (!timing.perSubstep) continue;
      const auto start = Clock::now();
      runStage(timing.stage);
      timing.lastSeconds += std::chrono::duration<double>(Clock::now() - start).count();
    }
  }
  for (StageTiming& timing : profile_) {
    if (timing.perSubstep) continue;
    const auto start = Clock::now();
    if (timing.stage == Stage::guard) divergence_ = findBadParticle();
    timing.lastSeconds += std::chrono::duration<double>(Clock::now() - start).count();
  }
  for (StageTiming& timing : profile_) timing.totalSeconds += timing.lastSeconds;

  if (divergence_) {
    for (std::size_t c = 0; c < cloths_.size(); ++c) {
      ParticleState& s = cloths_[c].state;
      s.position = lastGood_[c].position;
      s.previousPosition = lastGood_[c].previousPosition;
      s.velocity = lastGood_[c].velocity;
    }
    for (Collider& collider : colliders_) collider.setTime(time());  // back where the good state saw them
    return StepStatus::diverged;
  }
  ++stepCount_;
  return StepStatus::ok;
}

StepStatus World::run(std::int64_t steps) {
  for (std::int64_t i = 0; i < steps; ++i) {
    if (step() == StepStatus::diverged) return StepStatus::diverged;
  }
  return StepStatus::ok;
}

}  // namespace drape::sim
