// The stability classification against linear stability theory for the undamped oscillator.
#include <gtest/gtest.h>

#include <cmath>

#include "drape/analysis/fabric.hpp"
#include "drape/analysis/stability.hpp"
#include "drape/scene/fabric.hpp"

#include <numbers>

namespace drape::analysis {
namespace {

using sim::Integrator;

TEST(Stability, ExplicitEulerAndMidpointNeverConserveAndEulerAlwaysBlowsUp) {
  // |1 + i omega dt| > 1 at any dt: given long enough, explicit Euler's energy runs away.
  EXPECT_EQ(runOscillator(Integrator::explicitEuler, 100.0, 0.01, 5000).verdict, Stability::diverged);
  EXPECT_GT(runOscillator(Integrator::explicitEuler, 100.0, 0.001, 2000).endEnergyRatio, 1.1);
  EXPECT_GT(runOscillator(Integrator::midpoint, 100.0, 0.05, 2000).maxEnergyRatio, 1.0);
}

class Boundary : public ::testing::TestWithParam<Integrator> {};

TEST_P(Boundary, LargestStableStepMatchesLinearTheory) {
  // k = 100 N/m, m = 1 kg: omega = 10 rad/s, so theory says dt < bound / 10.
  const double omega = 10.0;
  const double bound = *theoreticalStableOmegaDt(GetParam()) / omega;
  const std::optional<double> measured = largestStableDt(GetParam(), 100.0, bound / 8.0, bound * 2.0, 1.02, 400);
  ASSERT_TRUE(measured.has_value());
  EXPECT_LE(*measured, bound * 1.02);  // nothing beyond the bound holds (one grid step of slack)
  EXPECT_GE(*measured, bound * 0.85);  // and up to near it everything does
}

INSTANTIATE_TEST_SUITE_P(Integrators, Boundary,
                         ::testing::Values(Integrator::symplecticEuler, Integrator::verlet, Integrator::rk4));

TEST(Stability, BelowTheBoundTheSymplecticSchemesKeepTheirEnergy) {
  for (Integrator integrator : {Integrator::symplecticEuler, Integrator::verlet}) {
    // omega dt = 0.5. Energy is measured with a velocity half a step off the position, so it
    // oscillates (by up to 1 / (1 - omega dt / 2) here) but never drifts: 200 or 2000 steps, same.
    const OscillatorRun brief = runOscillator(integrator, 100.0, 0.05, 200);
    const OscillatorRun run = runOscillator(integrator, 100.0, 0.05, 2000);
    EXPECT_EQ(run.verdict, Stability::stable) << sim::name(integrator);
    EXPECT_LE(run.maxEnergyRatio, 1.0 / (1.0 - 0.25) + 1e-9);
    EXPECT_NEAR(run.maxEnergyRatio, brief.maxEnergyRatio, 1e-3);
  }
  // RK4 dissipates a little below its bound: at omega dt = 2.5 it visibly damps.
  EXPECT_EQ(runOscillator(Integrator::rk4, 100.0, 0.25, 400).verdict, Stability::damped);
}

TEST(Cantilever, AFineStripWithLinesSettlesWithinTwoPercentAtSixteenSweeps) {
  // 3.125 mm, 16 sweeps (of 40 substeps: sim::substepsFor), the stretch a line at a time: the
  // stencils swept one by one left it 28 % soft (a moment carried along 20 cells by Gauss-Seidel);
  // solved at once as a block (bending.hpp) it settles on the elastica's answer.
  CantileverSpec spec;
  spec.fabric = sim::Fabric{0.324, 6.4e-5, 5.0e4, 150.0};
  spec.spacing = 0.003125;
  spec.substeps = 10;
  spec.iterations = 16;
  spec.lines = true;
  const CantileverResult r = cantilever(spec);
  ASSERT_FALSE(r.diverged);
  EXPECT_LT(r.tipMotion, 1e-5) << "still moving";
  EXPECT_NEAR(r.bendingLength / r.expected, 1.0, 0.02);
}

TEST(Cusick, NodesAreTheRisesOfTheEdgeThroughItsMean) {
  // r = 1 + 0.2 cos(6 theta): six folds, whatever the phase; a circle has none.
  for (double phase : {0.0, 0.3, 1.0}) {
    std::vector<double> r(360);
    for (int k = 0; k < 360; ++k) r[k] = 1.0 + 0.2 * std::cos(6.0 * (k * std::numbers::pi / 180.0 + phase));
    EXPECT_EQ(nodeCount(r, 5), 6) << phase;
  }
  EXPECT_EQ(nodeCount(std::vector<double>(360, 1.0), 5), 0);
}

TEST(Cusick, ASilkDiscHangsLowerThanADenimOneAndBothComeToRest) {
  // 12.5 mm, 10 x 4: the lab's coarsest run. DC between the limits (0 hanging straight down, 1 flat),
  // silk's well below denim's (bending lengths 16.5 and 27.2 mm), folds on both.
  CusickSpec spec;
  spec.spacing = 0.0125;
  spec.fabric = sim::Fabric{0.045, 2.0e-6, 5.0e3, 30.0};
  const CusickResult silk = cusick(spec);
  spec.fabric = sim::Fabric{0.324, 6.4e-5, 5.0e4, 150.0};
  const CusickResult denim = cusick(spec);
  for (const CusickResult& r : {silk, denim}) {
    ASSERT_FALSE(r.diverged);
    EXPECT_GT(r.coefficient, 0.2);
    EXPECT_LT(r.coefficient, 0.95);
    EXPECT_GE(r.nodes, 3);
    EXPECT_LT(r.motion, 1e-5);  // 0.01 mm a frame
  }
  EXPECT_LT(silk.coefficient + 0.15, denim.coefficient);
}

TEST(Cusick, ADiscStillMovingWhenFirstLookedAtIsReadWhereItComesToRest) {
  // Looked at after 0.5 s the silk disc is still falling; the lab waits for it to stop (no particle
  // moving 0.01 mm in a frame) and reads the drape there: the drape a 5 s wait reads.
  CusickSpec spec;
  spec.spacing = 0.0125;
  spec.fabric = sim::Fabric{0.045, 2.0e-6, 5.0e3, 30.0};
  const CusickResult patient = cusick(spec);
  spec.settle = 0.5;
  const CusickResult early = cusick(spec);
  ASSERT_FALSE(early.diverged);
  EXPECT_GT(early.motion, 1e-4);
  EXPECT_GT(early.restedAt, 0.5);
  EXPECT_NEAR(early.coefficient, patient.coefficient, 0.01);
  EXPECT_EQ(patient.restedAt, 5.0);
}

}  // namespace
}  // namespace drape::analysis

