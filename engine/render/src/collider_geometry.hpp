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

// A plane through the origin facing (nearly) up: the table, which the renderer draws itself.
bool showsAsTable(const sim::Collider& collider);

// Appends the collider's surface, `inset` (m) inside the real one: cloth rests a thickness off a
// collider, and a flat triangle of it across a box's edge cuts the corner; drawn inside that
// thickness, the edge does not show through the cloth. A sphere, capsule or box keeps at least half
// its size; a mesh (a shell the cloth keeps off on both sides) is drawn as it is. The table is
// left out.
void appendColliderGeometry(const sim::Collider& collider, ColliderGeometry& out, double inset = 0.0);

}  // namespace drape::render
