#include "drape/analysis/fabric.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <memory>
#include <numbers>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>

#include "drape/mesh/outline.hpp"
#include "drape/sim/metrics.hpp"
#include "drape/sim/world.hpp"

namespace drape::analysis {

namespace {

// A drawn cloth's mesh: the outline meshed once, for the engine to constrain.
std::shared_ptr<const sim::LatticeMesh> drawnMesh(const mesh::OutlineSpec& outline) {
  mesh::OutlineMesh shape = mesh::meshOutline(outline);
  return std::make_shared<const sim::LatticeMesh>(sim::LatticeMesh{
      std::move(shape.positions), std::move(shape.triangles), std::move(shape.nodes), outline.spacing});
}

struct Shot {
  double endSlope;  // theta'(lambda)
  double x, y;      // the tip, in units of c
};

// theta'' = -(lambda - s) cos theta from theta(0) = 0, theta'(0) = p, by classical Runge-Kutta; the
// tip by the same steps (x' = cos theta, y' = sin theta).
Shot shoot(double lambda, double p) {
  constexpr int kSteps = 4000;
  const double h = lambda / kSteps;
  double theta = 0.0, slope = p, x = 0.0, y = 0.0;
  const auto accel = [&](double s, double t) { return -(lambda - s) * std::cos(t); };
  for (int i = 0; i < kSteps; ++i) {
    const double s = i * h;
    const double k1t = slope, k1s = accel(s, theta);
    const double k2t = slope + 0.5 * h * k1s, k2s = accel(s + 0.5 * h, theta + 0.5 * h * k1t);
    const double k3t = slope + 0.5 * h * k2s, k3s = accel(s + 0.5 * h, theta + 0.5 * h * k2t);
    const double k4t = slope + h * k3s, k4s = accel(s + h, theta + h * k3t);
    const double t1 = theta, t2 = theta + 0.5 * h * k1t, t3 = theta + 0.5 * h * k2t, t4 = theta + h * k3t;
    x += h / 6.0 * (std::cos(t1) + 2.0 * std::cos(t2) + 2.0 * std::cos(t3) + std::cos(t4));
    y += h / 6.0 * (std::sin(t1) + 2.0 * std::sin(t2) + 2.0 * std::sin(t3) + std::sin(t4));
    theta += h / 6.0 * (k1t + 2.0 * k2t + 2.0 * k3t + k4t);
    slope += h / 6.0 * (k1s + 2.0 * k2s + 2.0 * k3s + k4s);
  }
  return {slope, x, y};
}

}  // namespace

double elasticaChordAngle(double lambda) {
  if (!(lambda > 0.0)) return 0.0;
  // theta'(lambda) = p - integral of (lambda - s) cos theta: below 0 at p = 0, at least 0 at p = lambda^2 / 2.
  double low = 0.0, high = 0.5 * lambda * lambda;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (low + high);
    (shoot(lambda, mid).endSlope < 0.0 ? low : high) = mid;
  }
  const Shot tip = shoot(lambda, 0.5 * (low + high));
  return std::atan2(tip.y, tip.x);
}

double elasticaBendingLength(double overhang, double chordAngle) {
  if (!(overhang > 0.0) || !(chordAngle > 0.0) || !(chordAngle < 0.5 * std::numbers::pi)) return 0.0;
  // The angle grows with lambda = overhang / c: bisect on log lambda.
  // Up to 4.5 (80 degrees): beyond it the shooting loses the solution, and no textile test reads there.
  double low = std::log(0.05), high = std::log(4.5);
  if (elasticaChordAngle(std::exp(high)) < chordAngle) return 0.0;
  for (int i = 0; i < 50; ++i) {
    const double mid = 0.5 * (low + high);
    (elasticaChordAngle(std::exp(mid)) < chordAngle ? low : high) = mid;
  }
  return overhang / std::exp(0.5 * (low + high));
}

double peirceBendingLength(double overhang, double chordAngle) {
  if (!(chordAngle > 0.0)) return 0.0;
  return overhang * std::cbrt(std::cos(0.5 * chordAngle) / (8.0 * std::tan(chordAngle)));
}

