// Fuzzes the outline mesher (a cloth cut to a drawn stroke: mesh::meshOutline, then the engine's
// sim::constrainMesh).
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
// Checked of a mesh it makes: every index names a particle it has, every position is finite, no
// two particles stand for one lattice node, there is a loop of at least 3 corners, and (for small
// cloths) meshing it again gives the same mesh; the engine takes it (constrainMesh refusing it is
// a failure), and every constraint it makes names two particles and has a finite rest length.
// Expected failure: std::invalid_argument from the mesher; anything else escapes, and libFuzzer
// reports it.
#include <cmath>
#include <cstring>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>

#include "drape/mesh/outline.hpp"
#include "drape/sim/cloth.hpp"
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

void check(const mesh::OutlineMesh& shape) {
  const std::size_t n = shape.positions.size();
  if (n < 3 || shape.triangles.empty()) fuzz::broken("an outline mesh without particles or triangles");
  if (shape.nodes.size() != n) fuzz::broken("an outline mesh without a node (or none) for every particle");
  if (shape.loop.size() < 3) fuzz::broken("an outline mesh's loop has fewer than 3 corners");
  for (const glm::dvec3& p : shape.positions) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) fuzz::broken("a position not finite");
  }
  for (const glm::uvec3& t : shape.triangles) {
    if (t.x >= n || t.y >= n || t.z >= n) fuzz::broken("a triangle names a particle the mesh does not have");
    if (t.x == t.y || t.y == t.z || t.x == t.z) fuzz::broken("a triangle names one particle twice");
  }
  std::set<std::pair<int, int>> nodes;
  for (const glm::ivec2& node : shape.nodes) {
    if (node == mesh::kNoNode) continue;
    if (node.x < 0 || node.y < 0) fuzz::broken("a lattice node with a negative column or row");
    if (!nodes.insert({node.x, node.y}).second) fuzz::broken("two particles stand for one lattice node");
  }
  for (const glm::dvec2& p : shape.loop) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) fuzz::broken("a loop point not finite");
  }
}

void check(const sim::ClothRest& rest) {
  const std::size_t n = rest.particleCount();
  if (rest.columns != 0 || rest.rows != 0) fuzz::broken("an outline cloth claims to be a lattice");
  for (sim::ConstraintKind kind : sim::kConstraintKinds) {
    for (const sim::DistanceConstraint& k : rest.of(kind)) {
      if (k.a >= n || k.b >= n || k.a == k.b) fuzz::broken("a constraint names a wrong particle");
      if (!std::isfinite(k.restLength) || k.restLength < 0) fuzz::broken("a rest length not finite");
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 4) return 0;
  const auto flags = take<std::uint8_t>(data, size);
  const bool rawHeader = flags & 1, rawPoints = flags & 2, wide = flags & 4;
  const int e = flags >> 3;
  mesh::OutlineSpec spec;
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
  mesh::OutlineMesh shape;
  try {
    shape = mesh::meshOutline(spec);
  } catch (const std::invalid_argument&) {
    return 0;
  }
  check(shape);
  if (shape.positions.size() <= 500) {
    const mesh::OutlineMesh again = mesh::meshOutline(spec);
    if (again.positions != shape.positions || again.triangles != shape.triangles || again.nodes != shape.nodes ||
        again.loop != shape.loop || again.tookLargestLoop != shape.tookLargestLoop) {
      fuzz::broken("the same outline meshed twice gives two meshes");
    }
  }
  try {
    check(sim::constrainMesh({shape.positions, shape.triangles, shape.nodes, spec.spacing}, selection));
  } catch (const std::invalid_argument& error) {
    fuzz::broken((std::string("the engine refused the mesher's mesh: ") + error.what()).c_str());
  }
  return 0;
}
