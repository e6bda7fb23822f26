// The engine against closed-form answers: cases with an exact solution, for the accuracy report
// and the tests.
#pragma once

namespace drape::analysis {

// Position model, one free particle for 2 s at dt = 1/60 s: the largest |y - (y0 - g t^2 / 2)|.
double freeFallError(int substeps);

// Position model: a chain of `links` links, 1.2 m long, hung between two pins 1 m apart, settled
// (10 s, drag 2/s): the largest vertical distance of a particle from the catenary of that length
// and span, y = a cosh(x / a) + c with 2 a sinh(s / 2a) = L (m); `strain` gets the worst edge's.
// With `lines`, the chain is solved a line at a time (sim::SolverSettings::lines).
double catenaryError(int links, int iterations, double* strain = nullptr, bool lines = false);

// Position model: a rigid pendulum of length 1 m (one link, a 1 kg bob) released horizontally; the
// error of the time it takes to swing to the bottom (s) against the exact nonlinear quarter period
// sqrt(L / g) K(sin 45 deg) = 0.5920 s (K: the complete elliptic integral of the first kind).
double pendulumError(int substeps);

}  // namespace drape::analysis
