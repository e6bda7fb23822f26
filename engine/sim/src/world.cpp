#include "drape/sim/world.hpp"

#include "drape/sim/metrics.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "cloth_work.hpp"
#include "collision/contacts.hpp"
#include "collision/self_contact.hpp"
#include "invariant.hpp"
#include "parallel/workers.hpp"
#include "solver/batches.hpp"
#include "solver/force_model.hpp"
#include "solver/lines.hpp"
#include "solver/pair_order.hpp"
#include "solver/position_model.hpp"
#include "solver/solver_scratch.hpp"
#include "solver/tethers.hpp"
#include "topology/topology.hpp"

namespace drape::sim {

namespace {

// v turned by `angle` (radians) about the unit axis u.
Vec3 turned(const Vec3& v, const Vec3& u, Real angle) {
  if (angle == 0.0) return v;
  const Real c = std::cos(angle), s = std::sin(angle);
  return v * c + glm::cross(u, v) * s + u * (glm::dot(u, v) * (1.0 - c));
}

constexpr Real kLargest = std::numeric_limits<Real>::max();
// The most a hand of fingers turns what it holds in one step, radians (fingersTwist): 15 degrees a
// frame at 60 frames a second, far past a wrist's turn.
constexpr Real kMostTwist = 0.25;
bool finite(Real value) { return std::isfinite(value); }
bool finite(Vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

void require(bool condition, const std::string& what) {
  if (!condition) throw std::invalid_argument(what);
}

// Particles the cloth will have: its lattice's, or its mesh's.
long long particlesOf(const ClothSettings& cloth) {
  return cloth.mesh ? static_cast<long long>(cloth.mesh->positions.size())
                    : static_cast<long long>(cloth.lattice.columns) * cloth.lattice.rows;
}

void validateCloth(const ClothSettings& cloth, Model model) {
  if (cloth.mesh) {
    require(cloth.pins.empty(), "a drawn cloth has no lattice to pin by column and row");
    require(!cloth.mesh->triangles.empty(), "a drawn cloth's mesh needs a triangle");
    require(finite(cloth.mesh->spacing) && cloth.mesh->spacing > 0.0, "a drawn cloth's spacing must be positive");
  }
  const long long clothParticles = particlesOf(cloth);
  require(clothParticles <= kMaxParticles, "too many particles");
  require(finite(cloth.mass) && cloth.mass > 0.0, "cloth mass must be positive");
  require(std::isfinite(static_cast<Real>(clothParticles) / cloth.mass) &&
              cloth.mass / static_cast<Real>(clothParticles) > 0.0,
          "cloth mass per particle must be a positive number with a finite inverse");
  require(finite(cloth.lattice.origin), "cloth origin must be finite");
  require(finite(cloth.initialVelocity), "cloth velocity must be finite");
  require(finite(cloth.initialSpin), "cloth spin must be finite");
  for (const KindMaterial& m : cloth.materials) {
    require(finite(m.stiffness) && m.stiffness >= 0.0 && finite(m.damping) && m.damping >= 0.0,
            "constraint stiffness and damping must be finite and >= 0");
    if (model == Model::position) {
      require(m.stiffness <= 1.0 && m.damping <= 1.0, "position-model stiffness and damping must be in 0..1");
    }
    require(finite(m.compliance) && m.compliance >= 0.0, "constraint compliance must be finite and >= 0");
  }
  if (cloth.mesh) require(cloth.masses.empty(), "a drawn cloth has no lattice to weigh particles by column and row");
  for (const ParticleMass& m : cloth.masses) {
    require(m.column >= 0 && m.column < cloth.lattice.columns && m.row >= 0 && m.row < cloth.lattice.rows,
            "particle mass outside the lattice");
    require(finite(m.mass) && m.mass > 0.0 && std::isfinite(1.0 / m.mass), "particle mass must be positive");
  }
  for (const Pin& pin : cloth.pins) {
    require(pin.column >= 0 && pin.column < cloth.lattice.columns && pin.row >= 0 && pin.row < cloth.lattice.rows,
            "pin outside the lattice");
    require(!pin.position || finite(*pin.position), "pin position must be finite");
  }
  require(finite(cloth.thickness) && cloth.thickness > 0.0, "cloth thickness must be positive");
  if (cloth.fabric) {
    const Fabric& f = *cloth.fabric;
    require(model == Model::position, "a fabric needs the position model");
    if (!cloth.mesh) {
      require(cloth.lattice.columns >= 2 && cloth.lattice.rows >= 2,
              "a fabric needs a sheet, at least 2 x 2 particles");
    }
    for (Real value : {f.arealDensity, f.bendingRigidity, f.stretchStiffness, f.shearStiffness}) {
      require(finite(value) && value > 0.0 && std::isfinite(1.0 / value),
              "fabric density, rigidity and stiffnesses must be positive numbers");
    }
    require(cloth.masses.empty(), "a fabric's particles weigh what their area does");
  }
}

void validateTearing(const TearSettings& tearing) {
  require(finite(tearing.threshold) && tearing.threshold > 1.0, "tearing threshold must be a number above 1");
}

void validate(const WorldSettings& s) {
  const SolverSettings& solver = s.solver;
  require(std::isfinite(solver.dt) && solver.dt > 0.0, "solver.dt must be a positive number of seconds");
  require(solver.substeps >= 1 && solver.substeps <= kMaxSubsteps, "solver.substeps is out of range");
  require(solver.dt / solver.substeps >= 1e-9, "the substep dt / substeps must be at least 1e-9 s");
  require(solver.iterations >= 0 && solver.iterations <= kMaxIterations, "solver.iterations is out of range");
  require(finite(solver.damping) && solver.damping >= 0.0, "solver.damping must be finite and >= 0");
  require(finite(solver.maxStretch) && solver.maxStretch >= 0.0 && solver.maxStretch <= 1.0,
          "solver.maxStretch must be a fraction from 0 to 1");
  require(finite(solver.fabricSubstepSpeed) && solver.fabricSubstepSpeed >= 0.0,
          "solver.fabricSubstepSpeed must be a finite number of m/s, 0 or more");
  if (const std::optional<SolverConflict> c = conflict(solver)) {
    throw std::invalid_argument("solver." + std::string(c->key) + ": " + std::string(c->value));
  }
  require(finite(s.gravity), "gravity must be finite");
  require(finite(s.air.velocity), "wind velocity must be finite");
  require(finite(s.air.drag) && s.air.drag >= 0.0, "wind drag must be finite and >= 0");
  require(finite(s.air.pressure) && s.air.pressure >= 0.0, "wind pressure must be finite and >= 0");
  validateTearing(s.tearing);
  long long particles = 0;
  for (const ClothSettings& cloth : s.cloths) {
    validateCloth(cloth, solver.model);
    particles += particlesOf(cloth);
  }
  require(particles <= kMaxParticles, "too many particles");
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
        require(std::isfinite(c.rounding) && c.rounding >= 0.0 &&
                    c.rounding <= std::min({c.halfExtents.x, c.halfExtents.y, c.halfExtents.z}),
                "box rounding must be in 0 .. its smallest half extent");
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

void sortUnique(std::vector<ParticleIndex>& list) {
  std::sort(list.begin(), list.end());
  list.erase(std::unique(list.begin(), list.end()), list.end());
}

// A fabric's stretch and shear in XPBD's compliances; its bending goes to bend stencils.
ClothSettings withFabricMaterials(ClothSettings settings) {
  if (!settings.fabric) return settings;
  KindMaterial& stretch = settings.material(ConstraintKind::stretch);
  KindMaterial& shear = settings.material(ConstraintKind::shear);
  KindMaterial& bend = settings.material(ConstraintKind::bend);
  stretch.stiffness = shear.stiffness = 1.0;
  stretch.compliance = 1.0 / settings.fabric->stretchStiffness;
  shear.compliance = 1.0 / settings.fabric->shearStiffness;
  bend = KindMaterial{0.0, 0.0, 0.0};
  return settings;
}

Cloth makeCloth(const ClothSettings& given, Model model) {
  Cloth cloth;
  const ClothSettings settings = withFabricMaterials(given);
  cloth.settings = settings;
  const ConstraintSelection selection{used(settings.material(ConstraintKind::stretch)),
                                      used(settings.material(ConstraintKind::shear)),
                                      used(settings.material(ConstraintKind::bend))};
  cloth.rest = settings.mesh ? constrainMesh(*settings.mesh, selection) : buildLattice(settings.lattice, selection);
  const std::size_t n = cloth.rest.particleCount();
  ParticleState& s = cloth.state;
  s.position.resize(n);
  for (std::size_t i = 0; i < n; ++i) s.position[i] = cloth.rest.restPosition(i);
  s.mass.assign(n, toMass(settings.mass / static_cast<Real>(n)));
  if (settings.fabric) {
    const std::vector<Real> area = particleAreas(cloth.rest);
    for (std::size_t i = 0; i < n; ++i) {
      const Real m = settings.fabric->arealDensity * area[i];
      require(m > 0.0 && std::isfinite(1.0 / m), "every particle of a fabric must lie on a triangle with an area");
      s.mass[i] = toMass(m);
    }
    cloth.rest.bending = buildBendStencils(cloth.rest);
  } else if (settings.mesh) {
    // By area: a third of each triangle's area to each of its corners, so the border is lighter.
    const std::vector<Real> area = particleAreas(cloth.rest);
    Real total = 0.0;
    for (const glm::uvec3& t : cloth.rest.triangles) total += triangleArea(cloth.rest, t);
    for (std::size_t i = 0; i < n; ++i) s.mass[i] = toMass(settings.mass * area[i] / total);
  }
  for (const ParticleMass& m : settings.masses) s.mass[cloth.rest.index(m.column, m.row)] = toMass(m.mass);
  s.inverseMass.resize(n);
  for (std::size_t i = 0; i < n; ++i) s.inverseMass[i] = 1.0 / s.mass[i];
  s.pinned.assign(n, 0);
  for (const Pin& pin : settings.pins) {
    const ParticleIndex p = cloth.rest.index(pin.column, pin.row);
    s.inverseMass[p] = 0.0;
    s.pinned[p] = 1;
    if (pin.position) s.position[p] = *pin.position;
    cloth.tetherPins.push_back(p);
  }
  sortUnique(cloth.tetherPins);
  s.previousPosition = s.position;
  if (model == Model::force) {
    s.velocity.assign(n, settings.initialVelocity);
    const Vec3 spin = settings.initialSpin;
    const bool spins = glm::dot(spin, spin) > 0.0;
    const Vec3 centre = spins ? centreOfMass(cloth) : Vec3{0.0};
    for (std::size_t i = 0; i < n; ++i) {
      if (s.inverseMass[i] == 0.0) {
        s.velocity[i] = Vec3{0.0};
      } else if (spins) {
        s.velocity[i] += glm::cross(spin, s.position[i] - centre);
      }
    }
  }
  cloth.piece = topology::pieces(cloth.rest, cloth.pieceCount);
  cloth.spacing = topology::madeSpacing(cloth);
  return cloth;
}

// Every unpinned particle with all its array entries grown to `n` (new entries zero).
void grow(std::vector<Vec3>& array, std::size_t n) {
  if (!array.empty()) array.resize(n, Vec3{0.0});
}

}  // namespace

std::uint64_t nextTopologyVersion() {
  // Process-wide so that two worlds never share a version; it never influences the simulation.
  static std::atomic<std::uint64_t> counter{0};
  return ++counter;
}

World::World(WorldSettings settings)
    : settings_(std::move(settings)),
      topologyVersion_(nextTopologyVersion()),
      selfCollisionScratch_(std::make_unique<SelfCollisionScratch>()),
      workers_(std::make_unique<Workers>(1)) {
  validate(settings_);
  for (std::size_t c = 0; c < settings_.cloths.size(); ++c) {
    try {
      records_.emplace_back(makeCloth(settings_.cloths[c], settings_.solver.model));
    } catch (const std::invalid_argument& error) {
      // "cloths.2: ...", or "cloths.2.grid.width: ..." where the message names a key of the cloth.
      const std::string what = error.what();
      throw std::invalid_argument("cloths." + std::to_string(c) + (what.starts_with("grid.") ? "." : ": ") + what);
    }
  }
  require(particleCount() <= static_cast<std::size_t>(kMaxParticles), "too many particles");
  settings_.cloths.clear();  // each cloth keeps its own, in its record
  substeps_ = substepsFor(settings_.solver, finestFabricSpacing());
  for (std::size_t c = 0; c < records_.size(); ++c) buildTethers(c);
  for (const ColliderSettings& collider : settings_.colliders) colliders_.emplace_back(collider);
  buildPipeline();
  planAll();
}

void World::buildTethers(std::size_t c) {
  if (!settings_.solver.tethers || settings_.solver.model != Model::position) return;
  const std::vector<SolverScratch::Tethers::Tether> tethers = nearestPinTethers(records_[c].cloth);
  records_[c].work->solver.tethers.assign(tethers);
}

void World::buildPipeline() {
  const Model model = settings_.solver.model;
  bool anyTriangles = false, anyProjected = false, anyDamped = false;
  for (std::size_t c = 0; c < records_.size(); ++c) {
    const Cloth& cloth = records_[c].cloth;
    anyTriangles = anyTriangles || !cloth.rest.triangles.empty();
    anyProjected = anyProjected || !records_[c].work->solver.tethers.empty();
    for (ConstraintKind kind : kConstraintKinds) {
      if (cloth.rest.of(kind).empty()) continue;
      anyProjected = anyProjected || cloth.settings.material(kind).stiffness > 0.0;
      anyDamped = anyDamped || cloth.settings.material(kind).damping > 0.0;
    }
  }
  const bool anyColliders = !colliders_.empty();
  const bool selfContact = settings_.selfCollision.enabled && model == Model::position && anyTriangles &&
                           settings_.selfCollision.method == SelfContactMethod::triangles;
  const bool selfCollision = settings_.selfCollision.enabled && model == Model::position &&
                             settings_.selfCollision.method == SelfContactMethod::particles;
  selfContactHolds_ = selfContact;
  bool anyHeld = false;
  for (const Finger& finger : fingers_) anyHeld = anyHeld || !finger.grips.empty();

  // Timings carry over for the stages that stay.
  const Profile old = std::move(profile_);
  profile_.clear();
  const auto add = [&](Stage stage, bool perSubstep) {
    StageTiming timing{stage, perSubstep, 0.0, 0.0, {}};
    for (const StageTiming& before : old) {
      if (before.stage != stage) continue;
      timing.totalSeconds = before.totalSeconds;
      timing.parts = before.parts;
    }
    profile_.push_back(timing);
  };
  if (anyHeld) add(Stage::fingers, true);
  if (model == Model::position) {
    if (settings_.air.pressure > 0.0 && anyTriangles) add(Stage::windPressure, true);
    add(Stage::verletIntegrate, true);
    // Self-collision before the sweeps: its pushes are then reconciled with the constraints
    // (after them, a push in a dense pile could stretch an edge by up to the collision distance).
    if (selfCollision) add(Stage::selfCollide, true);
    if (anyColliders) add(Stage::collide, true);
    const bool sweeps = anyProjected && settings_.solver.iterations > 0;
    if (sweeps) add(Stage::projectConstraints, true);
    // Self-contact after everything else that moves positions, so that its fail-safe has the last
    // word: nothing after it in a substep moves a particle (constraint damping changes velocities).
    // It applies the colliders' friction itself, between its sweeps and its fail-safe. Without it,
    // the sweeps apply it after each one (timed as their part `contact planes`), and the stage is
    // wanted only where there are no sweeps.
    if (anyColliders && !selfContact && !sweeps) add(Stage::friction, true);
    if (selfContact) add(Stage::selfContact, true);
    if (selfCollision) add(Stage::clampTravel, true);
    if (anyDamped) add(Stage::dampConstraints, true);
  } else {
    add(integratorStage(settings_.solver.integrator), true);
    if (anyColliders) add(Stage::collideForces, true);
  }
  add(Stage::guard, false);
  if (settings_.tearing.enabled && !records_.empty()) add(Stage::tear, false);
  // The guard goes back to the positions before the step, at rest: no copy where one substep of the
  // position model leaves them in the previous positions (its integration sets x_prev = x and no
  // stage after it writes x_prev); else a copy, made by that integration as it reads them where
  // it is the first stage to change anything (no finger moves particles before it).
  const auto onlyPositionsAfterIntegration = [&] {
    for (const StageTiming& timing : profile_) {
      switch (timing.stage) {
        case Stage::windPressure:
        case Stage::verletIntegrate:
        case Stage::projectConstraints:
        case Stage::collide:
        case Stage::friction:
        case Stage::selfContact:
        case Stage::guard:
        case Stage::tear: break;
        default: return false;
      }
    }
    return true;
  };
  guardCopy_ = model != Model::position                            ? GuardCopy::before
               : substeps_ == 1 && onlyPositionsAfterIntegration() ? GuardCopy::none
               : anyHeld                                           ? GuardCopy::before
                                                                   : GuardCopy::integration;
  if (model == Model::position) {
    // Wind pressure's per-particle accelerations exist exactly while its stage does (tuning can
    // switch it on or off): the integrator adds them whenever the array is there.
    const bool wind = hasStage(Stage::windPressure);
    for (std::size_t c = 0; c < records_.size(); ++c) {
      std::vector<Vec3>& acceleration = records_[c].work->solver.acceleration;
      if (wind) {
        acceleration.resize(records_[c].cloth.state.position.size(), Vec3{0.0});
      } else {
        acceleration.clear();
      }
    }
  }
}

void World::plan(std::size_t c) {
  SolverScratch& scratch = records_[c].work->solver;
  if (scratch.planVersion == topologyVersion_) return;
  if (settings_.solver.lines()) {
    // The fast sweep's batches and lines, read off the constraints' one order (orderConstraints,
    // which the cloth's came in or were put in when it changed): the plan reorders nothing.
    const Cloth& cloth = records_[c].cloth;
    // The stretch constraints have no batches: the lines solve them (a loose one one by one).
    const batches::Batches made = batches::find(cloth.rest, false);
    scratch.batchStart = made.start;
    scratch.sequentialTail = made.sequentialTail;
    lines::build(cloth, scratch, workers_->threads());
    scratch.sweepOrder = {};
  } else {
    // The seed's sweep takes each kind by particle pair, however the lists are kept.
    const Cloth& cloth = records_[c].cloth;
    for (std::size_t kind = 0; kind < kConstraintKindCount; ++kind) {
      scratch.sweepOrder[kind] = byParticlePair(cloth.rest.constraints[kind]);
    }
    scratch.batchStart = {};
    scratch.lines = {};
    scratch.looseStretch.clear();
    scratch.lineNormal.clear();
    scratch.lineUpper.clear();
    scratch.lineSolution.clear();
    scratch.lineStiff.clear();
  }
  scratch.planVersion = topologyVersion_;
}

void World::setThreads(int threads) {
  require(threads >= 1 && threads <= kMaxThreads, "threads must be 1 to 64");
  if (threads == workers_->threads()) return;
  workers_ = std::make_unique<Workers>(threads);
  for (ClothRecord& record : records_) record.work->solver.planVersion = 0;  // line slices are per thread
  planAll();
}

int World::threads() const { return workers_->threads(); }

namespace {
template <class T>
std::size_t bytes(const std::vector<T>& v) {
  return v.capacity() * sizeof(T);
}
template <class T, std::size_t N>
std::size_t bytes(const std::array<std::vector<T>, N>& arrays) {
  std::size_t total = 0;
  for (const std::vector<T>& v : arrays) total += bytes(v);
  return total;
}
}  // namespace

MemoryUse World::memoryUse() const {
  MemoryUse m;
  for (const ClothRecord& record : records_) {
    const Cloth& cloth = record.cloth;
    m.rest += bytes(cloth.rest.restOffsets) + bytes(cloth.rest.triangles);
    m.constraints += bytes(cloth.rest.constraints) + bytes(cloth.rest.bending);
    const ParticleState& s = cloth.state;
    m.state += bytes(s.position) + bytes(s.previousPosition) + bytes(s.velocity) + bytes(s.inverseMass) +
               bytes(s.mass) + bytes(s.pinned);
    m.lines += bytes(cloth.stretchTension);
    const Topology& t = cloth.topology;
    m.topology += bytes(t.neighbour) + bytes(t.triangleArea) + bytes(t.templates) + bytes(t.source) +
                  bytes(t.restFrames) + bytes(cloth.piece);
  }
  for (const ClothRecord& record : records_) {
    const SolverScratch& s = record.work->solver;
    m.solver += bytes(s.acceleration) + bytes(s.trialPosition) + bytes(s.trialVelocity) + bytes(s.sumPosition) +
                bytes(s.sumVelocity) + bytes(s.contactCollider) + bytes(s.contactNormal) + bytes(s.contactOffset) +
                bytes(s.contactDepth) + bytes(s.contactRub) + bytes(s.layerContacts) + bytes(s.lambda) +
                bytes(s.bendingLambda) + bytes(s.looseStretch) + bytes(s.lineNormal) + bytes(s.lineUpper) +
                bytes(s.lineSolution) + bytes(s.lineStiff) + bytes(s.batchStart) + bytes(s.sweepOrder) +
                bytes(s.bendingFactor.stencils) + bytes(s.bendingFactor.inverseMass) + bytes(s.bendingFactor.lower) +
                bytes(s.bendingFactor.work) + bytes(s.bendingFactor.rank);
    m.tethers += bytes(s.tethers.run) + bytes(s.tethers.pin) + bytes(s.tethers.length);
    for (const SolverScratch::LineFamily& f : s.lines) {
      m.lines += bytes(f.start) + bytes(f.lambda) + bytes(f.taut) + bytes(f.order) + bytes(f.besideNext);
    }
  }
  for (const ClothRecord& record : records_) {
    m.guard += bytes(record.work->lastGood);
    m.solver += bytes(record.work->held);
  }
  const SelfCollisionScratch& h = *selfCollisionScratch_;
  m.solver += bytes(h.owner) + bytes(h.cell) + bytes(h.start) + bytes(h.fill) + bytes(h.entries);
  for (const auto& pairs : h.pairs) m.solver += bytes(pairs);
  if (selfContact_) m.solver += selfContact_->bytes();
  return m;
}

std::size_t World::memoryBytes() const { return memoryUse().total(); }

std::size_t World::tetherCount() const {
  std::size_t n = 0;
  for (const ClothRecord& record : records_) n += record.work->solver.tethers.size();
  return n;
}

std::int64_t World::extraLineSteps() const {
  std::int64_t n = 0;
  for (const ClothRecord& record : records_) n += record.work->solver.extraLineSteps;
  return n;
}

SelfContactStats World::selfContactStats() const { return selfContact_ ? selfContact_->stats() : SelfContactStats{}; }

ClothRecord::ClothRecord(Cloth c) : cloth(std::move(c)), work(std::make_unique<ClothWork>()) {}
ClothRecord::ClothRecord(ClothRecord&&) noexcept = default;
ClothRecord& ClothRecord::operator=(ClothRecord&&) noexcept = default;
ClothRecord::~ClothRecord() = default;

std::vector<Cloth> ClothList::copy() const {
  std::vector<Cloth> cloths;
  cloths.reserve(records_->size());
  for (const ClothRecord& record : *records_) cloths.push_back(record.cloth);
  return cloths;
}

bool World::isHeld(std::size_t cloth, std::size_t particle) const { return records_[cloth].work->isHeld(particle); }

World::~World() = default;
World::World(World&&) noexcept = default;
World& World::operator=(World&&) noexcept = default;

bool World::hasStage(Stage stage) const {
  for (const StageTiming& timing : profile_) {
    if (timing.stage == stage) return true;
  }
  return false;
}

Real World::stableForceSubstep() const {
  if (settings_.solver.model != Model::force) return std::numeric_limits<Real>::infinity();
  Real fastest = 0.0;  // omega + decay rate, 1/s
  for (const ClothRecord& record : records_) {
    const Cloth& cloth = record.cloth;
    const ParticleState& s = cloth.state;
    std::vector<Real> stiffness(s.position.size(), 0.0), damping(s.position.size(), 0.0);
    for (ConstraintKind kind : kConstraintKinds) {
      const KindMaterial& material = cloth.settings.material(kind);
      for (const DistanceConstraint& c : cloth.rest.of(kind)) {
        for (const ParticleIndex p : {c.a, c.b}) {
          stiffness[p] += material.stiffness;
          damping[p] += material.damping;
        }
      }
    }
    for (std::size_t i = 0; i < s.position.size(); ++i) {
      if (s.inverseMass[i] == 0.0) continue;
      fastest =
          std::max(fastest, std::sqrt(2.0 * stiffness[i] * s.inverseMass[i]) + 2.0 * damping[i] * s.inverseMass[i]);
    }
  }
  if (fastest == 0.0) return std::numeric_limits<Real>::infinity();
  const Real interval = settings_.solver.integrator == Integrator::rk4 ? 2.78 : 2.0;
  return interval / (fastest + settings_.air.drag);
}

Vec3 World::velocity(int cloth, ParticleIndex particle) const {
  const ParticleState& s = records_.at(static_cast<std::size_t>(cloth)).cloth.state;
  if (!s.velocity.empty()) return s.velocity.at(particle);
  return (s.position.at(particle) - s.previousPosition.at(particle)) / static_cast<Real>(substepDt());
}

void World::startHistory(std::size_t c) {
  const Real h = static_cast<Real>(substepDt());
  records_[c].cloth.historyStep = h;
  if (settings_.solver.model == Model::position) {
    position::startHistory(records_[c].cloth, settings_.gravity + settings_.air.drag * settings_.air.velocity,
                           settings_.solver.damping + settings_.air.drag, h);
  } else {
    force::startHistory(records_[c].cloth, force::makeSubstep(settings_, h), records_[c].work->solver);
  }
}

void World::startHistory() {
  for (std::size_t c = 0; c < records_.size(); ++c) startHistory(c);
  historyStarted_ = true;
}

namespace {
// The pipeline's entry for `stage`, or null where the pipeline has no such stage.
StageTiming* entryOf(Profile& profile, Stage stage) {
  for (StageTiming& timing : profile) {
    if (timing.stage == stage) return &timing;
  }
  return nullptr;
}
}  // namespace

template <class Work>
void World::timed(Stage stage, Work&& work) {
  StageTiming* const timing = entryOf(profile_, stage);
  if (!timing) return;
  // The rows run their stages in the order the pipeline lists them, which is the order the profile
  // and the app's stage plot show.
  DRAPE_INVARIANT(timing - profile_.data() > rowAt_, "buildPipeline lists the stages in the order the rows run them");
  rowAt_ = timing - profile_.data();
  ++rowRan_;
  PartClock parts(*timing);
  const auto start = std::chrono::steady_clock::now();
  std::forward<Work>(work)(parts);
  timing->lastSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// A substep of the position model, stage by stage, over what the substep is (position::Substep:
// the integrator's decay and reach, worked out once as it begins). Each runs where the pipeline
// has it (buildPipeline): over every cloth, or over the world at once (fingers, self-collision
// and self-contact span every cloth; colliders move once a substep).
void World::positionSubstep(Real h) {
  const position::Substep substep = position::makeSubstep(settings_, h);
  timed(Stage::fingers, [&](PartClock&) { moveFingers(substep.h); });
  timed(Stage::windPressure, [&](PartClock&) {
    for (ClothRecord& record : records_)
      position::accumulateWindPressure(record.cloth, settings_.air, substep.h, record.work->solver.acceleration);
  });
  timed(Stage::verletIntegrate, [&](PartClock&) {
    const bool keep = guardCopy_ == GuardCopy::integration && substep_ == 0;
    for (ClothRecord& record : records_) {
      std::vector<Vec3>& acceleration = record.work->solver.acceleration;
      position::integrate(record.cloth, substep, acceleration.empty() ? nullptr : &acceleration, *workers_,
                          keep ? record.work->lastGood.data() : nullptr);
    }
  });
  timed(Stage::selfCollide, [&](PartClock&) {
    contact::selfCollide(records_, settings_.selfCollision, *selfCollisionScratch_, *workers_);
  });
  timed(Stage::collide, [&](PartClock&) {
    moveColliders();
    for (ClothRecord& record : records_) contact::detect(record.cloth, colliders_, record.work->solver, workers_.get());
  });
  timed(Stage::projectConstraints, [&](PartClock& parts) {
    for (std::size_t c = 0; c < records_.size(); ++c) {
      // Planned when the world changed (planAll: a tear's or a cut's time includes it), never by the
      // sweeps' own stage. (Should a path have missed it, a build that does not check this plans
      // here, and the plan shows in the profile.)
      DRAPE_INVARIANT(records_[c].work->solver.planVersion == topologyVersion_,
                      "planAll ran after every change a plan is made of");
      if (records_[c].work->solver.planVersion != topologyVersion_) parts.time(Stage::plan, [&] { plan(c); });
      position::projectConstraints(records_[c].cloth, settings_.solver, substep, records_[c].work->solver, colliders_,
                                   *workers_, parts);
    }
  });
  timed(Stage::friction, [&](PartClock&) {
    for (ClothRecord& record : records_)
      contact::friction(record.cloth, colliders_, substep.h, record.work->solver, workers_.get());
  });
  timed(Stage::selfContact, [&](PartClock& parts) {
    if (!selfContact_) selfContact_ = std::make_unique<contact::SelfContact>();
    selfContact_->solve(records_, settings_.selfCollision, topologyVersion_, substeps_ - substep_, *workers_, &parts);
    // Where the contacts pushed, the constraints answer: a sweep of each cloth that pushed against
    // itself, holding what it pushed (position::sweepAfterContacts; contacts between two cloths are
    // not held, so a cloth only another pushed is left as it is), and then the contacts pushed
    // again from there (SelfContact::pushAgain), so that the fail-safe starts from the layers apart.
    const bool pushed = std::any_of(records_.begin(), records_.end(),
                                    [](const ClothRecord& r) { return !r.work->solver.layerContacts.empty(); });
    if (pushed) {
      parts.time(Stage::sweepAfter, [&] {
        PartClock inside;
        for (ClothRecord& record : records_) {
          if (record.work->solver.layerContacts.empty()) continue;
          position::sweepAfterContacts(record.cloth, settings_.solver, substep, record.work->solver, colliders_,
                                       *workers_, inside);
        }
        selfContact_->pushAgain(records_, settings_.selfCollision);
      });
    }
    if (!colliders_.empty()) {
      parts.time(Stage::friction, [&] {
        for (ClothRecord& record : records_)
          contact::friction(record.cloth, colliders_, substep.h, record.work->solver, workers_.get());
      });
    }
    selfContact_->finish(records_, settings_.selfCollision, *workers_, &parts);
  });
  timed(Stage::clampTravel, [&](PartClock&) {
    for (ClothRecord& record : records_)
      contact::clampTravel(record.cloth, settings_.selfCollision.maxTravel * settings_.selfCollision.distance);
  });
  timed(Stage::dampConstraints, [&](PartClock&) {
    for (ClothRecord& record : records_) position::dampConstraints(record.cloth, record.work->solver);
  });
}

// A substep of the force model: the integrator's stage (one of five), then the colliders.
void World::forceSubstep(Real h) {
  const force::Substep substep = force::makeSubstep(settings_, h);
  timed(Stage::fingers, [&](PartClock&) { moveFingers(substep.h); });
  timed(integratorStage(substep.integrator), [&](PartClock&) {
    for (ClothRecord& record : records_) force::step(record.cloth, substep, record.work->solver);
  });
  timed(Stage::collideForces, [&](PartClock&) {
    moveColliders();
    for (ClothRecord& record : records_)
      contact::respondWithVelocities(record.cloth, colliders_, substep.h, record.work->solver);
  });
}

void World::moveColliders() {
  // Contacts are made against where the colliders are at the end of the current substep.
  const Real end = (static_cast<Real>(stepCount_) + static_cast<Real>(substep_ + 1) / substeps_) * settings_.solver.dt;
  for (Collider& collider : colliders_) {
    if (collider.moving()) collider.setTime(end);
  }
}

std::optional<Divergence> World::findBadParticle() const {
  for (std::size_t c = 0; c < records_.size(); ++c) {
    const ParticleState& s = records_[c].cloth.state;
    const auto bad = [&](std::size_t i) {
      const Vec3 x = s.position[i];
      return !finite(x) ||
             !(glm::abs(x.x) <= kRunawayDistance && glm::abs(x.y) <= kRunawayDistance &&
               glm::abs(x.z) <= kRunawayDistance) ||
             (!s.velocity.empty() && !(glm::length(s.velocity[i]) <= kRunawaySpeed)) || !finite(s.previousPosition[i]);
    };
    // Without stored velocities, a block at a time first, without branches (vector instructions):
    // a position within the runaway distance is finite too.
    const auto blockIsGood = [&](std::size_t begin, std::size_t end) {
      if (!s.velocity.empty()) return false;
      bool good = true;
      for (std::size_t i = begin; i < end; ++i) {
        const Vec3 x = s.position[i], p = s.previousPosition[i];
        good &= (std::abs(x.x) <= kRunawayDistance) & (std::abs(x.y) <= kRunawayDistance) &
                (std::abs(x.z) <= kRunawayDistance) & (std::abs(p.x) <= kLargest) & (std::abs(p.y) <= kLargest) &
                (std::abs(p.z) <= kLargest);
      }
      return good;
    };
    // The first bad particle, whichever part of the cloth each worker looked at.
    std::atomic<std::size_t> first{s.position.size()};
    workers_->run(
        s.position.size(),
        [&](std::size_t begin, std::size_t end, int) {
          for (std::size_t block = begin; block < end; block += 256) {
            const std::size_t last = std::min(block + 256, end);
            if (blockIsGood(block, last)) continue;
            for (std::size_t i = block; i < last; ++i) {
              if (!bad(i)) continue;
              std::size_t seen = first.load();
              while (i < seen && !first.compare_exchange_weak(seen, i)) {
              }
              return;
            }
          }
        },
        4096);
    if (first.load() < s.position.size()) {
      return Divergence{stepCount_ + 1, static_cast<int>(c), static_cast<ParticleIndex>(first.load())};
    }
  }
  return std::nullopt;
}

StepStatus World::step() {
  if (divergence_) return StepStatus::diverged;
  if (!historyStarted_) startHistory();
  // The positions before the step, for the guard (where its copy is made: buildPipeline).
  for (std::size_t c = 0; c < records_.size(); ++c) {
    std::vector<Vec3>& good = records_[c].work->lastGood;
    const std::vector<Vec3>& x = records_[c].cloth.state.position;
    if (guardCopy_ == GuardCopy::none) {
      good = {};
      continue;
    }
    good.resize(x.size());
    if (guardCopy_ == GuardCopy::integration) continue;
    workers_->run(
        x.size(),
        [&](std::size_t begin, std::size_t end, int) {
          std::copy(x.begin() + begin, x.begin() + end, good.begin() + begin);
        },
        4096);
  }

  for (StageTiming& timing : profile_) {
    timing.lastSeconds = 0.0;
    for (StageTiming& part : timing.parts) part.lastSeconds = 0.0;
  }
  // A step starts from its state alone: the layers' contacts its substeps hand on begin empty.
  for (ClothRecord& record : records_) record.work->solver.layerContacts.clear();
  const Real h = static_cast<Real>(substepDt());
  for (int substep = 0; substep < substeps_; ++substep) {
    substep_ = substep;
    rowAt_ = -1;
    rowRan_ = 0;
    if (settings_.solver.model == Model::position) {
      positionSubstep(h);
    } else {
      forceSubstep(h);
    }
    DRAPE_INVARIANT(
        rowRan_ == static_cast<std::size_t>(std::count_if(profile_.begin(), profile_.end(),
                                                          [](const StageTiming& t) { return t.perSubstep; })),
        "a substep's row runs every stage the pipeline has for it");
  }
  // Once a step: the guard, then (if it found nothing) tearing.
  timed(Stage::guard, [&](PartClock&) { divergence_ = findBadParticle(); });
  if (!divergence_) timed(Stage::tear, [&](PartClock&) { tear(); });
  for (StageTiming& timing : profile_) {
    timing.totalSeconds += timing.lastSeconds;
    for (StageTiming& part : timing.parts) part.totalSeconds += part.lastSeconds;
  }

  if (divergence_) {
    for (std::size_t c = 0; c < records_.size(); ++c) {
      ParticleState& s = records_[c].cloth.state;
      if (guardCopy_ == GuardCopy::none) {
        s.position = s.previousPosition;
      } else {
        s.position = records_[c].work->lastGood;
        s.previousPosition = records_[c].work->lastGood;
      }
      std::fill(s.velocity.begin(), s.velocity.end(), Vec3{0.0});
    }
    for (Collider& collider : colliders_) collider.setTime(time());  // back where the last good positions saw them
    return StepStatus::diverged;
  }
  // The grips keep the turn the step gave them (moveFingers; the turn reads the fingers' positions
  // and targets, not the offsets it turns).
  const Vec3 axis = fingersAxis();
  for (Finger& finger : fingers_) {
    const Real twist = fingersTwist(finger);
    if (twist == 0.0) continue;
    for (FingerGrip& grip : finger.grips) grip.offset = turned(grip.offset, axis, twist);
  }
  for (Finger& finger : fingers_) finger.position = finger.target;
  ++stepCount_;
  if constexpr (kCheckInvariants) checkInvariants();
  return StepStatus::ok;
}

// What every step leaves as it found it: each record's arrays made for its cloth, each
// particle's arrays as long as its cloth's positions, and the fingers' grips on particles that exist.
void World::checkInvariants() const {
  for (std::size_t c = 0; c < records_.size(); ++c) {
    const ParticleState& s = records_[c].cloth.state;
    const std::size_t n = s.position.size();
    DRAPE_INVARIANT(n == records_[c].cloth.rest.particleCount(), "a particle's rest and state together");
    DRAPE_INVARIANT(
        s.previousPosition.size() == n && s.inverseMass.size() == n && s.mass.size() == n && s.pinned.size() == n,
        "every particle array as long as the positions");
    DRAPE_INVARIANT(s.velocity.empty() || s.velocity.size() == n, "velocities for every particle or none");
    DRAPE_INVARIANT(records_[c].work->held.empty() || records_[c].work->held.size() == n,
                    "held flags for every particle or none");
    DRAPE_INVARIANT(records_[c].work->solver.acceleration.empty() || records_[c].work->solver.acceleration.size() == n,
                    "wind accelerations for every particle or none");
  }
  for (const Finger& finger : fingers_) {
    for (const FingerGrip& grip : finger.grips) {
      const auto c = static_cast<std::size_t>(grip.cloth);
      DRAPE_INVARIANT(c < records_.size() && grip.particle < records_[c].cloth.state.position.size(),
                      "a finger holds particles that exist");
      DRAPE_INVARIANT(isHeld(c, grip.particle), "a particle a finger holds is marked held");
    }
  }
}

StepStatus World::run(std::int64_t steps) {
  for (std::int64_t i = 0; i < steps; ++i) {
    if (step() == StepStatus::diverged) return StepStatus::diverged;
  }
  return StepStatus::ok;
}

// ---- fingers ----------------------------------------------------------------------------------

const Finger* World::finger(int id) const {
  for (const Finger& f : fingers_) {
    if (f.id == id) return &f;
  }
  return nullptr;
}

Finger* World::findFinger(int id) {
  for (Finger& f : fingers_) {
    if (f.id == id) return &f;
  }
  return nullptr;
}

void World::grab(Finger& finger, std::size_t c, ParticleIndex nearest) {
  Cloth& cloth = records_[c].cloth;
  ParticleState& s = cloth.state;
  const Real r2 = finger.radius * finger.radius;
  const std::uint32_t piece = cloth.pieceOf(nearest);
  if (records_[c].work->held.empty()) records_[c].work->held.assign(s.position.size(), 0);
  for (std::size_t i = 0; i < s.position.size(); ++i) {
    const Vec3 offset = s.position[i] - finger.position;
    if (records_[c].work->held[i] || cloth.pieceOf(i) != piece || glm::dot(offset, offset) > r2) continue;
    records_[c].work->held[i] = 1;
    s.inverseMass[i] = 0.0;
    finger.grips.push_back({static_cast<int>(c), static_cast<ParticleIndex>(i), offset});
  }
}

std::optional<int> World::pressFinger(int id, Vec3 point, Real radius) {
  if (finger(id) || fingers_.size() >= static_cast<std::size_t>(kMaxFingers) || !finite(point) || !finite(radius) ||
      !(radius > 0.0)) {
    return std::nullopt;
  }
  Finger f;
  f.id = id;
  f.position = f.target = point;
  f.radius = radius;
  // The piece under the finger is the piece of the free particle nearest to it.
  Real best = radius * radius;
  std::optional<std::pair<std::size_t, ParticleIndex>> nearest;
  for (std::size_t c = 0; c < records_.size(); ++c) {
    const ParticleState& s = records_[c].cloth.state;
    for (std::size_t i = 0; i < s.position.size(); ++i) {
      const Vec3 d = s.position[i] - point;
      const Real d2 = glm::dot(d, d);
      if (isHeld(c, i) || d2 > best) continue;
      best = d2;
      nearest = {{c, static_cast<ParticleIndex>(i)}};
    }
  }
  if (nearest) grab(f, nearest->first, nearest->second);
  fingers_.push_back(std::move(f));
  buildPipeline();
  return static_cast<int>(fingers_.back().grips.size());
}

std::optional<Vec3> World::pressFingerAlongRay(int id, Vec3 origin, Vec3 direction, Real radius) {
  if (finger(id) || fingers_.size() >= static_cast<std::size_t>(kMaxFingers) || !finite(origin) || !finite(direction) ||
      !(glm::length(direction) > 0.0) || !finite(radius) || !(radius > 0.0)) {
    return std::nullopt;
  }
  const Vec3 unit = glm::normalize(direction);
  std::optional<Real> first;
  for (std::size_t c = 0; c < records_.size(); ++c) {
    const ParticleState& s = records_[c].cloth.state;
    for (std::size_t i = 0; i < s.position.size(); ++i) {
      if (isHeld(c, i)) continue;
      const Vec3 d = s.position[i] - origin;
      const Real t = glm::dot(d, unit);
      if (t <= 0.0 || glm::dot(d, d) - t * t > radius * radius) continue;
      if (!first || t < *first) first = t;
    }
  }
  if (!first) return std::nullopt;
  const Vec3 point = origin + unit * *first;
  pressFinger(id, point, radius);
  return point;
}

bool World::moveFinger(int id, Vec3 target) {
  Finger* f = findFinger(id);
  if (!f || !finite(target)) return false;
  f->target = target;
  return true;
}

bool World::releaseFinger(int id) {
  Finger* f = findFinger(id);
  if (!f) return false;
  for (const FingerGrip& grip : f->grips) {
    ParticleState& s = records_[static_cast<std::size_t>(grip.cloth)].cloth.state;
    records_[static_cast<std::size_t>(grip.cloth)].work->held[grip.particle] = 0;
    if (s.pinned[grip.particle]) {
      // A pin the finger carried stays where it was put.
      s.previousPosition[grip.particle] = s.position[grip.particle];
      if (!s.velocity.empty()) s.velocity[grip.particle] = Vec3{0.0};
    } else {
      // x - x_prev (and the stored velocity) still hold the finger's last motion: it flies on.
      s.inverseMass[grip.particle] = 1.0 / s.mass[grip.particle];
    }
  }
  fingers_.erase(fingers_.begin() + (f - fingers_.data()));
  buildPipeline();
  return true;
}

std::optional<int> World::pinFinger(int id) {
  Finger* f = findFinger(id);
  if (!f) return std::nullopt;
  std::vector<std::size_t> changed;
  for (const FingerGrip& grip : f->grips) {
    const auto c = static_cast<std::size_t>(grip.cloth);
    records_[c].cloth.state.pinned[grip.particle] = 1;
    if (std::find(changed.begin(), changed.end(), c) == changed.end()) changed.push_back(c);
  }
  const int pinned = static_cast<int>(f->grips.size());
  releaseFinger(id);
  // A pinned particle has no tethers of its own; none go to these pins (Cloth::tetherPins).
  for (const std::size_t c : changed) buildTethers(c);
  buildPipeline();
  return pinned;
}

int World::unpin(Vec3 point, Real radius) {
  if (!finite(point) || !finite(radius) || !(radius > 0.0)) return 0;
  int freed = 0;
  for (std::size_t c = 0; c < records_.size(); ++c) {
    ParticleState& s = records_[c].cloth.state;
    bool changed = false;
    for (std::size_t i = 0; i < s.position.size(); ++i) {
      const Vec3 d = s.position[i] - point;
      if (!s.pinned[i] || isHeld(c, i) || glm::dot(d, d) > radius * radius) continue;
      s.pinned[i] = 0;
      s.inverseMass[i] = 1.0 / s.mass[i];
      ++freed;
      std::vector<ParticleIndex>& anchors = records_[c].cloth.tetherPins;
      const auto anchor = std::find(anchors.begin(), anchors.end(), static_cast<ParticleIndex>(i));
      if (anchor != anchors.end()) anchors.erase(anchor);  // for good: pinned again by hand it is anywhere
      changed = true;
    }
    if (changed) buildTethers(c);  // none to what is no longer a pin; the freed particle's own
  }
  if (freed > 0) buildPipeline();
  return freed;
}

// The up axis a hand turns about: against gravity, or +y without it.
Vec3 World::fingersAxis() const {
  const Real g = glm::length(settings_.gravity);
  return g > 0.0 && std::isfinite(g) ? -settings_.gravity / g : Vec3{0.0, 1.0, 0.0};
}

Real World::fingersTwist(const Finger& finger) const {
  // The fingers that turn together: those holding the same piece of the same cloth as this one
  // (fingers on another cloth or piece are another hand's). The turn about the up axis that best
  // carries them from where they are to where the step takes them, each about their centre (least
  // squares: the angle of the summed cross and dot products of their offsets from the centres, in
  // the plane across the axis).
  if (finger.grips.empty()) return 0.0;
  const auto handOf = [&](const Finger& f) {
    const FingerGrip& g = f.grips.front();
    const Cloth& cloth = records_[static_cast<std::size_t>(g.cloth)].cloth;
    return std::pair<int, std::uint32_t>{g.cloth, cloth.pieceOf(g.particle)};
  };
  const auto hand = handOf(finger);
  const auto inHand = [&](const Finger& f) { return !f.grips.empty() && handOf(f) == hand; };
  const Vec3 u = fingersAxis();
  Vec3 from{0.0}, to{0.0};
  Real radius = 0.0;
  int count = 0;
  for (const Finger& f : fingers_) {
    if (!inHand(f)) continue;
    from += f.position;
    to += f.target;
    radius += f.radius;
    ++count;
  }
  if (count < 2) return 0.0;
  from /= static_cast<Real>(count);
  to /= static_cast<Real>(count);
  radius /= static_cast<Real>(count);
  Real cross = 0.0, dot = 0.0, spreadFrom = 0.0, spreadTo = 0.0;
  for (const Finger& f : fingers_) {
    if (!inHand(f)) continue;
    Vec3 a = f.position - from, b = f.target - to;
    a -= u * glm::dot(u, a);
    b -= u * glm::dot(u, b);
    cross += glm::dot(u, glm::cross(a, b));
    dot += glm::dot(a, b);
    spreadFrom += glm::dot(a, a);
    spreadTo += glm::dot(b, b);
  }
  // Fingers nearer each other across the axis than about a patch's diameter (two fingers closing
  // to pinch) have no turn to give: there a sideways miss of a millimetre would read as a large
  // turn. Nor has a move that turns them a quarter turn or more in one step (which way is not
  // told), or a figure that is not finite. And at most kMostTwist a step.
  const Real least = static_cast<Real>(count) * radius * radius;
  if (!(spreadFrom >= least) || !(spreadTo >= least) || !(dot > 0.0)) return 0.0;
  const Real angle = std::atan2(cross, dot);
  return std::isfinite(angle) ? std::clamp(angle, -kMostTwist, kMostTwist) : 0.0;
}

void World::moveFingers(Real h) {
  const Real n = static_cast<Real>(substeps_);
  const Real from = static_cast<Real>(substep_) / n, to = static_cast<Real>(substep_ + 1) / n;
  // Two fingers or more turn what they hold with them, as a hand's twist turns the cloth under each
  // fingertip: each grip's offset turns about its finger by the fingers' turn (fingersTwist), a
  // share of it each substep. (Held without turning, each finger's patch kept its heading while the
  // cloth around it turned: two fingers turning the desk's cloth a quarter turn stretched the links
  // around their patches to 2.4 times their length.)
  const Vec3 axis = fingersAxis();
  for (const Finger& f : fingers_) {
    const Real twist = fingersTwist(f);
    const Vec3 path = f.target - f.position;
    const Vec3 start = f.position + path * from;
    const Vec3 travel = path * (to - from);
    for (const FingerGrip& grip : f.grips) {
      const Vec3 offsetFrom = turned(grip.offset, axis, twist * from), offsetTo = turned(grip.offset, axis, twist * to);
      ClothRecord& record = records_[static_cast<std::size_t>(grip.cloth)];
      ParticleState& s = record.cloth.state;
      // Where the cloth cannot tear, a finger cannot hold a particle beyond its tethers (as far from
      // each pin as at rest): the cloth is taut from the pin to the finger there, and the grip slips
      // along it. (Held there, the tethers kept the particles beside it within reach, and the links
      // between took the whole pull: on hang2, a corner drawn 30 cm down past the sheet's reach left
      // one link 27 times its rest length; docs/design.md.) A cloth that can tear is torn instead.
      const SolverScratch::Tethers& tethers = record.work->solver.tethers;
      const bool slips = !tethers.empty() && !settings_.tearing.enabled;
      const auto reach = [&](const Vec3& at) {
        return slips ? position::withinTethers(s, tethers, grip.particle, at) : at;
      };
      if (selfContactHolds_) {
        // Self-contact may have held the particle back where the finger would have driven it through
        // cloth (its fail-safe moves a held particle with the rest of an impact zone): it goes on from
        // where it is, one substep's travel behind where the finger will be at the end of this one,
        // and the integrator (inverse mass 0) carries it there.
        // It catches up at most half the contact distance a substep faster than the finger moves, so
        // that it is not flung when it comes free (nor when the finger lets go just then).
        const Vec3 x = s.position[grip.particle];
        Vec3 move = reach(start + travel + offsetTo) - x;
        const Real length = glm::length(move),
                   most = glm::length(travel + offsetTo - offsetFrom) + 0.5 * settings_.selfCollision.distance;
        if (length > most) move *= most / length;
        s.previousPosition[grip.particle] = x - move;
        continue;
      }
      // Set where the finger is at the start of the substep, and one substep's travel behind: the
      // integrator then carries the particle to where the finger is at its end (inverse mass 0).
      const Vec3 at = reach(start + offsetFrom), by = reach(start + travel + offsetTo) - at;
      s.position[grip.particle] = at;
      s.previousPosition[grip.particle] = at - by;
      if (!s.velocity.empty()) s.velocity[grip.particle] = by / h;
    }
  }
}

// ---- topology ---------------------------------------------------------------------------------

std::size_t World::particleCount() const {
  std::size_t n = 0;
  for (const ClothRecord& record : records_) n += record.cloth.state.position.size();
  return n;
}

void World::afterTopologyChange(std::size_t c, const std::vector<ParticleSplit>& splits,
                                const std::vector<ParticleInsert>& inserted) {
  Cloth& cloth = records_[c].cloth;
  const std::size_t n = cloth.state.position.size();
  cloth.stretchTension.clear();  // its links were split or re-pointed: the tension builds again
  orderConstraints(cloth.rest, cloth.topology.built ? &cloth.topology.source : nullptr);
  if (!records_[c].work->held.empty()) records_[c].work->held.resize(n, 0);
  // A particle a cut put between two particles one finger holds is held by it too, where it lies.
  for (const ParticleInsert& in : inserted) {
    if (!isHeld(c, in.a) || !isHeld(c, in.b)) continue;
    for (Finger& f : fingers_) {
      const FingerGrip *ga = nullptr, *gb = nullptr;
      for (const FingerGrip& g : f.grips) {
        if (g.cloth != static_cast<int>(c)) continue;
        if (g.particle == in.a) ga = &g;
        if (g.particle == in.b) gb = &g;
      }
      if (!ga || !gb) continue;
      const Vec3 offset = glm::mix(ga->offset, gb->offset, in.s);
      f.grips.push_back({static_cast<int>(c), in.particle, offset});
      records_[c].work->held[in.particle] = 1;
      cloth.state.inverseMass[in.particle] = 0.0;
      break;
    }
  }
  // A copy of a held particle stays in the same finger's grip.
  for (const ParticleSplit& split : splits) {
    if (!isHeld(c, split.original)) continue;
    for (Finger& f : fingers_) {
      for (std::size_t g = 0; g < f.grips.size(); ++g) {
        if (f.grips[g].cloth != static_cast<int>(c) || f.grips[g].particle != split.original) continue;
        f.grips.push_back({static_cast<int>(c), split.copy, f.grips[g].offset});
        records_[c].work->held[split.copy] = 1;
        break;
      }
    }
  }
  SolverScratch& scratch = records_[c].work->solver;
  grow(scratch.acceleration, n);
  grow(scratch.trialPosition, n);
  grow(scratch.trialVelocity, n);
  grow(scratch.sumPosition, n);
  grow(scratch.sumVelocity, n);
  cloth.piece = topology::pieces(cloth.rest, cloth.pieceCount);
  // A fabric's stencils from the triangles and links that still join it.
  if (cloth.settings.fabric) cloth.rest.bending = buildBendStencils(cloth.rest);
  // A tether may not reach across a tear; a torn-off copy of a particle is tied to its piece's pins
  // as the particle was. (Built afresh, as loading a snapshot builds them.)
  buildTethers(c);
  topologyVersion_ = nextTopologyVersion();
}

void World::planAll() {
  if (!hasStage(Stage::projectConstraints)) return;
  for (std::size_t c = 0; c < records_.size(); ++c) plan(c);
}

void World::tear() {
  changeTopology(
      [&](Cloth& cloth, std::size_t budget, std::vector<ParticleSplit>& splits, std::vector<ParticleInsert>& inserted) {
        return topology::tear(cloth, settings_.tearing.threshold, budget, splits, inserted);
      });
}

int World::cut(Vec3 a, Vec3 b, Vec3 depth) {
  if (!finite(a) || !finite(b) || !finite(depth)) return 0;
  return changeTopology(
      [&](Cloth& cloth, std::size_t budget, std::vector<ParticleSplit>& splits, std::vector<ParticleInsert>& inserted) {
        return topology::cut(cloth, a, b, depth, budget, splits, inserted);
      });
}

int World::changeTopology(
    const std::function<bool(Cloth&, std::size_t, std::vector<ParticleSplit>&, std::vector<ParticleInsert>&)>& change) {
  // A tear relaxes the links near a fresh crack and a cut puts particles near its line onto it:
  // moves made outside the substeps, where self-contact did not look. With self-contact on, its
  // fail-safe then takes them as a substep's motion from where each particle was: an old one where
  // it was, a new one where it was made (on its edge, in the surface as it was), a copy where its
  // particle was. So neither passes cloth through cloth (a tear's opening seam did, for a few steps).
  const bool settle = hasStage(Stage::selfContact);
  std::vector<std::vector<Vec3>> before;
  if (settle) {
    for (const ClothRecord& record : records_) before.push_back(record.cloth.state.position);
  }
  int opened = 0;
  std::vector<ParticleSplit> splits;
  std::vector<ParticleInsert> inserted;
  for (std::size_t c = 0; c < records_.size(); ++c) {
    splits.clear();
    inserted.clear();
    const std::size_t budget =
        static_cast<std::size_t>(kMaxParticles) - std::min<std::size_t>(particleCount(), kMaxParticles);
    if (!change(records_[c].cloth, budget, splits, inserted)) continue;
    afterTopologyChange(c, splits, inserted);
    ++opened;
    if (!settle) continue;
    // New particles in the order they were made: each from particles made before it.
    std::vector<Vec3>& from = before[c];
    const std::size_t n0 = from.size(), n = records_[c].cloth.state.position.size();
    std::vector<std::int64_t> origin(n - n0, -1);  // index into inserted, or -2 - the copy's original
    for (std::size_t k = 0; k < inserted.size(); ++k) {
      if (inserted[k].particle >= n0) origin[inserted[k].particle - n0] = static_cast<std::int64_t>(k);
    }
    for (const ParticleSplit& split : splits) {
      if (split.copy >= n0) origin[split.copy - n0] = -2 - static_cast<std::int64_t>(split.original);
    }
    from.resize(n);
    for (std::size_t p = n0; p < n; ++p) {
      const std::int64_t o = origin[p - n0];
      if (o >= 0) {
        const ParticleInsert& in = inserted[static_cast<std::size_t>(o)];
        from[p] = glm::mix(from[in.a], from[in.b], in.s);
      } else if (o <= -2) {
        from[p] = from[static_cast<std::size_t>(-2 - o)];
      } else {
        DRAPE_INVARIANT(false, "every new particle is a split's copy or an insert");
        from[p] = records_[c].cloth.state.position[p];
      }
    }
  }
  if (settle && opened > 0) {
    // (A cloth that did not change has as many particles as before.)
    for (std::size_t c = 0; c < records_.size(); ++c) {
      DRAPE_INVARIANT(before[c].size() == records_[c].cloth.state.position.size(),
                      "a cloth that did not change kept its particles");
    }
    if (!selfContact_) selfContact_ = std::make_unique<contact::SelfContact>();
    selfContact_->settle(records_, before, settings_.selfCollision, topologyVersion_, *workers_);
  }
  planAll();
  return opened;
}

Real World::finestFabricSpacing() const {
  Real finest = 0.0;
  for (const ClothRecord& record : records_) {
    if (!record.cloth.settings.fabric) continue;
    const Real spacing = record.cloth.spacing;
    if (spacing > 0.0 && (finest == 0.0 || spacing < finest)) finest = spacing;
  }
  return finest;
}

void World::followSpacing(Real hBefore) {
  substeps_ = substepsFor(settings_.solver, finestFabricSpacing());
  const Real hAfter = static_cast<Real>(substepDt());
  if (historyStarted_ && hAfter != hBefore) {
    // Verlet keeps velocity as x - x_prev over one substep: rescale it to the new substep.
    for (ClothRecord& record : records_) rescaleHistory(record.cloth, hBefore, hAfter);
  }
}

void World::rescaleHistory(Cloth& cloth, Real from, Real to) {
  ParticleState& s = cloth.state;
  if (from > 0.0 && to != from) {
    for (std::size_t i = 0; i < s.position.size(); ++i) {
      s.previousPosition[i] = s.position[i] - (s.position[i] - s.previousPosition[i]) * (to / from);
    }
  }
  cloth.historyStep = to;
}

void World::setTearing(const TearSettings& tearing) {
  validateTearing(tearing);
  settings_.tearing = tearing;
  buildPipeline();
}

// ---- tuning while running ---------------------------------------------------------------------

void World::tune(const WorldSettings& next) {
  WorldSettings candidate = next;
  candidate.cloths.clear();  // the cloths stay as they are (each with its own settings)
  require(
      candidate.solver.model == settings_.solver.model && candidate.solver.integrator == settings_.solver.integrator,
      "the model and the integrator cannot change while the world runs");
  require(candidate.colliders.size() == settings_.colliders.size(),
          "colliders cannot be added or removed while the world runs");
  for (std::size_t i = 0; i < candidate.colliders.size(); ++i) {
    // Only the friction of a collider is tunable: everything else stays as it is.
    const Friction friction = candidate.colliders[i].friction;
    candidate.colliders[i] = settings_.colliders[i];
    candidate.colliders[i].friction = friction;
  }
  validate(candidate);
  const Real hBefore = static_cast<Real>(substepDt());
  const bool tethersChanged = candidate.solver.tethers != settings_.solver.tethers;
  settings_ = std::move(candidate);
  followSpacing(hBefore);
  for (std::size_t i = 0; i < colliders_.size(); ++i) {
    colliders_[i] = Collider(settings_.colliders[i]);
    colliders_[i].setTime(time());
  }
  for (ClothRecord& record : records_) record.work->solver.planVersion = 0;  // lines may have been switched
  if (tethersChanged) {
    for (std::size_t c = 0; c < records_.size(); ++c) {
      records_[c].work->solver.tethers.clear();
      buildTethers(c);
    }
  }
  buildPipeline();
  planAll();
}

// ---- cloths while running ----------------------------------------------------------------------

int World::addCloth(const ClothSettings& settings) {
  validateCloth(settings, settings_.solver.model);
  Cloth cloth = makeCloth(settings, settings_.solver.model);
  require(particleCount() + cloth.state.position.size() <= static_cast<std::size_t>(kMaxParticles),
          "too many particles");
  records_.emplace_back(std::move(cloth));
  const std::size_t c = records_.size() - 1;
  followSpacing(static_cast<Real>(substepDt()));  // before its history starts: made at rest, it stays so
  buildTethers(c);
  buildPipeline();
  if (historyStarted_) {
    // It starts at rest where it was made, whatever happened to the world before.
    startHistory(c);
  }
  topologyVersion_ = nextTopologyVersion();
  planAll();
  return static_cast<int>(c);
}

void World::restoreStepCount(std::int64_t steps) {
  require(steps >= 0, "a step count must not be negative");
  stepCount_ = steps;
  for (Collider& collider : colliders_) collider.setTime(time());
}

void World::restoreCloths(std::vector<Cloth> cloths) {
  std::size_t particles = 0;
  for (const Cloth& cloth : cloths) {
    const ParticleState& s = cloth.state;
    const std::size_t n = cloth.rest.particleCount();
    particles += n;
    validateCloth(cloth.settings, settings_.solver.model);
    require(s.position.size() == n && s.previousPosition.size() == n && s.mass.size() == n &&
                s.inverseMass.size() == n && s.pinned.size() == n &&
                (settings_.solver.model == Model::force ? s.velocity.size() == n : s.velocity.empty()),
            "a cloth's arrays do not all have one entry per particle");
    for (std::size_t i = 0; i < n; ++i) {
      require(finite(cloth.rest.restPosition(i)) && finite(s.position[i]) && finite(s.previousPosition[i]) &&
                  (s.velocity.empty() || finite(s.velocity[i])),
              "a cloth has a position that is not finite");
      // As toMass would keep it: a normal float (a tear halves masses).
      require(std::isfinite(s.mass[i]) && s.mass[i] >= std::numeric_limits<MassReal>::min(),
              "a particle's mass must be positive, at least 1.2e-38 kg");
    }
    for (const ParticleIndex p : cloth.tetherPins)
      require(p < n, "a tether pin names a particle the cloth does not have");
    require(
        cloth.stretchTension.empty() || cloth.stretchTension.size() == cloth.rest.of(ConstraintKind::stretch).size(),
        "a cloth's stretch tension must have one entry per stretch constraint, or none");
    for (const float t : cloth.stretchTension) require(std::isfinite(t), "a stretch tension is not finite");
    for (const glm::uvec3& t : cloth.rest.triangles) {
      require(t.x < n && t.y < n && t.z < n, "a triangle names a particle the cloth does not have");
      require(t.x != t.y && t.y != t.z && t.z != t.x, "a triangle names one particle twice");
    }
    for (const auto& list : cloth.rest.constraints) {
      for (const DistanceConstraint& c : list) {
        require(c.a < n && c.b < n && c.a != c.b, "a constraint names a particle the cloth does not have");
        require(finite(c.restLength) && c.restLength >= 0.0, "a constraint's rest length must be finite");
      }
    }
  }
  require(particles <= static_cast<std::size_t>(kMaxParticles), "too many particles");
  while (!fingers_.empty()) releaseFinger(fingers_.front().id);
  // Made apart and then moved in (which cannot throw): a failure to allocate leaves the world as
  // it was.
  for (Cloth& cloth : cloths) {
    // In the engine's one order, whatever order they were kept in (a hand-edited snapshot).
    orderConstraints(cloth.rest, cloth.topology.built ? &cloth.topology.source : nullptr, &cloth.stretchTension);
  }
  std::vector<ClothRecord> records;
  records.reserve(cloths.size());
  for (Cloth& cloth : cloths) records.emplace_back(std::move(cloth));
  records_ = std::move(records);
  for (ClothRecord& record : records_) {
    // (A snapshot from before cloths kept their spacing has none.)
    if (!(record.cloth.spacing > 0.0)) record.cloth.spacing = topology::madeSpacing(record.cloth);
  }
  // Each cloth's history was kept over the substep it ran at (historyStep; 0: this world's, as in
  // a snapshot of it), which need not be the one these cloths' spacings ask for now: a redo can bring
  // back the finest fabric, whose removal rescaled the others to a longer substep.
  substeps_ = substepsFor(settings_.solver, finestFabricSpacing());
  for (std::size_t c = 0; c < records_.size(); ++c) {
    Cloth& cloth = records_[c].cloth;
    const Real h = static_cast<Real>(substepDt());
    rescaleHistory(cloth, cloth.historyStep > 0.0 ? cloth.historyStep : h, h);
    cloth.settings = withFabricMaterials(cloth.settings);
    if (cloth.settings.fabric) cloth.rest.bending = buildBendStencils(cloth.rest);  // derived from the rest shape
    ParticleState& s = cloth.state;
    // Inverse masses follow from masses and pins (no finger holds anything now); a pin stands still
    // (it may have been caught moving in a finger when the copy was taken).
    for (std::size_t i = 0; i < s.mass.size(); ++i) {
      s.inverseMass[i] = s.pinned[i] ? 0.0 : 1.0 / s.mass[i];
      if (!s.pinned[i]) continue;
      s.previousPosition[i] = s.position[i];
      if (!s.velocity.empty()) s.velocity[i] = Vec3{0.0};
    }
    cloth.piece = topology::pieces(cloth.rest, cloth.pieceCount);
    sortUnique(cloth.tetherPins);  // as makeCloth keeps them
    buildTethers(c);
    if (settings_.solver.model == Model::force)
      force::startHistory(cloth, force::makeSubstep(settings_, static_cast<Real>(substepDt())),
                          records_[c].work->solver);
  }
  buildPipeline();
  // The cloths come with their own history (x_prev, velocities): the next step must not restart it.
  historyStarted_ = true;
  topologyVersion_ = nextTopologyVersion();
  planAll();
}

void World::removeCloth(int index) {
  if (index < 0 || static_cast<std::size_t>(index) >= records_.size()) return;
  for (Finger& f : fingers_) {
    std::erase_if(f.grips, [&](const FingerGrip& g) { return g.cloth == index; });
    for (FingerGrip& g : f.grips) {
      if (g.cloth > index) --g.cloth;
    }
  }
  records_.erase(records_.begin() + index);
  followSpacing(static_cast<Real>(substepDt()));
  buildPipeline();
  topologyVersion_ = nextTopologyVersion();
  planAll();
}

}  // namespace drape::sim
