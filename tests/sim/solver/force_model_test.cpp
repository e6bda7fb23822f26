// The force-based model: the seed's spring-damper force and the five integrators, checked against
// the linear theory of the harmonic oscillator.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>

#include "drape/sim/metrics.hpp"
#include "drape/sim/world.hpp"
#include "solver/force_model.hpp"
#include "world_builder.hpp"

namespace drape::sim {
namespace {

TEST(SpringForce, EqualsTheSeedsFormulaWorkedByHand) {
  // x1 = 0, x2 = (3, 4, 0): dx = x1 - x2 = (-3, -4, 0), |dx| = 5, r = 4, ks = 10, kd = 2,
  // v1 = (1, 0, 0), v2 = 0: (dv . dx) / |dx| = -3 / 5.
  // f1 = -[10 (5 - 4) + 2 (-0.6)] (-3, -4, 0) / 5 = -8.8 (-0.6, -0.8, 0) = (5.28, 7.04, 0).
  const Vec3 f1 = force::springForce({0, 0, 0}, {3, 4, 0}, {1, 0, 0}, {0, 0, 0}, 4.0, 10.0, 2.0);
  EXPECT_NEAR(f1.x, 5.28, 1e-5);
  EXPECT_NEAR(f1.y, 7.04, 1e-5);
  EXPECT_NEAR(f1.z, 0.0, 1e-6);
  // f2 = -f1: swapping the particles flips the force.
  const Vec3 f2 = force::springForce({3, 4, 0}, {0, 0, 0}, {0, 0, 0}, {1, 0, 0}, 4.0, 10.0, 2.0);
  EXPECT_NEAR(f2.x, -f1.x, 1e-5);
  EXPECT_NEAR(f2.y, -f1.y, 1e-5);
  // At rest length and no relative velocity there is no force; coincident particles give none.
  EXPECT_EQ(force::springForce({0, 0, 0}, {0, 4, 0}, {}, {}, 4.0, 10.0, 2.0), Vec3(0.0));
  EXPECT_EQ(force::springForce({1, 1, 1}, {1, 1, 1}, {}, {}, 4.0, 10.0, 2.0), Vec3(0.0));
}

TEST(SpringForce, TheWorldAppliesItToTheParticles) {
  // The top particle pinned 0.5 m above its rest place stretches the 1 m spring by 0.5 m:
  // one explicit Euler step from rest gives the free 1 kg particle v = ks 0.5 / m * h upwards.
  WorldSettings settings = test::verticalSpring(Model::force, Integrator::explicitEuler, 0.01, 10.0, 1.0);
  settings.gravity = Vec3{0.0};
  settings.cloths[0].pins[0].position = Vec3{0.0, 2.5, 0.0};
  World world(settings);
  ASSERT_EQ(world.step(), StepStatus::ok);
  EXPECT_NEAR(world.velocity(0, 1).y, 10.0 * 0.5 / 1.0 * 0.01, 1e-6);
}

// One step of each integrator multiplies the oscillator's complex amplitude by lambda(i omega h).
std::complex<double> amplification(Integrator integrator, double omegaH) {
  const std::complex<double> z{0.0, omegaH};
  switch (integrator) {
    case Integrator::explicitEuler: return 1.0 + z;
    case Integrator::midpoint: return 1.0 + z + z * z / 2.0;
    case Integrator::rk4: return 1.0 + z + z * z / 2.0 + z * z * z / 6.0 + z * z * z * z / 24.0;
    case Integrator::symplecticEuler:
    case Integrator::verlet:
      // x_{n+1} - 2 x_n + x_{n-1} = -(omega h)^2 x_n: |lambda| = 1, cos(theta) = 1 - (omega h)^2 / 2.
      return std::polar(1.0, std::acos(1.0 - omegaH * omegaH / 2.0));
  }
  return 0.0;
}

struct Oscillation {
  double period;          // s, from crossings of the equilibrium
  double firstAmplitude;  // m, largest |displacement| in the first period
  double lastAmplitude;   // m, in the last period
};

// A 1 kg ball on a 100 N/m spring hanging from a pin (omega = 10 rad/s), released at the spring's
// rest length: it oscillates about y_eq = y_rest - g / omega^2 with amplitude g / omega^2.
Oscillation oscillate(Integrator integrator, double h, int periods) {
  const double omega = 10.0;
  World world(test::verticalSpring(Model::force, integrator, h, 100.0, 1.0));
  const double equilibrium = 1.0 - 9.81 / (omega * omega);
  const double period = 2.0 * std::numbers::pi / omega;
  // Released at an extreme: crossings at T/4, 3T/4, ...; a quarter more so `periods` are spanned.
  const int steps = static_cast<int>(std::ceil((periods + 0.25) * period / h)) + 2;
  std::vector<double> crossings;
  double previous = world.cloths()[0].state.position[1].y - equilibrium, first = 0.0, last = 0.0;
  for (int step = 1; step <= steps; ++step) {
    EXPECT_EQ(world.step(), StepStatus::ok);
    const double displacement = world.cloths()[0].state.position[1].y - equilibrium;
    if ((previous < 0.0) != (displacement < 0.0)) {
      crossings.push_back(world.time() - h * displacement / (displacement - previous));
    }
    if (world.time() <= period) first = std::max(first, std::abs(displacement));
    if (world.time() >= steps * h - period) last = std::max(last, std::abs(displacement));
    previous = displacement;
  }
  EXPECT_GE(crossings.size(), 3u);
  const double measured = 2.0 * (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
  return {measured, first, last};
}

struct IntegratorCase {
  Integrator integrator;
  int periods;
};

void PrintTo(const IntegratorCase& c, std::ostream* os) { *os << name(c.integrator); }

class Oscillator : public ::testing::TestWithParam<IntegratorCase> {};

TEST_P(Oscillator, PeriodIsWhatTheIntegratorsAmplificationFactorPredicts) {
  // At omega h = 0.5 every integrator's numerical period differs from 2 pi / omega in its own way
  // (explicit Euler ~8 % long, Verlet ~1 % short, midpoint ~4 % short, RK4 ~0.01 %); the measured
  // period must be the predicted one, which tells the integrators apart.
  const double h = 0.05, omega = 10.0;
  const auto [integrator, periods] = GetParam();
  const double theta = std::arg(amplification(integrator, omega * h));
  const double predicted = 2.0 * std::numbers::pi * h / theta;
  const Oscillation result = oscillate(integrator, h, periods);
  EXPECT_NEAR(result.period, predicted, 2e-3 * predicted) << name(integrator);
}

INSTANTIATE_TEST_SUITE_P(Integrators, Oscillator,
                         ::testing::Values(IntegratorCase{Integrator::explicitEuler, 1},
                                           IntegratorCase{Integrator::symplecticEuler, 10},
                                           IntegratorCase{Integrator::verlet, 10},
                                           IntegratorCase{Integrator::midpoint, 10},
                                           IntegratorCase{Integrator::rk4, 10}),
                         [](const auto& testInfo) {
                           std::string text(name(testInfo.param.integrator));
                           std::erase(text, '-');
                           return text;
                         });

TEST(Oscillator, ExplicitEulerGainsEnergySymplecticOnesDoNot) {
  const double amplitude = 9.81 / 100.0;
  // |1 + i omega h| > 1: explicit Euler's amplitude grows every step, whatever the step.
  const Oscillation euler = oscillate(Integrator::explicitEuler, 0.02, 2);
  EXPECT_GT(euler.lastAmplitude, 1.5 * euler.firstAmplitude);
  // Symplectic Euler and Verlet keep it bounded over many periods (no drift).
  for (Integrator integrator : {Integrator::symplecticEuler, Integrator::verlet}) {
    const Oscillation result = oscillate(integrator, 0.02, 50);
    EXPECT_NEAR(result.firstAmplitude, amplitude, 0.05 * amplitude) << name(integrator);
    EXPECT_NEAR(result.lastAmplitude, amplitude, 0.05 * amplitude) << name(integrator);
  }
}

// For x' = v, v' = -omega^2 x, a Runge-Kutta step multiplies the complex amplitude x + i v / omega by
// exactly lambda(i omega h): after n steps its modulus has grown by |lambda|^n, to rounding.
TEST(Oscillator, RungeKuttaAmplitudeChangesByExactlyLambdaToTheN) {
  const double omega = 10.0, h = 0.05, equilibrium = 1.0 - 9.81 / (omega * omega);
  for (Integrator integrator : {Integrator::explicitEuler, Integrator::midpoint, Integrator::rk4}) {
    World world(test::verticalSpring(Model::force, integrator, h, 100.0f, 1.0f));
    const auto amplitude = [&] {
      const double d = world.cloths()[0].state.position[1].y - equilibrium;
      const double v = world.velocity(0, 1).y;
      return std::hypot(d, v / omega);
    };
    const double start = amplitude();
    const int steps = integrator == Integrator::explicitEuler ? 20 : 200;
    world.run(steps);
    const double expected = std::pow(std::abs(amplification(integrator, omega * h)), steps);
    EXPECT_NEAR(amplitude() / start, expected, 1e-9 * expected) << name(integrator);
  }
}

TEST(Oscillator, Rk4ConservesEnergyOfAnUndampedSpring) {
  World world(test::verticalSpring(Model::force, Integrator::rk4, 0.005, 100.0, 1.0));
  const double start = energy(world).total();
  world.run(2000);
  EXPECT_NEAR(energy(world).total(), start, 1e-4 * std::abs(start) + 1e-4);
}

}  // namespace
}  // namespace drape::sim
