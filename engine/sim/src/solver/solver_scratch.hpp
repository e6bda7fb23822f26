// The solver's per-cloth working arrays (SolverScratch: the acceleration buffers, tethers, lines,
// batches and the AVX rows of the stiff line solve), a fabric's factored bending block and the
// particle self-collision's hash: internal to the engine, out of its public headers.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "drape/sim/cloth.hpp"
#include "drape/sim/state.hpp"
#include "drape/sim/types.hpp"

namespace drape::sim {

// A fabric's bending block factored (bending.hpp): the Cholesky factor of G W G^T + alpha~ I in
// band storage, and what it was made for.
struct BendingFactor {
  std::vector<BendStencil> stencils;  // as they were when factored
  std::vector<Real> inverseMass;
  Real alphaTilde = 0.0;
  bool usable = false;              // false: too wide to factor (the stencils are swept instead)
  std::vector<std::uint32_t> rank;  // each stencil's row (reverse Cuthill-McKee order)
  std::size_t band = 0;             // half-bandwidth
  std::vector<Real> lower;          // row i: columns i - band .. i, band + 1 entries a row
  std::vector<Vec3> work;           // the right-hand side, then the solution
};

// Per-cloth working arrays of the solver, sized once when the world is made and only for the
// stages that need them (empty otherwise).
struct SolverScratch {
  std::vector<Vec3> acceleration;   // m/s^2: wind pressure (position model), a(x, v) (force model)
  std::vector<Vec3> trialPosition;  // force model, multi-stage integrators: x at a trial point
  std::vector<Vec3> trialVelocity;  // ... and v there
  std::vector<Vec3> sumPosition;    // rk4: weighted sum of the stages' dx/dt
  std::vector<Vec3> sumVelocity;    // rk4: weighted sum of the stages' dv/dt
  // Contacts, only when the world has colliders: per particle the contact plane n . x >= offset.
  std::vector<std::int32_t> contactCollider;  // -1: none
  std::vector<Vec3> contactNormal;
  std::vector<Real> contactOffset;  // m
  std::vector<Real> contactDepth;   // m, penetration resolved this substep (for friction)
  std::vector<Vec3> contactRub;     // m, the friction's tangential correction so far this substep
  // The self-contacts the last substep of this step pushed apart with all four corners in this
  // cloth (in its own numbering; self_contact.hpp's Contact): held again after each of this
  // substep's constraint sweeps (position::projectConstraints), so that the sweeps settle with the
  // layers apart instead of drawing them together for the contacts to push apart once more.
  // Emptied as each step begins: a step starts from its state alone (a snapshot, a tear). Held as
  // the contact sweep holds them (contact::partingWeight, contact::facing).
  struct LayerContact {
    ParticleIndex v[4];
    Real c[4];    // the weights of its two points: sum_k c_k (n . x_k) >= target
    Vec3 normal;  // at the substep's x0, where it was measured
    Real target;  // m
    bool edges;   // edge and edge (corners 0, 1 and 2, 3), else vertex 0 and triangle 1, 2, 3
  };
  std::vector<LayerContact> layerContacts;
  // XPBD: the Lagrange multiplier of every constraint, by kind, reset each substep.
  std::array<std::vector<Real>, kConstraintKindCount> lambda;
  std::vector<Vec3> bendingLambda;  // a fabric's bend stencils (XPBD, a vector multiplier each), reset each substep
  BendingFactor bendingFactor;      // a fabric's: its stencils solved at once
  // Tethers (solver.tethers): each free particle may be no farther from each of its pins (the nearest of its piece,
  // tethers.hpp) than at rest. Kept in runs of consecutive particles tied to the same pins: a run lists its pins once
  // and each of its particles only its lengths (on hang2 that is 8 bytes a particle, not 24).
  struct Tethers {
    struct Tether {  // one, as they are built and filtered (list, assign)
      ParticleIndex particle;
      ParticleIndex pin;
      RestReal length;  // m, the longest they may be apart
    };
    struct Run {
      ParticleIndex first;  // particles first .. first + count
      std::uint32_t count;
      std::uint32_t pins;  // pin[pins .. pins + pinCount)
      std::uint32_t pinCount;
      std::uint32_t lengths;  // particle first + i to pin j: length[lengths + i * pinCount + j]
      std::uint32_t before;   // particles in the runs before this one
    };
    std::vector<Run> run;
    std::vector<ParticleIndex> pin;
    std::vector<RestReal> length;