#include "drape/analysis/convergence.hpp"

namespace drape::analysis {
namespace {

struct OrderCase {
  Integrator integrator;
  double order;
};

void PrintTo(const OrderCase& c, std::ostream* os) { *os << sim::name(c.integrator); }

class Order : public ::testing::TestWithParam<OrderCase> {};

TEST_P(Order, ObservedConvergenceOrderIsTheIntegratorsOrder) {
  // Explicit and symplectic Euler 1, Verlet and midpoint 2, RK4 4.
  const Convergence c = oscillatorConvergence(GetParam().integrator, 0.01, 5);
  EXPECT_NEAR(c.order, GetParam().order, 0.25) << sim::name(GetParam().integrator);
}

INSTANTIATE_TEST_SUITE_P(Integrators, Order,
                         ::testing::Values(OrderCase{Integrator::explicitEuler, 1},
                                           OrderCase{Integrator::symplecticEuler, 1}, OrderCase{Integrator::verlet, 2},
                                           OrderCase{Integrator::midpoint, 2}, OrderCase{Integrator::rk4, 4}));

}  // namespace
}  // namespace drape::analysis

#include "drape/analysis/analytic.hpp"

namespace drape::analysis {
namespace {

TEST(Analytic, PendulumQuarterPeriodConvergesToTheEllipticIntegral) {
  // First order in the substep (the constraint projection is a first-order step): 4x the substeps,
  // about a quarter of the error, and under a millisecond at 8.
  const double coarse = pendulumError(1), fine = pendulumError(4), finest = pendulumError(8);
  EXPECT_LT(fine, 0.5 * coarse);
  EXPECT_LT(finest, 1e-3);
}

TEST(Analytic, FreeFallIsExact) { EXPECT_LT(freeFallError(4), 1e-9); }

TEST(Analytic, AHangingChainSettlesIntoTheCatenaryOfItsLengthAndSpan) {
  // The sag is 0.36 m; converged (400 sweeps), the 60-link chain follows the curve within 3 mm and
  // is not stretched to get there. Fewer sweeps leave it stretched and sagging lower.
  double strain = 0.0;
  EXPECT_LT(catenaryError(60, 400, &strain), 0.003);
  EXPECT_LT(strain, 0.001);
  EXPECT_GT(catenaryError(60, 20), 0.005);
}

TEST(Analytic, SolvedALineAtATimeTheChainReachesTheCatenaryInTwoSweeps) {
  // The whole chain is one line: two sweeps a substep do what 400 Gauss-Seidel sweeps do.
  double strain = 1.0;
  EXPECT_LT(catenaryError(60, 2, &strain, true), 0.003);
  EXPECT_LT(strain, 0.001);
  EXPECT_GT(catenaryError(60, 2, nullptr, false), 0.005);
}

}  // namespace
}  // namespace drape::analysis

