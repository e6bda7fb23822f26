#include "solver/position_model.hpp"

#include "drape/sim/metrics.hpp"

#include "collision/contacts.hpp"
#include "invariant.hpp"
#include "solver/aerodynamics.hpp"
#include "solver/bending.hpp"
#include "solver/distance_wide.hpp"
#include "solver/lines.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <functional>

#include <glm/geometric.hpp>

#if defined(__SSE2__) && defined(__x86_64__)
#include <emmintrin.h>
#endif

namespace drape::sim::position {

namespace {
// (1 - e^{-kh}) / (kh), the weight of a constant acceleration in the damped Verlet step; 1 at k = 0.
Real relaxation(Real kh) { return kh > 0.0 ? -std::expm1(-kh) / kh : 1.0; }
}  // namespace

void startHistory(Cloth& cloth, Vec3 acceleration, Real k, Real h) {
  ParticleState& s = cloth.state;
  const Real kh = k * h;
  const auto backFor = [&](Vec3 v0) {
    // Exact displacement over [0, h] of du/dt = a - k u, u(0) = v0: a h^2 / 2 + v0 h when k = 0.
    const Vec3 displacement = kh > 0.0 ? acceleration / k * h + (v0 - acceleration / k) * (h * relaxation(kh))
                                       : v0 * h + 0.5 * acceleration * h * h;
    // Choose x_prev so that the first step, x1 = x0 + (x0 - x_prev) e^{-kh} + a h^2 relaxation, moves exactly that far.
    return (displacement - acceleration * (h * h * relaxation(kh))) * std::exp(kh);
  };
  const Vec3 spin = cloth.settings.initialSpin;
  const bool spins = glm::dot(spin, spin) > 0.0;
  const Vec3 back = backFor(cloth.settings.initialVelocity);
  const Vec3 centre = spins ? centreOfMass(cloth) : Vec3{0.0};
  for (std::size_t i = 0; i < s.position.size(); ++i) {
    if (s.inverseMass[i] == 0.0) {
      s.previousPosition[i] = s.position[i];
    } else if (spins) {
      s.previousPosition[i] =
          s.position[i] - backFor(cloth.settings.initialVelocity + glm::cross(spin, s.position[i] - centre));
    } else {
      s.previousPosition[i] = s.position[i] - back;
    }
  }
}

void accumulateWindPressure(const Cloth& cloth, const AirSettings& air, Real h, std::vector<Vec3>& acceleration) {
  const ParticleState& s = cloth.state;
  std::fill(acceleration.begin(), acceleration.end(), Vec3{0.0});
  const Real inverseH = 1.0 / h;
  addWindPressure(
      cloth.rest, s.position, s.inverseMass, air,
      [&](ParticleIndex p) { return (s.position[p] - s.previousPosition[p]) * inverseH; }, acceleration);
}

namespace {

// The guard's copy is written once a step and read only if the step goes bad: stored past the
// caches where the CPU can (SSE2's streaming stores), it neither reads the lines it fills nor
// pushes the cloth out of the cache. keptAll makes the stores seen before the workers join.
void keep(Vec3* to, const Vec3& x) {
#if defined(__SSE2__) && defined(__x86_64__)
  static_assert(sizeof(Vec3) == 3 * sizeof(double));
  long long* out = reinterpret_cast<long long*>(to);
  for (int k = 0; k < 3; ++k) _mm_stream_si64(out + k, std::bit_cast<long long>(x[k]));
#else
  *to = x;
#endif
}

void keptAll() {
#if defined(__SSE2__) && defined(__x86_64__)
  _mm_sfence();
#endif
}

}  // namespace

Substep makeSubstep(const WorldSettings& world, Real h) {
  // Exact for du/dt = a - k u over one substep: u' = u e^{-kh} + a h (1 - e^{-kh}) / (k h).
  const Real kh = (world.solver.damping + world.air.drag) * h;
  Substep substep;
  substep.h = h;
  substep.decay = std::exp(-kh);
  substep.reach = h * h * relaxation(kh);
  substep.acceleration = world.gravity + world.air.drag * world.air.velocity;
  return substep;
}

void integrate(Cloth& cloth, const Substep& substep, const std::vector<Vec3>* extraAcceleration, Workers& workers,
               Vec3* keepPosition) {
  ParticleState& s = cloth.state;
  const Real decay = substep.decay, h2 = substep.reach;
  const Vec3 constantAcceleration = substep.acceleration;
  workers.run(
      s.position.size(),
      [&](std::size_t begin, std::size_t end, int) {
        for (std::size_t i = begin; i < end; ++i) {
          if (keepPosition) keep(keepPosition + i, s.position[i]);
          if (s.inverseMass[i] == 0.0) {
            // Pinned or held: no force moves it, only the world does. It carries on as it was set to move
            // (a finger sets x_prev one finger step behind); a pin has x_prev = x and stays exactly put.
            const Vec3 x = s.position[i];
            s.position[i] = x + (x - s.previousPosition[i]);
            s.previousPosition[i] = x;
            continue;
          }
          Vec3 acceleration = constantAcceleration;
          if (extraAcceleration) acceleration += (*extraAcceleration)[i];
          const Vec3 x = s.position[i];
          s.position[i] = x + (x - s.previousPosition[i]) * decay + acceleration * h2;
          s.previousPosition[i] = x;
        }
        if (keepPosition) keptAll();
      },
      4096);
}

void projectDistance(std::vector<Vec3>& position, const std::vector<Real>& inverseMass, const DistanceConstraint& c,
                     Real stiffness) {
  const Real wa = inverseMass[c.a], wb = inverseMass[c.b];
  const Real wSum = wa + wb;
  if (wSum == 0.0) return;
  const Vec3 d = position[c.b] - position[c.a];
  const Real length2 = glm::dot(d, d);
  // Coincident particles give no direction to push along; a later sweep, after the neighbours
  // have moved them apart, will.
  if (!(length2 > 1e-20)) return;
  const Real length = std::sqrt(length2);
  const Vec3 correction = d * (stiffness * (length - c.restLength) / (length * wSum));
  position[c.a] += wa * correction;
  position[c.b] -= wb * correction;
}

// XPBD (Macklin et al. 2016, eq. 18): with C = |x_b - x_a| - r and alpha~ = compliance / h^2,
// dlambda = (-C - alpha~ lambda) / (w_a + w_b + alpha~), x_a -= w_a dlambda n0, x_b += w_b dlambda n0,
// n0 the link's direction at the substep's start (alongStart).
void projectCompliant(std::vector<Vec3>& position, const std::vector<Vec3>& start, const std::vector<Real>& inverseMass,
                      const DistanceConstraint& c, Real alphaTilde, Real& lambda) {
  const Real wa = inverseMass[c.a], wb = inverseMass[c.b];
  const Real denominator = wa + wb + alphaTilde;
  if (denominator == 0.0) return;
  const Vec3 d = position[c.b] - position[c.a];
  const Real length2 = glm::dot(d, d);
  if (!(length2 > 1e-20)) return;
  const Real length = std::sqrt(length2);
  const Real deltaLambda = (-(length - c.restLength) - alphaTilde * lambda) / denominator;
  lambda += deltaLambda;
  const Vec3 n = alongStart(d / length, start[c.a], start[c.b], lambda, wa + wb, c.restLength);
  position[c.a] -= n * (wa * deltaLambda);
  position[c.b] += n * (wb * deltaLambda);
}

namespace {

// Onto the ball of radius r around c, if outside it.
Vec3 intoBall(Vec3 x, Vec3 c, Real r) {
  const Vec3 d = x - c;
  const Real length2 = glm::dot(d, d);
  if (length2 <= r * r) return x;
  return c + d * (r / std::sqrt(length2));
}

// The line through two pins: consecutive particles mostly share their pins, so it is worked out
// once per pair met.
struct PinAxis {
  ParticleIndex a = ~ParticleIndex{0}, b = ~ParticleIndex{0};
  Vec3 n{0.0};  // unit, from a to b
  Real distance = 0.0;
  Real halfInverse = 0.0;  // 1 / (2 distance); 0 where the pins coincide
  void update(ParticleIndex pinA, ParticleIndex pinB, Vec3 xa, Vec3 xb) {
    if (pinA == a && pinB == b) return;
    a = pinA;
    b = pinB;
    const Vec3 axis = xb - xa;
    distance = glm::length(axis);
    n = distance > 0.0 ? axis / distance : Vec3{0.0};
    halfInverse = distance > 0.0 ? 0.5 / distance : 0.0;
  }
};

// Whether along / sqrt(length2) >= t / r (a direction within the cone around the axis whose cosine
// is t / r), without the square root.
bool withinCone(Real along, Real length2, Real t, Real r) {
  const Real lhs = along * along * r * r, rhs = t * t * length2;
  return t >= 0.0 ? along >= 0.0 && lhs >= rhs : along >= 0.0 || lhs <= rhs;
}

// The nearest point to x within both balls (Euclidean projection onto their intersection, which
// is never empty for tethers: the rest shape lies in it). Projecting onto one ball and then the
// other instead converges slowly where the balls barely overlap, as they do along an edge between
// two pins (the radii add up to the pins' distance): that edge then sags. Most particles of a
// hanging sheet are inside both balls or on the circle where the spheres meet: both cost no more
// than two square roots.
Vec3 intoLens(Vec3 x, Vec3 a, Real ra, Vec3 b, Real rb, const PinAxis& axis) {
  const Vec3 fromA = x - a, fromB = x - b;
  const Real la2 = glm::dot(fromA, fromA), lb2 = glm::dot(fromB, fromB);
  const bool inA = la2 <= ra * ra, inB = lb2 <= rb * rb;
  if (inA && inB) return x;
  const Real distance = axis.distance;
  if (!(distance > 0.0)) {  // the pins coincide: the smaller ball
    return ra <= rb ? intoBall(x, a, ra) : intoBall(x, b, rb);
  }
  // One ball inside the other (a pin carried towards the other): the lens is the inner ball. The
  // cones below would clamp to a single ray and let a particle on the axis through to the outer
  // sphere. (Told from the radii: along an edge between two pins the balls touch from outside,
  // ra + rb = distance, and that case belongs to the circle.)
  if (distance + rb <= ra) return intoBall(x, b, rb);
  if (distance + ra <= rb) return intoBall(x, a, ra);
  const Vec3 n = axis.n;
  // The spheres meet in the plane at tA from a along n (at tB from b back along it). The part of
  // sphere A inside ball B is the cone of directions from a whose cosine with n is at least
  // tA / ra; x projects onto it, radially, when its own direction from a is in that cone. Likewise
  // for B, along -n. Otherwise the nearest point is on the circle where the spheres meet. (Where
  // one projection lands inside the other ball it is the nearest point of the lens, as for any
  // intersection of convex sets.)
  const Real along = glm::dot(fromA, n);  // signed: negative where the particle is beyond pin a
  const Real tA = std::clamp((distance * distance + ra * ra - rb * rb) * axis.halfInverse, -ra, ra);
  const Real tB = std::clamp((distance * distance + rb * rb - ra * ra) * axis.halfInverse, -rb, rb);
  if (!inA && withinCone(along, la2, tA, ra)) return a + fromA * (ra / std::sqrt(la2));
  if (!inB && withinCone(distance - along, lb2, tB, rb)) return b + fromB * (rb / std::sqrt(lb2));
  const Real rho = std::sqrt(std::max(ra * ra - tA * tA, 0.0));
  const Vec3 centre = a + n * tA;
  const Vec3 off = fromA - n * along;
  const Real offLength = glm::length(off);
  // On the axis every point of the circle is as near; any is as good as another.
  if (!(offLength > 1e-15 * (rho + distance))) return centre;
  return centre + off * (rho / offLength);
}

// Whether every pin of a run of tethered particles still holds (is pinned, not let go).
bool allPinned(const SolverScratch::Tethers& tethers, const SolverScratch::Tethers::Run& run, const Real* w) {
  const ParticleIndex* pin = tethers.pin.data() + run.pins;
  bool all = true;
  for (std::uint32_t j = 0; j < run.pinCount; ++j) all = all && w[pin[j]] == 0.0;
  return all;
}

// `point` within the tethers of the run's particle i: the lens of its two pins where both hold
// (allPinned), else the ball of each pin that holds, in turn. `axis` keeps the line between the
// two pins for the next particle of the run.
Vec3 intoTethers(Vec3 point, const SolverScratch::Tethers& tethers, const SolverScratch::Tethers::Run& run,
                 std::size_t i, const Vec3* x, const Real* w, bool allPinned, PinAxis& axis) {
  const ParticleIndex* pin = tethers.pin.data() + run.pins;
  const RestReal* length = tethers.length.data() + run.lengths + i * run.pinCount;
  if (run.pinCount == 2 && allPinned) {
    axis.update(pin[0], pin[1], x[pin[0]], x[pin[1]]);
    return intoLens(point, x[pin[0]], length[0], x[pin[1]], length[1], axis);
  }
  for (std::uint32_t j = 0; j < run.pinCount; ++j) {
    if (w[pin[j]] == 0.0) point = intoBall(point, x[pin[j]], length[j]);
  }
  return point;
}

// The tethered particles [begin, end) (counted over the runs, in order). A tether holds while its
// pin is pinned (not let go) and nothing holds its particle (a finger then decides where it is).
// A particle is never a pin while it is projected (its inverse mass is not 0), so each one reads
// and writes only its own position.
void projectTethers(ParticleState& s, const SolverScratch::Tethers& tethers, std::size_t begin, std::size_t end) {
  const std::vector<SolverScratch::Tethers::Run>& runs = tethers.run;
  std::size_t r = static_cast<std::size_t>(
      std::upper_bound(runs.begin(), runs.end(), begin, [](std::size_t i, const auto& run) { return i < run.before; }) -
      runs.begin() - 1);
  const Real* w = s.inverseMass.data();
  Vec3* x = s.position.data();
  PinAxis axis;  // pins do not move while tethers are projected
  for (; r < runs.size() && runs[r].before < end; ++r) {
    const SolverScratch::Tethers::Run& run = runs[r];
    const std::size_t from = std::max(begin, std::size_t{run.before}) - run.before;
    const std::size_t to = std::min(end, std::size_t{run.before} + run.count) - run.before;
    const bool pinned = allPinned(tethers, run, w);
    for (std::size_t i = from; i < to; ++i) {
      const ParticleIndex particle = run.first + static_cast<ParticleIndex>(i);
      if (w[particle] == 0.0) continue;
      x[particle] = intoTethers(x[particle], tethers, run, i, x, w, pinned, axis);
    }
  }
}

// Constraints [begin, end) of one kind, in order, as projectDistance each.
void projectRange(ParticleState& s, const DistanceConstraint* constraints, std::size_t begin, std::size_t end,
                  Real stiffness) {
  for (std::size_t k = begin; k < end; ++k) projectDistance(s.position, s.inverseMass, constraints[k], stiffness);
}

void projectCompliantRange(ParticleState& s, const DistanceConstraint* constraints, Real* lambda, std::size_t begin,
                           std::size_t end, Real alphaTilde) {
  for (std::size_t k = begin; k < end; ++k)
    projectCompliant(s.position, s.previousPosition, s.inverseMass, constraints[k], alphaTilde, lambda[k]);
}

// A fabric's bend stencils, in order (XPBD on the vector constraint C = sum k_j (x_j - x_0), which is
// linear in the positions: dlambda = (-C - alpha~ lambda) / (sum w_j k_j^2 + alpha~),
// x_j += w_j k_j dlambda, with alpha~ = 1 / (B h^2)).
void projectBending(ParticleState& s, const std::vector<BendStencil>& stencils, std::vector<Vec3>& lambda,
                    Real alphaTilde) {
  Vec3* x = s.position.data();
  const Real* w = s.inverseMass.data();
  for (std::size_t i = 0; i < stencils.size(); ++i) {
    const BendStencil& b = stencils[i];
    Real weight = 0.0;
    Vec3 C{0.0};
    const Vec3 centre = x[b.v[0]];
    const int used = stencilSize(b);
    for (int j = 0; j < used; ++j) {
      const Real k = b.k[j];
      weight += w[b.v[j]] * k * k;
      if (j > 0) C += k * (x[b.v[j]] - centre);
    }
    if (weight == 0.0) continue;
    const Vec3 delta = (-C - alphaTilde * lambda[i]) / (weight + alphaTilde);
    lambda[i] += delta;
    for (int j = 0; j < used; ++j) x[b.v[j]] += (w[b.v[j]] * Real(b.k[j])) * delta;
  }
}

// A cloth's compliances over h^2 (XPBD's alpha tilde), each kind's and its fabric's bending's,
// worked out once a substep as its constraints are projected.
struct Compliances {
  bool xpbd = false;  // the constraints resist with their compliance (solver.xpbd, or a fabric)
  std::array<Real, kConstraintKindCount> kind{};
  Real bending = 0.0;  // 1 / (B h^2), a fabric's bend stencils (0 without one)
};

Compliances compliancesOf(const Cloth& cloth, const SolverSettings& solver, Real h) {
  Compliances c;
  c.xpbd = solver.xpbd || cloth.settings.fabric;
  for (ConstraintKind kind : kConstraintKinds)
    c.kind[static_cast<std::size_t>(kind)] = cloth.settings.material(kind).compliance / (h * h);
  if (cloth.settings.fabric) c.bending = 1.0 / (cloth.settings.fabric->bendingRigidity * h * h);
  return c;
}

// A fabric's bend stencils: all at once where their block is narrow enough to factor (bending.hpp),
// else one after another.
void bend(Cloth& cloth, const Compliances& compliances, SolverScratch& scratch) {
  const Real alphaTilde = compliances.bending;
  if (scratch.bendingFactor.usable) {
    bending::project(scratch.bendingFactor, cloth.state, cloth.rest.bending, scratch.bendingLambda, alphaTilde);
  } else {
    projectBending(cloth.state, cloth.rest.bending, scratch.bendingLambda, alphaTilde);
  }
}

// The sine of the angle two edges or a triangle's sides must make for their cross to be a normal.
constexpr Real kLeastSine = 0.25;

// The self-contacts the substep before pushed (SolverScratch::layerContacts), each once, as its
// sweeps push them (self_contact.cpp): sum_k c_k (n . x_k) >= target, the masses sharing the move,
// none where that would move a particle far more than the two points part, nor where the two points
// no longer face each other across the normal (one slid off the other's side since).
void holdLayers(Cloth& cloth, const SolverScratch& scratch) {
  std::vector<Vec3>& x = cloth.state.position;
  const std::vector<Real>& w = cloth.state.inverseMass;
  for (const SolverScratch::LayerContact& p : scratch.layerContacts) {
    const Real denominator = contact::partingWeight(w, p);
    if (!(denominator > 0.0)) continue;
    Vec3 between{0.0};
    for (int k = 0; k < 4; ++k) between += x[p.v[k]] * p.c[k];
    // Across the surface as it is now: the triangle's normal, or both edges', turned the way the
    // measured one faces (that one where they turned more than 60 degrees since, or where the two
    // edges, or the triangle's two sides, lie within 14 degrees of parallel, so that their cross
    // points nowhere in particular). The line between the two points (fixed on each layer) tilts
    // as the layers slide, and would push them sideways too; the measured normal is stale where a
    // fast finger turned the triangle.
    const Vec3 a = p.edges ? x[p.v[1]] - x[p.v[0]] : x[p.v[2]] - x[p.v[1]];
    const Vec3 b = p.edges ? x[p.v[3]] - x[p.v[2]] : x[p.v[3]] - x[p.v[1]];
    const Vec3 across = glm::cross(a, b);
    const Real length = glm::length(across);
    Vec3 normal = p.normal;
    if (length > kLeastSine * glm::length(a) * glm::length(b)) {
      const Vec3 unit = across / length;
      const Real facing = glm::dot(unit, p.normal);
      if (std::abs(facing) > 0.5) normal = facing > 0.0 ? unit : -unit;
    }
    const Real gap = glm::dot(between, normal) - p.target;
    if (gap >= 0.0 || !contact::facing(x, p)) continue;
    const Real lambda = -gap / denominator;
    for (int k = 0; k < 4; ++k) x[p.v[k]] += normal * (p.c[k] * w[p.v[k]] * lambda);
  }
}

}  // namespace

Vec3 withinTethers(const ParticleState& s, const SolverScratch::Tethers& tethers, ParticleIndex particle, Vec3 point) {
  const std::vector<SolverScratch::Tethers::Run>& runs = tethers.run;
  const auto after = std::upper_bound(runs.begin(), runs.end(), particle,
                                      [](ParticleIndex i, const auto& run) { return i < run.first; });
  if (after == runs.begin()) return point;
  const SolverScratch::Tethers::Run& run = *(after - 1);
  if (particle >= run.first + run.count) return point;  // pinned: no tethers of its own
  const Real* w = s.inverseMass.data();
  PinAxis axis;
  return intoTethers(point, tethers, run, particle - run.first, s.position.data(), w, allPinned(tethers, run, w), axis);
}

namespace {

Stage partOf(ConstraintKind kind) {
  switch (kind) {
    case ConstraintKind::stretch: return Stage::stretch;
    case ConstraintKind::shear: return Stage::shear;
    case ConstraintKind::bend: return Stage::bend;
  }
  return Stage::stretch;
}

// The seed's sweep: a fabric's bend stencils, then every kind in order (stretch, shear, bend), each
// constraint after the one before it by particle pair (SolverScratch::sweepOrder), then the tethers.
// One thread.
void sweepInOrder(Cloth& cloth, const Compliances& compliances, SolverScratch& scratch, PartClock& parts) {
  ParticleState& s = cloth.state;
  const bool xpbd = compliances.xpbd;
  // A fabric's bending first: the sweep ends with what the eye sees most, the cloth's length.
  if (!cloth.rest.bending.empty()) parts.time(Stage::bendStencils, [&] { bend(cloth, compliances, scratch); });
  for (ConstraintKind kind : kConstraintKinds) {
    const KindMaterial& material = cloth.settings.material(kind);
    if (material.stiffness == 0.0) continue;
    const DistanceConstraint* constraints = cloth.rest.of(kind).data();
    const std::vector<std::uint32_t>& order = scratch.sweepOrder[static_cast<std::size_t>(kind)];
    DRAPE_INVARIANT(order.size() == cloth.rest.of(kind).size(), "the sweep's order was planned");
    parts.time(partOf(kind), [&] {
      if (xpbd) {
        Real* lambda = scratch.lambda[static_cast<std::size_t>(kind)].data();
        const Real alphaTilde = compliances.kind[static_cast<std::size_t>(kind)];
        for (const std::uint32_t k : order) {
          projectCompliant(s.position, s.previousPosition, s.inverseMass, constraints[k], alphaTilde, lambda[k]);
        }
      } else {
        for (const std::uint32_t k : order)
          projectDistance(s.position, s.inverseMass, constraints[k], material.stiffness);
      }
    });
  }
  if (!scratch.tethers.empty()) {
    parts.time(Stage::tethers, [&] { projectTethers(s, scratch.tethers, 0, scratch.tethers.particles()); });
  }
}

// How the line solve works to solver.maxStretch, the same for a substep's every sweep. A rigid
// cloth's lines (not xpbd, no fabric) with a target take the full Newton step with their links'
// geometric stiffness where a line is taut, project the tethers (if any) after each step, both steps
// then full, and take up to kExtraLineSteps more while a link is over the target. A compliant
// cloth stretches as its material says, and takes the plain steps: with geometric stiffness the
// fabric cantilever strips' bending length came out 10 and 12 % short (the Cantilever tests).
struct StretchPlan {
  bool geometricStiffness = false;
  bool tethersBetweenSteps = false;
  lines::Extra extra;
};

StretchPlan stretchPlan(const Cloth& cloth, const SolverSettings& solver, const SolverScratch& scratch) {
  StretchPlan plan;
  // (A target with xpbd never gets here: sim::conflict refuses it.)
  if (!solver.lines() || !(solver.maxStretch > 0.0) || cloth.settings.fabric) return plan;
  plan.geometricStiffness = true;
  plan.tethersBetweenSteps = !scratch.tethers.empty();
  plan.extra = {plan.tethersBetweenSteps, kExtraLineSteps, solver.maxStretch};
  return plan;
}

// The fast sweep (the lines stretch solver): tethers first, then bend and shear in batches shared
// among the workers, then the stretch constraints a line at a time, last, so that a sweep ends with
// what matters most to the eye, the cloth's length; the line solve as `plan` says (lines::solve).
void sweepInBatches(Cloth& cloth, const Compliances& compliances, const StretchPlan& plan, SolverScratch& scratch,
                    Workers& workers, PartClock& parts) {
  ParticleState& s = cloth.state;
  const auto tethers = [&] {
    if (scratch.tethers.empty()) return;
    // Shared out in blocks: the particles near the pins cost more (they are on a sphere, and the
    // rest inside both balls); on hang2 256 the first half of the sheet took 2.6 times as long as
    // the second.
    parts.time(Stage::tethers, [&] {
      workers.runShared(scratch.tethers.particles(), 512, [&](std::size_t begin, std::size_t end, int) {
        projectTethers(s, scratch.tethers, begin, end);
      });
    });
  };
  tethers();
  const bool xpbd = compliances.xpbd;
  // A fabric's bend stencils on one thread (not yet in batches).
  if (!cloth.rest.bending.empty()) parts.time(Stage::bendStencils, [&] { bend(cloth, compliances, scratch); });
  for (ConstraintKind kind : {ConstraintKind::bend, ConstraintKind::shear, ConstraintKind::stretch}) {
    const std::size_t kindIndex = static_cast<std::size_t>(kind);
    const KindMaterial& material = cloth.settings.material(kind);
    if (material.stiffness == 0.0) continue;
    const Real alphaTilde = compliances.kind[kindIndex];
    if (kind == ConstraintKind::stretch) {
      const Real stiffness = xpbd ? 1.0 : material.stiffness;
      Real* looseLambda = scratch.lambda[kindIndex].data();
      // With the tethers between the line steps both steps are full and the tethers follow each,
      // the last too: they keep the edges beside a pin from being pulled long by the last step.
      parts.time(Stage::stretch, [&] {
        scratch.extraLineSteps +=
            lines::solve(cloth, scratch, stiffness, xpbd, alphaTilde, plan.geometricStiffness, workers, looseLambda,
                         plan.extra, plan.tethersBetweenSteps ? std::function<void()>(tethers) : nullptr, &parts);
      });
      continue;
    }
    const DistanceConstraint* constraints = cloth.rest.of(kind).data();
    Real* lambda = scratch.lambda[kindIndex].data();
    // A batch's constraints (no two share a particle) four at a time where the CPU has AVX.
    const auto body = [&](std::size_t begin, std::size_t end, bool batch) {
      if (xpbd) {
        projectCompliantRange(s, constraints, lambda, begin, end, alphaTilde);
        return;
      }
      if (batch && lines::cpuHasAvx()) {
        static_assert(sizeof(Vec3) == 3 * sizeof(double), "positions are read as x, y, z doubles");
        begin = projectBatchWide(reinterpret_cast<double*>(s.position.data()), s.inverseMass.data(), constraints, begin,
                                 end, material.stiffness);
      }
      projectRange(s, constraints, begin, end, material.stiffness);
    };
    const std::vector<std::uint32_t>& start = scratch.batchStart[kindIndex];
    parts.time(partOf(kind), [&] {
      for (std::size_t b = 0; b + 1 < start.size(); ++b) {
        const std::size_t begin = start[b], end = start[b + 1];
        if (scratch.sequentialTail[kindIndex] && b + 2 == start.size()) {
          body(begin, end, false);  // its constraints may share particles: one thread, one after another
        } else {
          // Blocks of up to 2048 constraints, at least four a thread (hang2 64's batches hold 2000).
          const std::size_t block =
              std::clamp<std::size_t>((end - begin) / (4 * static_cast<std::size_t>(workers.threads())), 256, 2048);
          workers.runShared(end - begin, block,
                            [&](std::size_t first, std::size_t last, int) { body(begin + first, begin + last, true); });
        }
      }
    });
  }
}

// One sweep: every constraint (a line at a time with the lines, else in the seed's order), then
// the self-contacts held (scratch.layerContacts) and the collider contacts' planes, with friction.
void sweep(Cloth& cloth, bool lines, const Compliances& compliances, const StretchPlan& plan, const Substep& substep,
           SolverScratch& scratch, const std::vector<Collider>& colliders, Workers& workers, PartClock& parts) {
  if (lines) {
    sweepInBatches(cloth, compliances, plan, scratch, workers, parts);
  } else {
    sweepInOrder(cloth, compliances, scratch, parts);
  }
  if (!scratch.layerContacts.empty()) parts.time(Stage::layerContacts, [&] { holdLayers(cloth, scratch); });
  if (!colliders.empty()) {
    parts.time(Stage::contactPlanes, [&] {
      contact::project(cloth, scratch, &workers);
      contact::friction(cloth, colliders, substep.h, scratch, &workers);
    });
  }
}

}  // namespace

void projectConstraints(Cloth& cloth, const SolverSettings& solver, const Substep& substep, SolverScratch& scratch,
                        const std::vector<Collider>& colliders, Workers& workers, PartClock& parts) {
  const Compliances compliances = compliancesOf(cloth, solver, substep.h);
  if (compliances.xpbd) {
    for (ConstraintKind kind : kConstraintKinds) {
      scratch.lambda[static_cast<std::size_t>(kind)].assign(cloth.rest.of(kind).size(), 0.0);
    }
    scratch.bendingLambda.assign(cloth.rest.bending.size(), Vec3{0.0});
    if (!cloth.rest.bending.empty()) {
      bending::prepare(scratch.bendingFactor, cloth.rest.bending, cloth.state.inverseMass, compliances.bending);
    }
    if (solver.lines()) {
      for (SolverScratch::LineFamily& family : scratch.lines) family.lambda.assign(family.slots(), 0.0);
    }
  }
  const StretchPlan plan = stretchPlan(cloth, solver, scratch);
  if (plan.geometricStiffness) lines::beginSubstep(scratch);
  for (int iteration = 0; iteration < solver.iterations; ++iteration) {
    // The lines' tension (what their geometric stiffness comes from) is the first sweep's
    // multipliers: each later sweep's would add what the bend and shear constraints took back
    // since, and with the geometric stiffness it makes those grow too. The trampoline at 8 sweeps
    // summed over all of them blew up in four frames.
    scratch.sumTension = iteration == 0;
    sweep(cloth, solver.lines(), compliances, plan, substep, scratch, colliders, workers, parts);
  }
}

void sweepAfterContacts(Cloth& cloth, const SolverSettings& solver, const Substep& substep, SolverScratch& scratch,
                        const std::vector<Collider>& colliders, Workers& workers, PartClock& parts) {
  scratch.sumTension = false;
  sweep(cloth, solver.lines(), compliancesOf(cloth, solver, substep.h), stretchPlan(cloth, solver, scratch), substep,
        scratch, colliders, workers, parts);
}

void dampConstraints(Cloth& cloth, const SolverScratch& scratch) {
  ParticleState& s = cloth.state;
  for (ConstraintKind kind : kConstraintKinds) {
    const Real damping = cloth.settings.material(kind).damping;
    if (damping == 0.0) continue;
    const std::vector<DistanceConstraint>& constraints = cloth.rest.of(kind);
    const std::vector<std::uint32_t>& order = scratch.sweepOrder[static_cast<std::size_t>(kind)];
    // In the seed's sweep's order (by particle pair) where it has one; with lines, as kept.
    const bool byPair = order.size() == constraints.size();
    for (std::size_t i = 0; i < constraints.size(); ++i) {
      const DistanceConstraint& c = constraints[byPair ? order[i] : i];
      const Real wa = s.inverseMass[c.a], wb = s.inverseMass[c.b];
      const Real wSum = wa + wb;
      if (wSum == 0.0) continue;
      const Vec3 d = s.position[c.b] - s.position[c.a];
      const Real length = glm::length(d);
      if (!(length > 1e-10)) continue;
      const Vec3 n = d / length;
      // relative displacement over the substep along n (velocity times h)
      const Real relative =
          glm::dot((s.position[c.b] - s.previousPosition[c.b]) - (s.position[c.a] - s.previousPosition[c.a]), n);
      const Real impulse = damping * relative / wSum;
      s.previousPosition[c.a] -= (wa * impulse) * n;
      s.previousPosition[c.b] += (wb * impulse) * n;
    }
  }
}

}  // namespace drape::sim::position
