// Numerical stability of the force model's integrators, measured on the undamped harmonic
// oscillator and compared with linear stability theory.
//
// The test system: a 1 kg particle hanging from a pin by one spring of stiffness k (N/m), no
// gravity, no damping, started 0.1 m stretched: omega = sqrt(k / m). Each run lasts `steps`
// steps and is classified (the factors are the documented thresholds):
//   diverged  the guard tripped (non-finite or runaway), or the energy grew above 10 x its start;
//   damped    the energy fell below 0.5 x its start (numerical dissipation);
//   stable    neither.
// Linear theory for the undamped oscillator (z = i omega dt, |lambda(z)| <= 1 required):
//   explicit Euler  |1 + z| > 1 for every dt: never stable;
//   symplectic Euler and Verlet  stable for dt < 2 / omega;
//   midpoint (RK2)  |1 + z + z^2/2|^2 = 1 + (omega dt)^4 / 4 > 1: slowly unstable for every dt;
//   RK4  stable for omega dt < 2 sqrt(2) ~ 2.83 (and slightly dissipative below).
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "drape/sim/settings.hpp"

namespace drape::analysis {

enum class Stability : std::uint8_t { stable, damped, diverged };
std::string_view name(Stability stability);

inline constexpr double kDivergedEnergyFactor = 10.0;
inline constexpr double kDampedEnergyFactor = 0.5;

struct OscillatorRun {
  Stability verdict = Stability::stable;
  double maxEnergyRatio = 1.0;  // largest E / E0 seen
  double endEnergyRatio = 1.0;  // E / E0 at the end
};

OscillatorRun runOscillator(sim::Integrator integrator, double stiffness, double dt, std::int64_t steps);

// The position model on a chain (a 1 m, 20-link pendulum released horizontally) or a sheet (a
// 1 m, 16 x 16 sheet held by two corners, falling from flat), at a 0..1 stiffness and a step dt
// (one substep, 10 iterations), for `steps` steps. The energy scale is the potential energy
// released by a 1 m drop, m g (1 m): diverged if the guard trips or the mechanical energy ever
// rises more than 10 scales above its start; damped if the kinetic energy at the end is below
// 1e-3 scales (it has come to rest); stable otherwise.
enum class PositionSystem : std::uint8_t { chain, sheet };
std::string_view name(PositionSystem system);
OscillatorRun runPositionModel(PositionSystem system, double stiffness, double dt, std::int64_t steps);

// The force model on the same chain and sheet: every spring (stretch, shear and, on the sheet, bend)
// of stiffness k (N/m), undamped, under gravity, classified as runPositionModel classifies.
OscillatorRun runForceModel(PositionSystem system, sim::Integrator integrator, double stiffness, double dt,
                            std::int64_t steps);
// A bound on the system's highest angular frequency (Gershgorin on the spring network's stiffness
// matrix): omega_max^2 <= 2 (sum of the spring constants at the busiest particle) / its mass. The
// chain's is exact for a long chain (2 sqrt(k / m)); the sheet's overestimates, so the step it
// predicts is a lower bound.
double highestOmegaBound(PositionSystem system, double stiffness);
// As largestStableDt, for runForceModel.
std::optional<double> largestStableDt(PositionSystem system, sim::Integrator integrator, double stiffness, double dtMin,
                                      double dtMax, double ratio, std::int64_t steps);

// The theoretical bound omega * dt below which the undamped oscillator is stable; none if never.
std::optional<double> theoreticalStableOmegaDt(sim::Integrator integrator);

// The largest dt on the grid dt_i = dtMin * ratio^i (<= dtMax) whose run is not diverged, scanning
// up from the smallest (the first divergence ends the scan); none if even dtMin diverges.
std::optional<double> largestStableDt(sim::Integrator integrator, double stiffness, double dtMin, double dtMax,
                                      double ratio, std::int64_t steps);

}  // namespace drape::analysis
