// Lines: a cloth's stretch constraints gathered into chains (rows and columns on a lattice), each
// chain solved at once. For a chain of links k joining particles k and k + 1 with
// C_k = |x_{k+1} - x_k| - r_k and unit directions n_k, the linearised system
//   (J W J^T + alpha~) dlambda = -C - alpha~ lambda
// is tridiagonal: diagonal w_k + w_{k+1} + alpha~, off-diagonal -w_{k+1} (n_k . n_{k+1}); then
//   dx_k = w_k (dlambda_{k-1} n_{k-1} - dlambda_k n_k).
// It is solved in O(links) (Thomas' algorithm; the matrix is symmetric positive definite). Where
// Gauss-Seidel moves a correction one particle per sweep, this moves it along the whole line in
// one: a hanging column of 128 particles is as cheap to keep taut as one of 8.
#pragma once

#include <cstdint>
#include <functional>

#include "drape/sim/world.hpp"
#include "parallel/workers.hpp"
#include "part_clock.hpp"
#include "solver/solver_scratch.hpp"

namespace drape::sim::lines {

// Whether this CPU has AVX (and the system saves its registers), asked once: the files built for
// AVX (lines_wide.cpp, distance_wide.cpp) are called only where it has. False where the engine is
// not built with them.
bool cpuHasAvx();

// The lines a cloth's stretch constraints make: a link goes to the family of its rest direction
// (along x, or not) and joins a line there unless that would give a particle three links in the
// family or close a loop (the links taken in the order of their particles, so the lines do not
// depend on the order the constraints come in); then it is loose. Line order: the rows' links line
// by line, then the columns', then the loose ones (each from its lower particle); each line's link k
// from its particle k (a) to k + 1 (b). It depends only on which links there are, not on the order
// they came in or which way round.
//
// Puts the stretch constraints in line order: part of the one order a cloth's constraints are kept
// in (orderConstraints, cloth.hpp), whichever solver runs. `source` (a torn cloth's recipe names,
// Topology::source) and `tension` (Cloth::stretchTension, where it has one a link; else it is
// stale and emptied) move with them. Putting them in order again changes nothing.
void order(ClothRest& rest, std::vector<std::uint32_t>* source, std::vector<float>* tension);

// Rebuilds scratch.lines and scratch.looseStretch from the cloth's stretch constraints, which must
// be in line order already (order): the lines read their particles and rest lengths there.
void build(const Cloth& cloth, SolverScratch& scratch, int threads);

// One Newton step of every line's projection from where its particles are now: the rows, then the
// columns. `stiffness` scales each correction (position model); with `xpbd`, alphaTilde =
// compliance / h^2 enters the system and the lines' lambdas accumulate. With `geometricStiffness`
// the step adds its multipliers to the tension (Cloth::stretchTension, while scratch.sumTension;
// the substep's first step starts it from them), and with `full` too it is the full Newton step, the links' geometric
// stiffness from that tension as the step found it included (at the substep's first step, the
// last substep's); else the tridiagonal (Gauss-Newton) one. The lines of a family are
// independent: they are shared among the workers.
void step(Cloth& cloth, SolverScratch& scratch, Real stiffness, bool xpbd, Real alphaTilde, bool geometricStiffness,
          bool full, Workers& workers);

// The loose stretch constraints, projected one by one, with XPBD into `looseLambda` (indexed like
// the cloth's stretch constraints).
void solveLoose(Cloth& cloth, const SolverScratch& scratch, Real stiffness, bool xpbd, Real alphaTilde,
                Real* looseLambda);

// How a sweep's stretch solve goes beyond its two Newton steps (solver settings of the same names).
struct Extra {
  bool bothFull = false;  // the second step full too (with geometric stiffness), as the first
  int steps = 0;          // at most this many more full steps ...
  Real tolerance = 0.0;   // ... while a line's link is longer than (1 + tolerance) times its rest
};

// A sweep's stretch solve: two Newton steps over every line of both families (the first full with
// `geometricStiffness`, the second tridiagonal unless extra.bothFull), `afterStep` after each; then,
// while some link a step can move (one of its particles is free) is over extra.tolerance, up to
// extra.steps more full steps, each followed by `afterStep`; then the loose stretch constraints.
// Returns how many more steps it took. Whether a link is over is an OR over the lines, the same
// however the workers share them. The loose constraints are timed by `parts` (Stage::looseLinks).
int solve(Cloth& cloth, SolverScratch& scratch, Real stiffness, bool xpbd, Real alphaTilde, bool geometricStiffness,
          Workers& workers, Real* looseLambda, const Extra& extra = {},
          const std::function<void()>& afterStep = nullptr, PartClock* parts = nullptr);

// At the start of a substep with geometric stiffness: the tension the last substep's first sweep
// added up is what the first step uses, and that step starts the sum again.
void beginSubstep(SolverScratch& scratch);

}  // namespace drape::sim::lines