double bendingLength(const sim::Fabric& fabric, double gravity) {
  return std::cbrt(fabric.bendingRigidity / (fabric.arealDensity * gravity));
}

namespace {

// A lab run's world: 60 frames a second, the spec's substeps, sweeps, damping and stretch solver.
template <class Spec>
sim::WorldSettings labWorld(const Spec& spec) {
  sim::WorldSettings settings;
  settings.solver.dt = 1.0 / 60.0;
  settings.solver.substeps = spec.substeps;
  settings.solver.fabricSubstepSpeed = spec.substepSpeed;
  settings.solver.iterations = spec.iterations;
  settings.solver.damping = spec.damping;
  settings.solver.stretchSolver = spec.lines ? sim::StretchSolver::lines : sim::StretchSolver::gaussSeidel;
  return settings;
}

// Runs all but the last frame of `seconds` (the caller steps the last one, to see what still
// moves); false if the world diverged on the way.
bool settleToLastFrame(sim::World& world, double seconds) {
  const auto frames = static_cast<std::int64_t>(std::ceil(seconds / world.settings().solver.dt));
  return world.run(frames - 1) == sim::StepStatus::ok;
}

}  // namespace

SpinResult spin(const SpinSpec& spec) {
  const auto started = std::chrono::steady_clock::now();
  sim::WorldSettings settings;
  settings.gravity = sim::Vec3{0.0};
  settings.solver.dt = 1.0 / 60.0;
  settings.solver.substeps = spec.substeps;
  settings.solver.iterations = spec.iterations;
  settings.solver.stretchSolver = spec.lines ? sim::StretchSolver::lines : sim::StretchSolver::gaussSeidel;
  sim::ClothSettings cloth;
  const int cells = std::max(1, static_cast<int>(std::lround(spec.side / spec.spacing)));
  cloth.lattice.columns = cloth.lattice.rows = cells + 1;
  cloth.lattice.width = cloth.lattice.height = spec.spacing * cells;
  cloth.lattice.origin = sim::Vec3{-0.5 * cloth.lattice.width, 1.0, -0.5 * cloth.lattice.height};
  cloth.fabric = spec.fabric;
  cloth.initialSpin = sim::Vec3{std::sin(spec.tilt), std::cos(spec.tilt), 0.0} * (2.0 * std::numbers::pi * spec.turns);
  settings.cloths.push_back(cloth);
  sim::World world(settings);
  SpinResult result;
  // The Verlet history, and so the velocity, starts at the first step.
  if (world.step() != sim::StepStatus::ok) {
    result.diverged = true;
    return result;
  }
  const sim::Vec3 start = sim::momentum(world).angular;
  const double size = glm::length(start);
  const auto perSecond = static_cast<std::int64_t>(std::lround(1.0 / settings.solver.dt));
  for (double t = 0.0; t < spec.seconds - 1e-9; t += 1.0) {
    if (world.run(perSecond) != sim::StepStatus::ok) {
      result.diverged = true;
      return result;
    }
    result.drift = std::max(result.drift, glm::length(sim::momentum(world).angular - start) / size);
  }
  result.kept = glm::dot(sim::momentum(world).angular, start) / (size * size);
  result.strain = sim::structuralStrain(world).max;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

namespace {

// What a cantilever reads once its chord's angle is in: the bending lengths, the worst strain, the time.
void finishCantilever(CantileverResult& result, const sim::World& world,
                      const std::chrono::steady_clock::time_point started) {
  result.bendingLength = elasticaBendingLength(result.overhang, result.chordAngle);
  result.peirce = peirceBendingLength(result.overhang, result.chordAngle);
  result.substeps = world.substeps();
  const sim::Cloth& c = world.cloths()[0];
  for (const sim::DistanceConstraint& link : c.rest.of(sim::ConstraintKind::stretch)) {
    const double length = glm::length(c.state.position[link.b] - c.state.position[link.a]);
    result.maxStrain = std::max(result.maxStrain, length / link.restLength - 1.0);
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
}

// The drawn strip (CantileverSpec::drawn): a rectangle along `along`, from three spacings back over
// the platform to the overhang, its particles on the platform pinned.
CantileverResult drawnCantilever(const CantileverSpec& spec, const std::chrono::steady_clock::time_point started) {
  constexpr double kHeight = 0.5;
  const sim::Vec3 along{std::cos(spec.angle), 0.0, std::sin(spec.angle)}, across{-along.z, 0.0, along.x};
  // The lattice's nodes where the strip's corners are not: its sides cut through the cells.
  const sim::Vec3 origin{0.3 * spec.spacing, kHeight, 0.45 * spec.spacing};
  const auto at = [&](double a, double b) { return origin + along * a + across * b; };
  sim::WorldSettings settings = labWorld(spec);
  sim::ClothSettings cloth;
  mesh::OutlineSpec outline;
  outline.spacing = spec.spacing;
  outline.height = kHeight;
  const double back = -3.0 * spec.spacing;
  for (const auto& [a, b] :
       {std::pair{back, 0.0}, {spec.overhang, 0.0}, {spec.overhang, spec.width}, {back, spec.width}}) {
    const sim::Vec3 corner = at(a, b);
    outline.points.push_back({corner.x, corner.z});
  }
  cloth.mesh = drawnMesh(outline);
  cloth.fabric = spec.fabric;
  settings.cloths.push_back(cloth);
  sim::World world(settings);
  std::vector<sim::Cloth> cloths = world.cloths().copy();
  sim::ParticleState& state = cloths[0].state;
  const sim::Vec3 tipCorners[2] = {at(spec.overhang, 0.0), at(spec.overhang, spec.width)};
  std::size_t tip[2] = {0, 0};
  for (std::size_t i = 0; i < state.position.size(); ++i) {
    const sim::Vec3 x = cloths[0].rest.restPosition(i);
    if (glm::dot(x - origin, along) <= 1e-9) {
      state.pinned[i] = 1;
      state.inverseMass[i] = 0.0;
    }
    for (int k = 0; k < 2; ++k) {
      const sim::Vec3 best = cloths[0].rest.restPosition(tip[k]);
      if (glm::length(x - tipCorners[k]) < glm::length(best - tipCorners[k])) tip[k] = i;
    }
  }
  world.restoreCloths(std::move(cloths));

  CantileverResult result;
  // Read from half a spacing behind the platform's edge (along the lattice, where the front of the
  // pinned particles lies), as the lattice strip is read from half a spacing behind its last pinned
  // column (below): the bend stencils of the front's particles bend the strip within half a spacing
  // of them on either side. (Read from the front itself, the strip along the lattice sat 17, 8 and 6 % soft at
  // 12.5, 6.25 and 3.125 mm, converging only linearly; so read, within 1.2 %.)
  const double behind = 0.5 * spec.spacing;
  result.overhang = spec.overhang + behind;
  result.expected = bendingLength(spec.fabric, 9.81);
  result.expectedAngle = elasticaChordAngle(result.overhang / result.expected);
  const sim::Vec3 root = at(-behind, 0.5 * spec.width);
  const auto tipNow = [&] {
    const sim::Cloth& c = world.cloths()[0];
    return 0.5 * (c.state.position[tip[0]] + c.state.position[tip[1]]);
  };
  if (!settleToLastFrame(world, spec.settle)) {
    result.diverged = true;
    return result;
  }
  const sim::Vec3 before = tipNow();
  result.diverged = world.step() != sim::StepStatus::ok;
  const sim::Vec3 end = tipNow();
  result.tipMotion = glm::length(end - before);
  result.chordAngle = std::atan2(root.y - end.y, glm::dot(end - root, along));
  finishCantilever(result, world, started);
  return result;
}

}  // namespace

CantileverResult cantilever(const CantileverSpec& spec) {
  const auto started = std::chrono::steady_clock::now();
  if (spec.drawn) return drawnCantilever(spec, started);
  const int free = std::max(1, static_cast<int>(std::lround(spec.overhang / spec.spacing - 0.5)));
  const int across = std::max(1, static_cast<int>(std::lround(spec.width / spec.spacing)));
  sim::WorldSettings settings = labWorld(spec);
  sim::ClothSettings cloth;
  cloth.lattice.columns = free + 2;
  cloth.lattice.rows = across + 1;
  cloth.lattice.width = spec.spacing * (free + 1);
  cloth.lattice.height = spec.spacing * across;
  cloth.lattice.origin = sim::Vec3{-0.5 * spec.spacing, 0.5, 0.0};  // the platform's edge at x = 0
  cloth.fabric = spec.fabric;
  for (int row = 0; row <= across; ++row) {
    cloth.pins.push_back({0, row, std::nullopt});
    cloth.pins.push_back({1, row, std::nullopt});
  }
  settings.cloths.push_back(cloth);
  sim::World world(settings);

  CantileverResult result;
  // The platform's edge is halfway between the pinned columns: the bend stencils of column 1 bend
  // the strip within half a spacing of it on either side, half of which lies on the platform, so
  // the free strip starts half a spacing before column 1. (Measured from column 1 instead, the
  // clamp's stencil would count a whole spacing of curvature, and the strip droop 20 % too far at
  // 12.5 mm, converging only linearly.)
  result.overhang = spec.spacing * (free + 0.5);
  result.expected = bendingLength(spec.fabric, 9.81);
  result.expectedAngle = elasticaChordAngle(result.overhang / result.expected);
  const auto tip = [&] {
    const sim::Cloth& c = world.cloths()[0];
    sim::Vec3 root{0.0}, end{0.0};
    for (int row = 0; row <= across; ++row) {
      root += 0.5 * (c.state.position[c.rest.index(0, row)] + c.state.position[c.rest.index(1, row)]);
      end += c.state.position[c.rest.index(free + 1, row)];
    }
    return std::pair{root / static_cast<double>(across + 1), end / static_cast<double>(across + 1)};
  };
  if (!settleToLastFrame(world, spec.settle)) {
    result.diverged = true;
    return result;
  }
  const sim::Vec3 before = tip().second;
  result.diverged = world.step() != sim::StepStatus::ok;
  const auto [root, end] = tip();
  result.tipMotion = glm::length(end - before);
  result.chordAngle = std::atan2(root.y - end.y, end.x - root.x);
  finishCantilever(result, world, started);
  return result;
}

int nodeCount(const std::vector<double>& radius, int smoothing) {
  const int n = static_cast<int>(radius.size());
  if (n < 3) return 0;
  std::vector<double> smooth(radius.size(), 0.0);
  for (int i = 0; i < n; ++i) {
    for (int k = -smoothing; k <= smoothing; ++k) smooth[i] += radius[((i + k) % n + n) % n];
    smooth[i] /= 2 * smoothing + 1;
  }
  double mean = 0.0;
  for (double r : smooth) mean += r;
  mean /= n;
  int rises = 0;
  for (int i = 0; i < n; ++i) {
    if (smooth[i] <= mean && smooth[(i + 1) % n] > mean) ++rises;
  }
  return rises;
}

CusickResult cusick(const CusickSpec& spec) {
  const auto started = std::chrono::steady_clock::now();
  constexpr double kHeight = 0.5;
  constexpr int kCorners = 180;
  sim::WorldSettings settings = labWorld(spec);
  sim::ClothSettings cloth;
  mesh::OutlineSpec outline;
  outline.spacing = spec.spacing;
  outline.height = kHeight;
  const double R = 0.5 * spec.diameter, r = 0.5 * spec.support;
  for (int k = 0; k < kCorners; ++k) {
    const double t = 2.0 * std::numbers::pi * k / kCorners;
    outline.points.push_back({R * std::cos(t), R * std::sin(t)});
  }
  cloth.mesh = drawnMesh(outline);
  cloth.fabric = spec.fabric;
  settings.cloths.push_back(cloth);
  sim::World world(settings);
  // The clamp: every particle within the support's radius, pinned where it lies.
  world.pressFinger(0, sim::Vec3{0.0, kHeight, 0.0}, r + 1e-9);
  world.pinFinger(0);

  CusickResult result;
  result.particles = static_cast<int>(world.cloths()[0].state.position.size());
  result.substeps = world.substeps();
  if (!settleToLastFrame(world, spec.settle)) {
    result.diverged = true;
    return result;
  }
  // The frame that ends at settle, then frames until one moves nothing more than `rest`.
  const double dt = world.settings().solver.dt;
  const auto lastFrames = static_cast<std::int64_t>(std::ceil(spec.longest / dt));
  for (std::int64_t frame = 0; frame <= lastFrames; ++frame) {
    const std::vector<sim::Vec3> before = world.cloths()[0].state.position;
    if (world.step() != sim::StepStatus::ok) {
      result.diverged = true;
      return result;
    }
    double motion = 0.0;
    const std::vector<sim::Vec3>& after = world.cloths()[0].state.position;
    for (std::size_t i = 0; i < before.size(); ++i) motion = std::max(motion, glm::length(after[i] - before[i]));
    if (frame == 0) result.motion = motion;
    if (motion <= spec.rest) {
      result.restedAt = spec.settle + static_cast<double>(frame) * dt;
      break;
    }
  }
  const sim::Cloth& c = world.cloths()[0];
  // The shadow on a grid of 0.5 mm cells: a cell is covered where its centre lies in a triangle
  // seen from above; its radius goes to the angle's bin (1 degree) of the edge profile.
  constexpr double kCell = 0.0005;
  const int half = static_cast<int>(std::ceil((R + 0.01) / kCell));
  const int side = 2 * half;
  std::vector<std::uint8_t> covered(static_cast<std::size_t>(side) * side, 0);
  for (const glm::uvec3& t : c.rest.triangles) {
    const glm::dvec2 a{c.state.position[t[0]].x, c.state.position[t[0]].z};
    const glm::dvec2 b{c.state.position[t[1]].x, c.state.position[t[1]].z};
    const glm::dvec2 d{c.state.position[t[2]].x, c.state.position[t[2]].z};
    const double area = (b.x - a.x) * (d.y - a.y) - (d.x - a.x) * (b.y - a.y);
    if (area == 0.0) continue;
    const auto cell = [&](double v) { return std::clamp(static_cast<int>(std::floor(v / kCell)) + half, 0, side - 1); };
    const int x0 = cell(std::min({a.x, b.x, d.x})), x1 = cell(std::max({a.x, b.x, d.x}));
    const int z0 = cell(std::min({a.y, b.y, d.y})), z1 = cell(std::max({a.y, b.y, d.y}));
    for (int z = z0; z <= z1; ++z) {
      for (int x = x0; x <= x1; ++x) {
        const glm::dvec2 p{(x - half + 0.5) * kCell, (z - half + 0.5) * kCell};
        const auto edge = [](glm::dvec2 u, glm::dvec2 v, glm::dvec2 q) {
          return (v.x - u.x) * (q.y - u.y) - (q.x - u.x) * (v.y - u.y);
        };
        const double e0 = edge(a, b, p), e1 = edge(b, d, p), e2 = edge(d, a, p);
        const bool inside = area > 0.0 ? (e0 >= 0.0 && e1 >= 0.0 && e2 >= 0.0) : (e0 <= 0.0 && e1 <= 0.0 && e2 <= 0.0);
        if (inside) covered[static_cast<std::size_t>(z) * side + x] = 1;
      }
    }
  }
  std::vector<double> profile(360, 0.0);
  std::size_t cells = 0;
  for (int z = 0; z < side; ++z) {
    for (int x = 0; x < side; ++x) {
      if (!covered[static_cast<std::size_t>(z) * side + x]) continue;
      ++cells;
      const double px = (x - half + 0.5) * kCell, pz = (z - half + 0.5) * kCell;
      const double angle = std::atan2(pz, px) + std::numbers::pi;
      const int bin = std::min(359, static_cast<int>(angle / (2.0 * std::numbers::pi) * 360.0));
      profile[static_cast<std::size_t>(bin)] = std::max(profile[static_cast<std::size_t>(bin)], std::hypot(px, pz));
    }
  }
  result.shadowArea = static_cast<double>(cells) * kCell * kCell;
  const double disc = std::numbers::pi * R * R, clamp = std::numbers::pi * r * r;
  result.coefficient = (result.shadowArea - clamp) / (disc - clamp);
  result.nodes = nodeCount(profile, 5);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

}  // namespace drape::analysis
