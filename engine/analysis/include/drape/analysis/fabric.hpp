// The virtual textile lab: the engine's fabrics (sim::Fabric) in the tests textile labs run, against
// closed-form answers.
#pragma once

#include <vector>

#include "drape/sim/settings.hpp"

namespace drape::analysis {

// The heavy elastica: a strip clamped level at one end, bent by its own weight, B theta'' = -q (L - s)
// cos theta, theta(0) = 0, theta'(L) = 0 (theta below the horizontal, s along the strip). In units of
// the bending length c = (B / q)^(1/3) it depends on L / c alone. Returns the chord's angle below the
// horizontal from the clamp to the tip (radians), for overhang / c = `lambda` in 0..4.5 (80 degrees).
double elasticaChordAngle(double lambda);
// The bending length c (m) for which a strip overhanging `overhang` (m) has that chord angle (the
// elastica inverted), or 0 outside the angles lambda 0.05..4.5 gives (0.007..80 degrees).
double elasticaBendingLength(double overhang, double chordAngle);
// Peirce's (1930) approximation of the same: c = L (cos(theta / 2) / (8 tan theta))^(1/3). ASTM D1388
// reads the strip at 41.5 degrees and takes c = L / 2 (the formula gives 0.509 L there).
double peirceBendingLength(double overhang, double chordAngle);
// (B / (rho g))^(1/3), m: what a fabric's bending length is.
double bendingLength(const sim::Fabric& fabric, double gravity = 9.81);

struct CantileverSpec {
  sim::Fabric fabric;
  double spacing = 0.00625;  // m, the lattice's
  double overhang = 0.05;    // m, rounded to a whole number of spacings and a half
  double width = 0.025;      // m, ASTM D1388's strip, rounded likewise
  int substeps = 10;
  int iterations = 4;
  // m/s: the world's solver.fabricSubstepSpeed (more substeps for a fine strip; 0: `substeps` as given)
  double substepSpeed = sim::SolverSettings{}.fabricSubstepSpeed;
  bool lines = false;    // the stretch links a line at a time (sim::SolverSettings::lines), not one by one
  double settle = 5.0;   // s of simulated time, damped, before it is read
  double damping = 4.0;  // 1/s (global: it slows the strip, it does not change where it comes to rest)
  // A drawn strip (sim::OutlineSpec) instead of a lattice: a rectangle `angle` (radians) off the
  // fill's lattice lines, its overhang and width as given (not rounded), its bend stencils those an
  // outline cloth gets (a clipped border, lines at `angle` to the strip).
  bool drawn = false;
  double angle = 0.0;
};

struct CantileverResult {
  double overhang = 0.0;       // m, as built
  double chordAngle = 0.0;     // radians below the horizontal, clamp to tip (the rows' mean)
  double bendingLength = 0.0;  // m: the elastica's c for that angle
  double peirce = 0.0;         // m: Peirce's formula's
  double expected = 0.0;       // m: (B / (rho g))^(1/3)
  double expectedAngle = 0.0;  // radians: the elastica's angle for the fabric's own c
  double tipMotion = 0.0;      // m, how far the tip moved in the last frame (is it at rest?)
  double maxStrain = 0.0;      // the longest stretch link's strain at the end
  int substeps = 0;            // a step's substeps as run (sim::World::substeps)
  double seconds = 0.0;        // wall-clock time the run took
  bool diverged = false;
};

// The strip, lying along +x with its first two columns pinned (the platform, whose edge is halfway
// between them), left to settle under gravity. The overhang is from that edge to the tip. Drawn:
// three spacings of the strip lie on the platform, every particle not beyond its edge pinned, and
// the overhang and the chord (to the middle of the tip's two corners) are read from half a spacing
// behind the edge, as the lattice strip's are from half a spacing behind its last pinned column.
CantileverResult cantilever(const CantileverSpec& spec);

// The Cusick drape test (BS 5058, ISO 9073-9): a disc of fabric clamped between two smaller discs
// and left to hang. Its drape coefficient is the share of the ring around the support that its
// shadow still covers, DC = (A_shadow - A_support) / (A_disc - A_support): 1 for a stiff sheet
// that stays flat, near 0 for one that hangs straight down. Nodes are its folds: how many times the
// shadow's edge, going round, rises through its mean radius.
struct CusickSpec {
  sim::Fabric fabric;
  double spacing = 0.00625;  // m, the lattice's
  double diameter = 0.30;    // m, the specimen
  double support = 0.18;     // m, the clamping discs
  int substeps = 10;
  int iterations = 4;
  double substepSpeed = sim::SolverSettings{}.fabricSubstepSpeed;  // m/s, as CantileverSpec's
  bool lines = false;
  double settle = 5.0;    // s: the time to be at rest by
  double damping = 4.0;   // 1/s
  double rest = 1e-5;     // m: at rest when no particle moves more than this in a frame
  double longest = 20.0;  // s: how long it may hang, past settle, to come to rest
};

struct CusickResult {
  double coefficient = 0.0;  // DC, 0..1, read where it came to rest (or at longest)
  int nodes = 0;
  double shadowArea = 0.0;  // m^2
  double motion = 0.0;      // m, the most a particle moved in the frame that ends at settle
  // s: the end of the first frame, from settle on, that moved no particle more than rest; -1 if none by
  // settle + longest
  double restedAt = -1.0;
  int particles = 0;
  int substeps = 0;  // a step's substeps as run (sim::World::substeps)
  double seconds = 0.0;
  bool diverged = false;
};

// The disc drawn as an outline (sim::OutlineSpec, a polygon of 180 corners) at 0.5 m, its particles
// within the support's radius pinned where they lie (the clamp), settled under gravity; the shadow
// is the mesh's triangles projected onto the table, counted on a grid of 0.5 mm cells, once the
// disc is at rest: a fine disc can still be folding over into another shape at `settle` (a slow
// buckle), and the coefficient is read, as the standard reads it, from the drape it comes to.
CusickResult cusick(const CusickSpec& spec);

// Rotation kept: a square of fabric in free space (no gravity, drag or damping), spun about an
// axis `tilt` off its normal, and how much of its angular momentum it keeps.
struct SpinSpec {
  sim::Fabric fabric;
  double side = 0.30;       // m
  double spacing = 0.0125;  // m, the lattice's
  double turns = 1.0;       // a second
  double tilt = 0.0;        // radians between the spin axis and the sheet's normal
  int substeps = 10;
  int iterations = 4;
  bool lines = false;
  double seconds = 5.0;  // s
};

struct SpinResult {
  double kept = 0.0;     // L(end) . L(start) / |L(start)|^2 (1: all of it)
  double drift = 0.0;    // the most |L(t) - L(start)| / |L(start)| over each second's end
  double strain = 0.0;   // the longest stretch link's strain at the end
  double seconds = 0.0;  // wall-clock
  bool diverged = false;
};

SpinResult spin(const SpinSpec& spec);

// Of a shadow's edge radius sampled at equal angles going round: how many times it rises through
// its mean (after a moving average over `smoothing` samples either side).
int nodeCount(const std::vector<double>& radius, int smoothing);

}  // namespace drape::analysis
