// What a simulation is asked to do: the engine-side mirror of a scene file, already validated.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string_view>
#include <vector>

#include "drape/sim/cloth.hpp"
#include "drape/sim/collider.hpp"
#include "drape/sim/types.hpp"

namespace drape::sim {

// The seed's two models of cloth.
enum class Model : std::uint8_t {
  position,  // Verlet + iterative constraint satisfaction (Provot 1995, Jakobsen 2001)
  force,     // mass-spring-damper forces integrated by one of the integrators below
};

// Integrators of the force model. The position model always uses Verlet.
enum class Integrator : std::uint8_t {
  explicitEuler,    // x += v dt; v += a(x, v) dt                        (first order, never stable undamped)
  symplecticEuler,  // v += a(x, v) dt; x += v dt      the seed's "Euler" (first order)
  verlet,           // x' = 2x - x_prev + a dt^2       the seed's Verlet  (second order)
  midpoint,         // RK2 with the derivative at the half step          (second order)
  rk4,              // classical Runge-Kutta                              (fourth order)
};

// How the position model solves the stretch (structural) constraints.
enum class StretchSolver : std::uint8_t {
  // The seed's sweep: one constraint at a time, each corrected as the ones before it left the
  // cloth (Gauss-Seidel).
  gaussSeidel,
  // Each row and column of stretch constraints at once, exactly for its linearised constraints (a
  // tridiagonal system, as Goldenthal et al. 2007 do for the whole cloth), two Newton steps a
  // sweep, after tethers, bend and shear in batches shared among the threads (the fast sweep): a
  // sweep carries a correction along the whole line, where Gauss-Seidel carries it one particle.
  lines,
};

std::string_view name(Model model);
std::string_view name(Integrator integrator);
std::string_view name(StretchSolver solver);
std::optional<Model> parseModel(std::string_view text);
std::optional<Integrator> parseIntegrator(std::string_view text);
std::optional<StretchSolver> parseStretchSolver(std::string_view text);

struct SolverSettings {
  Model model = Model::position;
  Integrator integrator = Integrator::verlet;  // force model only
  double dt = 1.0 / 60.0;                      // s, one step
  int substeps = 1;                            // each step is split into this many equal substeps
  int iterations = 20;                         // position model: constraint sweeps per substep
  Real damping = 0.0;                          // 1/s, global velocity damping: a -= damping * v
  // Position model: XPBD (Macklin, Mueller, Chentanez 2016) instead of the seed's stiffness-scaled
  // projection. Each kind then resists with a compliance (m/N, the inverse of a spring constant),
  // and the result no longer depends on the iteration count or the step.
  bool xpbd = false;
  // Position model: long-range attachments (Kim, Chentanez, Mueller 2012): no particle may be
  // farther from a pin than it is at rest. One cheap inequality per particle and pin.
  bool tethers = false;
  // Position model: how the stretch constraints are solved (StretchSolver).
  StretchSolver stretchSolver = StretchSolver::gaussSeidel;
  // Position model, with lines: the most a structural link may stretch, a fraction of its rest
  // length (0.04: 4 % long), that the solver works to; 0: no target, the sweeps do what they do.
  // With a target the engine picks what gets there (docs/scenes.md, position_model.cpp's
  // StretchPlan): each line's step includes its links' geometric stiffness where the line is taut
  // (Tournier et al. 2015, Andrews et al. 2017: a taut line's sideways kinks then cannot grow, so a
  // fine stiff cloth needs no more substeps than a coarse one); with tethers, they are projected
  // again after each line step, so that a tether's pull and the lines' lengths settle within a
  // sweep; and a sweep takes up to kExtraLineSteps more steps while a link a step can move is over
  // the target. A frame that jerks the cloth pays for the steps it needs; the others pay one check.
  // A compliant cloth (xpbd, or a fabric) stretches as its material says: the target leaves it as
  // it is.
  Real maxStretch = 0.0;
  // m/s, position model: a cloth with a fabric takes at least as many substeps as let something
  // moving this fast cross one of its cells in a substep, dt / substeps <= spacing / speed (0: the
  // substeps as given). The sweeps' error in a fabric's rest shape is first order in the substep and
  // grows as the cells shrink; at 7.5 m/s (10 substeps of a 60 Hz step at 12.5 mm, 40 at 3.125 mm)
  // every preset's Peirce cantilever is within 3 % of its bending length at 2 and at 16 sweeps with
  // lines, where 10 substeps left a 3.125 mm strip up to 12 % soft (docs/fabric.md). World::substeps
  // is the count the world runs.
  Real fabricSubstepSpeed = 7.5;