    bool empty() const { return run.empty(); }
    std::size_t size() const { return length.size(); }  // tethers
    std::size_t particles() const { return run.empty() ? 0 : run.back().before + run.back().count; }
    void clear() { *this = {}; }
    // The tethers one by one, in particle order, a particle's in its run's pin order.
    std::vector<Tether> list() const;
    // From tethers sorted by particle (a particle's consecutive).
    void assign(const std::vector<Tether>& tethers);
  };
  Tethers tethers;
  // Lines (the lines stretch solver): the stretch constraints as chains, rows and columns on a lattice, each
  // solved at once (lines.hpp). Built from the constraints whenever they change. A line keeps no
  // copy of its particles or rest lengths: a cloth keeps its stretch constraints in line order
  // (orderConstraints, lines::order), each line's links one after another and each link from the
  // line's particle k (its a) to k + 1 (its b), so the line reads them there.
  struct LineFamily {
    // Line l has start[l + 1] - start[l] particles, and a slot for each in the per-link arrays
    // below (lambda, tension): link k of the line (k < its particles - 1) is slot start[l] + k.
    std::vector<std::uint32_t> start;
    std::uint32_t linkBase = 0;  // the family's first line's first link, in the stretch constraints
    std::size_t slots() const { return start.empty() ? 0 : start.back(); }
    // Line l's first link in the cloth's stretch constraints.
    std::size_t firstLink(std::size_t l) const { return linkBase + start[l] - l; }
    std::vector<Real> lambda;  // XPBD: multiplier of link k, reset each substep
    // With geometric stiffness (solver.maxStretch) the links' tension is the cloth's
    // (Cloth::stretchTension): the sum of a link's multipliers over this substep's first sweep so
    // far, or before its first step, over the last substep's first sweep. The first step reads it
    // and starts it again (fresh).
    bool fresh = true;
    // Per line: 1 if it takes the full Newton step this substep; the lines in the order they are
    // solved (the taut ones first, tautCount of them). Worked out at the substep's first full step:
    // ordered is cleared by lines::beginSubstep and build, and must be by whatever else writes
    // tension.
    std::vector<std::uint8_t> taut;
    std::vector<std::uint32_t> order;
    // Per line: 1 if line l + 1 is as long and each of its particles is the one after l's (on a
    // lattice, the column beside it): eight such lines are gathered eight particles at a time.
    std::vector<std::uint8_t> besideNext;
    std::size_t tautCount = 0;
    bool ordered = false;
  };
  // With geometric stiffness: a line takes the full Newton step where its geometric stiffness
  // reaches this fraction of its particles' mass somewhere, else the tridiagonal one (lines.cpp,
  // needsFullStep). 0: every line with a link that is not pushed.
  Real fullStepRatio = 0.1;
  // Whether this sweep's line steps add their multipliers to the lines' tension: the substep's
  // first sweep only (position_model.cpp, projectConstraints).
  bool sumTension = true;
  std::array<LineFamily, 2> lines;          // along x, and across
  std::vector<std::uint32_t> looseStretch;  // stretch constraints in no line: solved one by one
  // Working arrays of the line solves, as long as the longest line, one slice per thread.
  std::size_t lineStride = 0;
  std::vector<Vec3> lineNormal;
  std::vector<Real> lineUpper, lineSolution;
  // ... and of the line solve with geometric stiffness: per particle of the stiffLanes lines solved
  // together, each quantity for those lines side by side, so that the solve runs in vector lanes
  // (single precision, in units of each line's first particle's mass).
  struct StiffRows {
    // Up to 8 lines side by side, an AVX register of floats; the solve takes 8 where the CPU has
    // AVX (chosen at run time, lines.cpp) and else 4, an SSE register, in the first lanes. Plain
    // arrays: the AVX solve (lines_wide.cpp, built for AVX) instantiates no library template.
    // The gather's inputs that only the forward elimination reads are kept where it then writes
    // the row's results (it reads them first): the link's constraint value C + alpha~ lambda in yl,
    // 1 if the solve corrects the link (else 0) in schur, the particle's mass in v[0] and 1 if it is
    // free to move in v[1]. 672 bytes a row, not 800: at N = 64 that is 2 bytes a particle.
    static constexpr std::size_t kLanes = 8;
    using Lanes = float[kLanes];
    Lanes nx, ny, nz;  // direction of the link to the next particle (gathered: the difference)
    Lanes g;           // its geometric stiffness: G = g (I - n n^T)
    Lanes inverse[6];  // A^-1 of its eliminated block (symmetric: xx yy zz xy xz yz)
    Lanes v[3], b[3], yx[3];
    Lanes schur;  // the inverse of the link multiplier's pivot
    Lanes yl;
  };
  std::vector<StiffRows> lineStiff;
  // Lines the solve takes side by side: set by lines::build, 8 where the CPU has AVX, else 4 (kept
  // here rather than asked of the CPU each step, so a test can solve the same lines both ways).
  std::size_t stiffLanes = 4;
  // Each kind's constraints come in batches that share no particle (batches.hpp): batch b is
  // [batchStart[b], batchStart[b + 1]); with sequentialTail the last batch is not one.
  std::array<std::vector<std::uint32_t>, kConstraintKindCount> batchStart;
  std::array<bool, kConstraintKindCount> sequentialTail{};
  // The seed's sweep (gauss-seidel): each kind's constraints in the order it takes them, by particle
  // pair (the lower first), as a lattice lists them by lattice position and a tear rebuilds them:
  // indices into the cloth's lists, which keep the lines' and batches' order (orderConstraints).
  std::array<std::vector<std::uint32_t>, kConstraintKindCount> sweepOrder;
  std::uint64_t planVersion = 0;    // the world's topology version the batches and lines were made for
  std::int64_t extraLineSteps = 0;  // line steps taken beyond a sweep's two (solver.maxStretch)
};

// The self-collision spatial hash over every particle of a world.
struct SelfCollisionScratch {
  struct Owner {
    std::uint32_t cloth;
    std::uint32_t particle;
  };
  struct Pair {
    std::uint32_t a, b;  // entries of owner, a < b
  };
  std::vector<Owner> owner;        // hash entry -> particle
  std::vector<glm::u64vec3> cell;  // of each entry, when the hash was built
  std::vector<std::uint32_t> start, fill, entries;
  std::vector<std::vector<Pair>> pairs;  // pairs in neighbouring cells, one list per thread
};

}  // namespace drape::sim
