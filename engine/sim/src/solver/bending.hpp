// A fabric's bending solved at once: the block of every bend stencil of a cloth, projected exactly.
//
// Each stencil's constraint is linear in the positions, C_i = sum_j k_ij x_j (BendStencil), so the
// XPBD update of all of them together is one linear solve,
//   (G W G^T + alpha~ I) dlambda = -(G x + alpha~ lambda),   x += W G^T dlambda,
// with G the stencils' weights, W the inverse masses and alpha~ = 1 / (B h^2). One such projection
// meets every stencil's equation at once, where a Gauss-Seidel sweep over them would need sweeps in
// proportion to (lattice size)^2 to carry a moment along a strip: the matrix couples stencils that
// share a particle, and it grows stiff as 1 / spacing^4 against alpha~. The matrix is symmetric
// positive definite (alpha~ > 0) and banded once the stencils are renumbered by reverse
// Cuthill-McKee (stencils that share a particle close together): on a lattice two share a particle
// only within two rows, so its half-bandwidth is about twice the columns, and a drawn cloth (its
// border particles listed after the inside) gets the same. It is factored (Cholesky, in band
// storage) when the stencils, the inverse masses (a pin or a finger) or alpha~ change, and each
// projection is then two triangular solves.
#pragma once

#include <cstddef>
#include <vector>

#include "drape/sim/cloth.hpp"
#include "drape/sim/state.hpp"
#include "solver/solver_scratch.hpp"

namespace drape::sim::bending {

// The most work a factor may cost, n b^2 multiply-adds for n stencils of half-bandwidth b: a 30 cm
// disc at 3.125 mm (7,383 stencils, b 92, its middle pinned) costs 6.4e7, one 128 particles across
// (2.36 mm) about 2e8, a 128 x 128 lattice (b about 256) 1.1e9; each projection then 2 n b
// multiply-adds a coordinate. Beyond it the stencils are swept one by one (projectBending's
// Gauss-Seidel), which carries a moment one cell a sweep: at 1e8, the limit until the thirty-third
// session, the 128-across disc was swept and hung as a cloth with no bending (cotton's drape
// coefficient 0.567 against 0.784 at 64 across; factored, 0.799).
inline constexpr double kMaxFactorWork = 2.0e9;

// Makes `factor` fit the stencils, inverse masses and alpha~ (refactoring only if one changed).
// False if the block is too wide to factor within kMaxFactorWork (then sweep instead).
bool prepare(BendingFactor& factor, const std::vector<BendStencil>& stencils, const std::vector<Real>& inverseMass,
             Real alphaTilde);

// One exact projection of the block (prepare first, and true).
void project(BendingFactor& factor, ParticleState& s, const std::vector<BendStencil>& stencils,
             std::vector<Vec3>& lambda, Real alphaTilde);

}  // namespace drape::sim::bending