  bool lines() const { return stretchSolver == StretchSolver::lines; }
};

// Which solver keys go together, said once, for the scene reader, the panels, a change of model
// and the world (which refuses settings that break it): the force model has none of xpbd, tethers,
// the lines stretch solver and maxStretch (they belong to the position model) and the position
// model only the "verlet" integrator; maxStretch needs the lines and not xpbd.
struct SolverConflict {
  std::string_view key;    // the key that does not go with the others, as scene files spell it
  std::string_view value;  // what it must be, and why: 0 unless "stretchSolver" is "lines" (...)
};
// The first key that does not go with the others, in the order above; none if they all do.
std::optional<SolverConflict> conflict(const SolverSettings& solver);
// The settings with every key that does not go with the others turned off (an integrator, back to
// "verlet" in the position model).
SolverSettings consistent(SolverSettings solver);

// The air around the cloth, moving uniformly at `velocity`.
struct AirSettings {
  Vec3 velocity{0.0};   // m/s, the wind
  Real drag = 0.0;      // 1/s, linear drag towards the air's velocity: a -= drag * (v - wind)
  Real pressure = 0.0;  // kg/(m^2 s), force on a triangle along its normal:
                        //   f = pressure * area * ((wind - v) . n) n   (what makes a flag flutter)
};

// How one constraint kind resists. Units depend on the model:
//   position: stiffness in 0..1 (fraction of the violation corrected per sweep, the seed's 1/2 each
//             side at 1), damping in 0..1 (fraction of the relative velocity along the constraint
//             removed per substep);
//   force:    stiffness ks in N/m, damping kd in N s/m (the seed's spring-damper).
struct KindMaterial {
  Real stiffness = 1.0;
  Real damping = 0.0;
  Real compliance = 0.0;  // m/N, XPBD only: 0 is rigid (a kind with stiffness 0 is still off)
};

struct Pin {
  int column = 0;
  int row = 0;
  std::optional<Vec3> position;  // m; absent: held where the lattice puts it
};

// One particle of a lattice with a mass of its own (a weight sewn into the hem).
struct ParticleMass {
  int column = 0;
  int row = 0;
  Real mass = 1.0;  // kg
};

// A fabric in physical units (position model). The cloth's mass is then arealDensity times its
// area, a third of each triangle's to each corner; its stretch and shear constraints resist with
// the compliance 1 / stiffness (XPBD, whatever solver.xpbd says: on the lattice an axis link's
// spring constant equals the sheet's stiffness in N/m at any spacing, and likewise the diagonals'
// for shear); and it bends by stencils (BendStencil, cloth.hpp) with the rigidity bendingRigidity instead of
// the seed's distance constraints two particles apart. The `materials` then only give damping.
// The defaults are the scene layer's "cotton" preset (drape/scene/fabric.hpp).
struct Fabric {
  Real arealDensity = 0.2;      // kg/m^2
  Real bendingRigidity = 3e-5;  // N m (bending moment per unit width per unit curvature)
  Real stretchStiffness = 2e4;  // N/m (force per unit width per unit strain)
  Real shearStiffness = 100.0;  // N/m (force per unit width per unit shear angle)
};

struct ClothSettings {
  LatticeSpec lattice;
  // A drawn cloth: this mesh instead of `lattice` (drape/mesh/outline.hpp makes one from a stroke;
  // constrainMesh gives it its constraints). Its mass is spread by area: each particle carries a
  // third of its triangles' area. Shared, not copied, by the settings' copies.
  std::shared_ptr<const LatticeMesh> mesh;
  Real mass = 1.0;            // kg, spread evenly over the particles of a lattice
  Vec3 initialVelocity{0.0};  // m/s, of every unpinned particle at the start
  // rad/s: every unpinned particle also starts turning at this angular velocity about the cloth's
  // centre of mass, v = initialVelocity + initialSpin x (x - centre).
  Vec3 initialSpin{0.0};
  Real thickness = 0.005;  // m, how close a particle comes to a collider's surface
  std::array<KindMaterial, kConstraintKindCount> materials{};
  std::vector<Pin> pins;
  std::vector<ParticleMass> masses;  // lattice only: these particles weigh this much instead
  std::optional<Fabric> fabric;      // physical units instead of `mass` and the materials' stiffness

