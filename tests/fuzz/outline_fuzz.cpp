// Fuzzes the outline builder (a cloth cut to a drawn stroke, sim::buildFromOutline).
//
// The bytes are read as an OutlineSpec, so that both wild and plausible strokes come up:
//   byte 0: bit 0: spacing and height are raw doubles; bit 1: points are raw doubles; bit 2:
//           points are 16-bit integers (else 8-bit); bits 3-7: e, a scale exponent 0..31.
//   raw spacing: bytes 1-8 spacing, 9-16 height (doubles, as in memory), 17 the constraint kinds;
//   else:        byte 1 spacing = (1 + b) / 2560 m (0.4 mm .. 10 cm), byte 2 height = (int8) b * 5 cm,
//                byte 3 the constraint kinds (bits 0-2: stretch, shear, bend; 0 is taken as all).
//   the rest: points (x, z) as pairs: raw doubles (16 bytes a point); 16-bit integers times
//             spacing * 2^(e/2 - 8); 8-bit integers times spacing * 2^(e/4 - 3).
// A stroke that could fill more than 400 particles (fuzz_support.hpp) is skipped (slow, not
// hostile), unless its numbers are not finite, which the builder must refuse at once.
//
// Checked of a cloth it builds: every index names a particle it has, every position and rest
// length is finite, there is a loop of at least 3 corners, and (for small cloths) building it
// again gives the same cloth. Expected failure: std::invalid_argument; anything else escapes, and
// libFuzzer reports it.
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "drape/sim/outline.hpp"
#include "fuzz_support.hpp"

using namespace drape;

namespace {

template <typename T>
T take(const std::uint8_t*& data, std::size_t& size) {
  T value{};
  std::memcpy(&value, data, sizeof(T));
  data += sizeof(T);
  size -= sizeof(T);
  return value;
}

void check(const sim::OutlineCloth& cloth) {
  const sim::ClothRest& rest = cloth.rest;
  const std::size_t n = rest.particleCount();
  if (n < 3 || rest.triangles.empty()) fuzz::broken("an outline cloth without particles or triangles");
  if (cloth.loop.size() < 3) fuzz::broken("an outline cloth's loop has fewer than 3 corners");
  if (rest.columns != 0 || rest.rows != 0) fuzz::broken("an outline cloth claims to be a lattice");
  for (std::size_t i = 0; i < n; ++i) {
    const sim::Vec3 p = rest.restPosition(i);
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) fuzz::broken("a rest position not finite");
  }
  for (const glm::uvec3& t : rest.triangles) {
    if (t.x >= n || t.y >= n || t.z >= n) fuzz::broken("a triangle names a particle the cloth does not have");
    if (t.x == t.y || t.y == t.z || t.x == t.z) fuzz::broken("a triangle names one particle twice");
  }
  for (sim::ConstraintKind kind : sim::kConstraintKinds) {
    for (const sim::DistanceConstraint& k : rest.of(kind)) {
      if (k.a >= n || k.b >= n || k.a == k.b) fuzz::broken("a constraint names a wrong particle");
      if (!std::isfinite(k.restLength) || k.restLength < 0) fuzz::broken("a rest length not finite");
    }
  }
  for (const glm::dvec2& p : cloth.loop) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) fuzz::broken("a loop point not finite");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 4) return 0;
  const auto flags = take<std::uint8_t>(data, size);
  const bool rawHeader = flags & 1, rawPoints = flags & 2, wide = flags & 4;
  const int e = flags >> 3;
  sim::OutlineSpec spec;
  std::uint8_t kinds = 0;
  if (rawHeader) {
    if (size < 17) return 0;
    spec.spacing = take<double>(data, size);
    spec.height = take<double>(data, size);
    kinds = take<std::uint8_t>(data, size);
  } else {
    spec.spacing = (1.0 + take<std::uint8_t>(data, size)) / 2560.0;
    spec.height = take<std::int8_t>(data, size) * 0.05;
    kinds = take<std::uint8_t>(data, size);
  }
  sim::ConstraintSelection selection;
  if (kinds & 7) selection = {(kinds & 1) != 0, (kinds & 2) != 0, (kinds & 4) != 0};
  if (rawPoints) {
    while (size >= 2 * sizeof(double)) {
      const double x = take<double>(data, size);
      spec.points.push_back({x, take<double>(data, size)});
    }
  } else if (wide) {
    const double unit = spec.spacing * std::exp2(e / 2.0 - 8.0);
    while (size >= 2 * sizeof(std::int16_t)) {
      const double x = take<std::int16_t>(data, size) * unit;
      spec.points.push_back({x, take<std::int16_t>(data, size) * unit});
    }
  } else {
    const double unit = spec.spacing * std::exp2(e / 4.0 - 3.0);
    while (size >= 2) {
      const double x = take<std::int8_t>(data, size) * unit;
      spec.points.push_back({x, take<std::int8_t>(data, size) * unit});
    }
  }
  const double particles = fuzz::estimatedParticles(spec);
  if (std::isfinite(particles) && particles > fuzz::kMaxOutlineParticles) return 0;
  try {
    const sim::OutlineCloth cloth = sim::buildFromOutline(spec, selection);
    check(cloth);
    if (cloth.rest.particleCount() <= 500) {
      const sim::OutlineCloth again = sim::buildFromOutline(spec, selection);
      if (again.rest.restOffsets != cloth.rest.restOffsets || again.rest.triangles != cloth.rest.triangles ||
          again.loop != cloth.loop || again.tookLargestLoop != cloth.tookLargestLoop) {
        fuzz::broken("the same outline built twice gives two cloths");
      }
    }
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
