// Observed order of convergence of the force model's integrators on the harmonic oscillator,
// against its exact solution.
#pragma once

#include <vector>

#include "drape/sim/settings.hpp"

namespace drape::analysis {

struct ConvergencePoint {
  double dt;     // s
  double error;  // m, |y(T) - y_exact(T)| at T = 1 s
};

struct Convergence {
  std::vector<ConvergencePoint> points;
  double order;  // least-squares slope of log(error) against log(dt)
};

// A 1 kg ball on a 100 N/m spring below a pin, released at rest length under gravity:
// y(t) = y0 - (g / omega^2)(1 - cos(omega t)), omega = 10 rad/s; errors at T = 1 s for
// dt = dtLargest / 2^k, k = 0 .. halvings - 1.
Convergence oscillatorConvergence(sim::Integrator integrator, double dtLargest, int halvings);

}  // namespace drape::analysis