  KindMaterial& material(ConstraintKind kind) { return materials[static_cast<std::size_t>(kind)]; }
  const KindMaterial& material(ConstraintKind kind) const { return materials[static_cast<std::size_t>(kind)]; }
};

// Cloth keeping out of cloth, within a cloth and between cloths.
enum class SelfContactMethod : std::uint8_t {
  // Triangles: no surface within `distance` of another, and no step makes two triangles pass through
  // each other (self_contact.hpp: vertex-triangle and edge-edge contacts, and an exact fail-safe).
  triangles,
  // Particles: no particle within `distance` of another (Ten Minute Physics 15; Teschner et al. 2003
  // hashing), and a cap on each particle's travel so it cannot cross a layer in one substep.
  particles,
};

std::string_view name(SelfContactMethod method);
std::optional<SelfContactMethod> parseSelfContactMethod(std::string_view text);

struct SelfCollisionSettings {
  bool enabled = false;
  SelfContactMethod method = SelfContactMethod::triangles;
  // m: triangles: the gap kept between two surfaces (the cloth's thickness); particles: the closest
  // two particles may come. Either way, parts of one cloth closer than that at rest keep their rest
  // distance.
  Real distance = 0.01;
  // 0..1: triangles: Coulomb's coefficient between layers; particles: the share of a touching pair's
  // relative velocity removed.
  Real friction = 0.2;
  Real maxTravel = 0.5;  // particles only: fraction of `distance` a particle may move per substep (no crossing)
};

// Tearing (the seed's node splitting): a stretch constraint longer than `threshold` times its rest
// length at the end of a step splits the mesh there. Tunable while the world runs.
struct TearSettings {
  bool enabled = false;
  Real threshold = 1.5;  // > 1
};

struct WorldSettings {
  SolverSettings solver;
  Vec3 gravity{0.0, -9.81, 0.0};  // m/s^2
  AirSettings air;
  std::vector<ClothSettings> cloths;
  std::vector<ColliderSettings> colliders;
  SelfCollisionSettings selfCollision;
  TearSettings tearing;
};

// Limits the engine accepts; the scene layer reports them to the user.
inline constexpr int kMaxLatticeSide = 4096;
inline constexpr long long kMaxParticles = 1 << 20;  // over all cloths of a world
inline constexpr int kMaxSubsteps = 1000;
inline constexpr int kMaxIterations = 10000;
// With solver.maxStretch: the most line steps a sweep takes beyond its two while a link is over it.
inline constexpr int kExtraLineSteps = 4;
// A particle farther than this from the origin is a runaway: the guard treats it like NaN.
inline constexpr Real kRunawayDistance = 1.0e6;  // m
inline constexpr Real kRunawaySpeed = 1.0e6;     // m/s, likewise for a stored velocity

// The substeps a world with these solver settings runs for cloths whose finest fabric spacing is
// `spacing` (m; 0 or less: no cloth has a fabric): solver.substeps, or more where
// solver.fabricSubstepSpeed asks for them, up to kMaxSubsteps.
int substepsFor(const SolverSettings& solver, Real spacing);

}  // namespace drape::sim
