// Triangles that show a collider: tessellated shapes at the collider's current pose.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "drape/sim/collider.hpp"

namespace drape::render {

struct ColliderGeometry {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<std::uint32_t> indices;
  void clear() {
    positions.clear();
    normals.clear();
    indices.clear();
  }
};

// Appends the collider's surface. A plane through the origin facing (nearly) up is left out: the
// renderer draws the table itself.
void appendColliderGeometry(const sim::Collider& collider, ColliderGeometry& out);

}  // namespace drape::render