namespace drape::analysis {
namespace {

TEST(Stability, ThePositionModelNeverDivergesOverStiffnessAndStep) {
  for (PositionSystem system : {PositionSystem::chain, PositionSystem::sheet}) {
    for (double stiffness : {0.01, 1.0}) {
      for (double dt : {0.001, 0.1}) {
        EXPECT_NE(runPositionModel(system, stiffness, dt, 200).verdict, Stability::diverged)
            << name(system) << " k=" << stiffness << " dt=" << dt;
      }
    }
  }
}

// The force model's springs on the chain and the sheet bound the step as linear theory says: for
// the chain, at 2 / omega_max with omega_max = 2 sqrt(k / m) (within the oscillator's 0.8-1.0 and a
// grid step); for the sheet, no earlier than the Gershgorin bound allows, and not far past it.
TEST(Stability, TheForceModelsSpringsBoundTheStepOnAChainAndASheet) {
  for (sim::Integrator integrator : {sim::Integrator::symplecticEuler, sim::Integrator::rk4}) {
    const double bound = *theoreticalStableOmegaDt(integrator);
    const double k = 1000.0;
    const auto chain = largestStableDt(PositionSystem::chain, integrator, k, 1e-4, 0.1, 1.1, 400);
    ASSERT_TRUE(chain);
    EXPECT_GT(*chain, 0.75 * bound / highestOmegaBound(PositionSystem::chain, k)) << sim::name(integrator);
    EXPECT_LT(*chain, 1.1 * bound / highestOmegaBound(PositionSystem::chain, k)) << sim::name(integrator);
    const auto sheet = largestStableDt(PositionSystem::sheet, integrator, k, 1e-4, 0.1, 1.1, 400);
    ASSERT_TRUE(sheet);
    EXPECT_GT(*sheet, 0.95 * bound / highestOmegaBound(PositionSystem::sheet, k)) << sim::name(integrator);
    EXPECT_LT(*sheet, 2.0 * bound / highestOmegaBound(PositionSystem::sheet, k)) << sim::name(integrator);
  }
  // Explicit Euler has no stable step: a step well inside the others' bound still blows up.
  EXPECT_EQ(runForceModel(PositionSystem::chain, sim::Integrator::explicitEuler, 1000.0, 0.004, 400).verdict,
            Stability::diverged);
}

constexpr double kDegree = std::numbers::pi / 180.0;

TEST(Elastica, GivesPeircesAngleAtTwiceTheBendingLengthAndTheBeamsDeflectionWhenSlight) {
  // ASTM D1388 reads the bending length as half the overhang whose chord droops 41.5 degrees.
  EXPECT_NEAR(elasticaChordAngle(2.0), 41.5 * kDegree, 0.05 * kDegree);
  // Slight: Euler-Bernoulli's tip deflection q L^4 / (8 B), lambda^3 / 8 of the length.
  EXPECT_NEAR(std::tan(elasticaChordAngle(0.3)), 0.3 * 0.3 * 0.3 / 8.0, 1e-5);
  // Inverted; and Peirce's formula beside it, whose c at 41.5 degrees is 0.509 L, 2 % over ASTM's L / 2.
  EXPECT_NEAR(elasticaBendingLength(0.06, elasticaChordAngle(0.06 / 0.025)), 0.025, 1e-6);
  EXPECT_NEAR(peirceBendingLength(0.05, 41.5 * kDegree), 0.05 * 0.5093, 1e-5);
  EXPECT_EQ(elasticaBendingLength(0.05, 89.0 * kDegree), 0.0);  // beyond what the shooting trusts
}

TEST(Cantilever, ADenimStripDroopsAsTheHeavyElasticaDoesWithinFivePercent) {
  // Denim (0.324 kg/m^2, 6.4e-5 N m): c = 2.72 cm. A 25 mm strip of about 5 cm overhang at two
  // spacings, settled; the bending length read from its chord through the exact elastica.
  CantileverSpec spec;
  spec.fabric = sim::Fabric{0.324, 6.4e-5, 5.0e4, 150.0};
  spec.substeps = 40;
  spec.iterations = 16;
  for (double spacing : {0.0125, 0.00625}) {
    spec.spacing = spacing;
    const CantileverResult r = cantilever(spec);
    ASSERT_FALSE(r.diverged);
    EXPECT_NEAR(r.expected, 0.02721, 1e-4);
    EXPECT_LT(r.tipMotion, 1e-5) << "still moving";
    EXPECT_NEAR(r.bendingLength / r.expected, 1.0, 0.05) << spacing;
    EXPECT_GT(r.chordAngle, 35.0 * kDegree);  // a real droop, not a stiff strip
  }
}

TEST(Cantilever, EveryPresetAtEverySpacingIsWithinFivePercentAtTwoSweepsWithLines) {
  // Issue 24's target at its fewest sweeps: 12.5, 6.25 and 3.125 mm, 2 sweeps with lines, the
  // substeps following the spacing (10, 20, 40: solver.fabricSubstepSpeed). At 10 substeps
  // throughout, the 3.125 mm strips sat 4 to 12 % soft (the sweeps' error is first order in the
  // substep and grows as the cells shrink; docs/fabric.md).
  for (const scene::FabricPreset& preset : scene::fabricPresets()) {
    const sim::Fabric& fabric = preset.fabric;
    for (double spacing : {0.0125, 0.00625, 0.003125}) {
      CantileverSpec spec;
      spec.fabric = fabric;
      spec.spacing = spacing;
      spec.overhang = 2.0 * bendingLength(fabric);
      spec.substeps = 10;
      spec.iterations = 2;
      spec.lines = true;
      const CantileverResult r = cantilever(spec);
      ASSERT_FALSE(r.diverged);
      EXPECT_EQ(r.substeps, static_cast<int>(std::lround(10 * 0.0125 / spacing)));
      EXPECT_LT(r.tipMotion, 1e-5) << "still moving";
      EXPECT_NEAR(r.bendingLength / r.expected, 1.0, 0.05) << preset.name << " " << spacing;
      EXPECT_GT(r.chordAngle, 30.0 * kDegree);  // a real droop, not a stiff strip
    }
  }
}

// Denim drawn as an outline, overhanging twice its bending length, with lines at `substeps` x 16.
CantileverSpec drawnDenim(int substeps) {
  CantileverSpec spec;
  spec.fabric = sim::Fabric{0.324, 6.4e-5, 5.0e4, 150.0};
  spec.overhang = 2.0 * bendingLength(spec.fabric);
  spec.substeps = substeps;
  spec.iterations = 16;
  spec.lines = true;
  spec.drawn = true;
  return spec;
}

TEST(Cantilever, ADrawnStripAlongTheLatticeIsWithinTwoPerCentOfTheElasticaAtEverySpacing) {
  // Denim drawn as an outline (analysis::CantileverSpec::drawn), along the fill's lattice, its tip
  // cutting the cells, at 10 x 16 with lines: read as the lattice strip is (from half a spacing
  // behind the pinned particles' front), it is the lattice strip, and as close to the elastica.
  // Read from the front itself it sat 17, 8 and 6 % soft. (Drawn at an angle to the lattice it is
  // not yet at this setting: docs/fabric.md, "Drawn strips".)
  CantileverSpec spec = drawnDenim(10);
  for (double spacing : {0.0125, 0.00625, 0.003125}) {
    spec.spacing = spacing;
    const CantileverResult r = cantilever(spec);
    ASSERT_FALSE(r.diverged);
    EXPECT_LT(r.tipMotion, 1e-5) << "still moving";
    EXPECT_NEAR(r.bendingLength / r.expected, 1.0, 0.02) << spacing;
    EXPECT_GT(r.chordAngle, 35.0 * kDegree);  // a real droop, not a stiff strip
  }
}

TEST(Cantilever, ADrawnStripAtAnAngleToItsLatticeIsWithinThreePercentOnceItsStretchHasConverged) {
  // Denim drawn at 15, 30 and 45 degrees to the fill's lattice, 6.25 mm, with lines at 100 x 16
  // (its links within 0.3 %): the bend stencils of the clipped cells along its border, the
  // cotangent Laplacian, bend it as the elastica does, within 2 % (3 % asked; docs/fabric.md, "Drawn
  // strips"). With a particle's two most nearly opposite pairs of links as its lines, as before, it
  // sat 7.4 and 6.5 % soft at 15 and 30 degrees and 5.2 % stiff at 45.
  CantileverSpec spec = drawnDenim(100);
  spec.spacing = 0.00625;
  for (double degrees : {15.0, 30.0, 45.0}) {
    spec.angle = degrees * kDegree;
    const CantileverResult r = cantilever(spec);
    ASSERT_FALSE(r.diverged);
    EXPECT_LT(r.tipMotion, 1e-5) << "still moving";
    EXPECT_LT(r.maxStrain, 0.005) << degrees;
    EXPECT_NEAR(r.bendingLength / r.expected, 1.0, 0.03) << degrees;
    EXPECT_GT(r.chordAngle, 35.0 * kDegree);
  }
}

}  // namespace
}  // namespace drape::analysis
