// What the fuzz harnesses share: the libFuzzer entry point's declaration, how big a world one input
// may make and step, and how a broken promise is reported (docs/fuzzing.md).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

#include <glm/common.hpp>
#include <nlohmann/json.hpp>

#include "drape/mesh/outline.hpp"
#include "drape/sim/settings.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace drape::fuzz {

// One input stays fast: a world of more particles is not built, and a world is stepped only as
// far as this much work (particles times constraint sweeps, roughly) allows. Scenes beyond these
// are legal but slow by design, not hostile.
inline constexpr long long kMaxWorldParticles = 20000;
// The outline builder alone: its bugs are in the geometry, which small cloths have as well. At
// 3,000 the harness ran 27-150 inputs a second, at 400 some 550 (docs/fuzzing.md).
inline constexpr long long kMaxOutlineParticles = 400;
inline constexpr double kStepBudget = 2.0e5;
// Self-contact's work follows how many primitives lie within reach of each other, which no setting
// tells before the world moves: the shipped gestures on the desk find up to 99 pairs a particle
// (spread; tear 92, crumple 77), a sheet torn to shreds and whipping about found 310 to 550, and
// its first step took 16 s under the sanitizers for 1,776 particles (docs/fuzzing.md, Findings).
// So a substep of it counts as this many sweeps a particle (at least: selfContactSweeps): a world
// that collides with itself is stepped once only at some 950 particle-substeps a step or fewer,
// twice at 475. (At 100, a 25 x 24 sheet whose pins lie metres from where it was built, stretched
// in its first step, was stepped once: 1.5 s in Release, past 10 s in the fuzz build;
// docs/fuzzing.md, Findings.)
inline constexpr double kSelfContactSweeps = 200.0;

inline std::string_view text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// A promise of the code under test did not hold: said on stderr, then abort, so that libFuzzer
// (or the replay) reports the input.
[[noreturn]] inline void broken(const char* what, const char* detail = "") {
  std::fprintf(stderr, "fuzz: broken promise: %s %s\n", what, detail);
  std::abort();
}

// At most how many particles an outline fills, before it is built: the cloth's loop is made of
// pieces of the closed stroke, so its perimeter is at most the stroke's length L, its area at most
// L^2 / (4 pi) (and at most the stroke's bounding box); a particle per lattice cell of that area
// plus a few per spacing of the border. Measured in spacings, so that a tiny spacing does not
// underflow. Infinite when that is not a finite number (the engine must refuse those at once).
inline double estimatedParticles(const mesh::OutlineSpec& outline) {
  if (outline.points.empty()) return 0.0;
  const double s = outline.spacing;
  glm::dvec2 lower = outline.points.front() / s, upper = lower;
  double length = 0.0;
  for (std::size_t i = 0; i < outline.points.size(); ++i) {
    const glm::dvec2 p = outline.points[i] / s;
    lower = glm::min(lower, p);
    upper = glm::max(upper, p);
    const glm::dvec2 d = outline.points[(i + 1) % outline.points.size()] / s - p;
    length += std::sqrt(d.x * d.x + d.y * d.y);
  }
  const double box = (upper.x - lower.x + 2.0) * (upper.y - lower.y + 2.0);
  const double area = std::min(box, length * length / (4.0 * 3.14159265358979323846));
  const double estimate = area + 4.0 * length + static_cast<double>(outline.points.size());
  return std::isfinite(estimate) ? estimate : HUGE_VAL;
}

// Particles a cloth will have, before it is built (a drawn cloth's mesh is made when its scene is read).
inline double estimatedParticles(const sim::ClothSettings& cloth) {
  if (cloth.mesh) return static_cast<double>(cloth.mesh->positions.size());
  return static_cast<double>(cloth.lattice.columns) * static_cast<double>(cloth.lattice.rows);
}

// The same for the drawn cloths of a scene document, before it is read: reading a scene builds
// each outline (to count its particles), so a short file with a wide outline is slow to read by
// design. Looks only at what it understands; anything malformed is left to the reader.
inline double estimatedOutlineParticles(const nlohmann::json& scene) {
  double total = 0.0;
  if (!scene.is_object() || !scene.contains("cloths") || !scene["cloths"].is_array()) return total;
  for (const nlohmann::json& cloth : scene["cloths"]) {
    if (!cloth.is_object() || !cloth.contains("outline") || !cloth["outline"].is_object()) continue;
    const nlohmann::json& outline = cloth["outline"];
    mesh::OutlineSpec spec;
    if (outline.contains("spacing") && outline["spacing"].is_number()) spec.spacing = outline["spacing"].get<double>();
    // What the reader refuses before it builds (docs/scenes.md's ranges), it refuses at once.
    if (!(spec.spacing >= 1.0e-3 && spec.spacing <= 10.0)) continue;
    if (!outline.contains("points") || !outline["points"].is_array()) continue;
    bool inRange = true;
    for (const nlohmann::json& p : outline["points"]) {
      if (p.is_array() && p.size() == 2 && p[0].is_number() && p[1].is_number()) {
        spec.points.push_back({p[0].get<double>(), p[1].get<double>()});
        inRange = inRange && std::abs(spec.points.back().x) <= 1.0e4 && std::abs(spec.points.back().y) <= 1.0e4;
      }
    }
    if (inRange) total += estimatedParticles(spec);
  }
  return total;
}

inline double estimatedParticles(const sim::WorldSettings& world) {
  double total = 0.0;
  for (const sim::ClothSettings& cloth : world.cloths) total += estimatedParticles(cloth);
  return total;
}

// Self-contact's pairs a particle grow with the square of its distance against the spacing (the
// neighbours within reach in a layer; more in a pile). Up to a fifth of the spacing (the desk at
// 24 x 24: 0.19) a substep of self-contact counts kSelfContactSweeps; beyond, that times the square
// of the ratio to a fifth (the desk at 32 x 32: 0.26, 1.7 times). (A 24 x 24 sheet torn to shreds
// in its first step at 2 cm, 0.46 of its 4.3 cm spacing, listed 326 pairs a particle: 0.8 s in
// Release and 9 s under the sanitizers for that one step; docs/fuzzing.md, Findings.)
//
// A pin placed far from where its lattice puts the particle drags the cloth that far in its first
// step, shredding it on the way (a tear threshold near 1) and sweeping every piece's box across the
// others: beyond ten spacings from the lattice's reach, that times the distance over ten spacings.
// (A 24 x 24 sheet 9 m by 2 m built 50 m from its pins, at 2 cm: 1.2 s for two steps in Release
// and 9.8 s for one in the fuzz build, at 260 sweeps; docs/fuzzing.md, Findings.)
inline double selfContactSweeps(const sim::WorldSettings& world) {
  double spacing = HUGE_VAL, far = 0.0;
  for (const sim::ClothSettings& cloth : world.cloths) {
    if (cloth.mesh) {
      spacing = std::min(spacing, cloth.mesh->spacing);
      continue;
    }
    const sim::LatticeSpec& grid = cloth.lattice;
    if (grid.columns > 1) spacing = std::min(spacing, grid.width / (grid.columns - 1));
    if (grid.rows > 1) spacing = std::min(spacing, grid.height / (grid.rows - 1));
    // The lattice lies within width + height of its origin along every axis, whatever its plane.
    const double reach = std::abs(grid.width) + std::abs(grid.height);
    for (const sim::Pin& pin : cloth.pins) {
      if (!pin.position) continue;
      const glm::dvec3 d = glm::max(glm::abs(*pin.position - grid.origin) - reach, glm::dvec3{0.0});
      far = std::max(far, std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z));
    }
  }
  const double ratio = world.selfCollision.distance / (0.2 * spacing);
  // (Not a number, or a spacing of nothing: as many as the cap.)
  double factor = ratio <= 1.0 ? 1.0 : std::min(ratio * ratio, 1.0e6);
  const double dragged = far / (10.0 * spacing);
  if (!(dragged <= 1.0)) factor *= std::isnan(dragged) ? 1.0e6 : std::min(dragged, 1.0e6);
  return kSelfContactSweeps * (std::isnan(factor) ? 1.0e6 : std::min(factor, 1.0e6));
}

// How many of `wanted` steps fit the budget for a world of `particles` particles.
inline int affordableSteps(const sim::WorldSettings& world, double particles, int wanted) {
  const sim::SolverSettings& s = world.solver;
  double sweeps = 4.0;  // the force model: RK4 evaluates the forces four times a substep
  if (s.model == sim::Model::position) {
    sweeps =
        std::max(1, s.iterations) * (1.0 + (s.lines() ? 2.0 + (s.maxStretch > 0.0 ? sim::kExtraLineSteps : 0) : 0.0)) +
        1.0;
  }
  if (world.selfCollision.enabled) sweeps += selfContactSweeps(world);
  const double perStep = std::max(1.0, particles) * std::max(1, s.substeps) * sweeps;
  return static_cast<int>(std::clamp(std::floor(kStepBudget / perStep), 0.0, static_cast<double>(wanted)));
}

}  // namespace drape::fuzz
