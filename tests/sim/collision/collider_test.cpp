// A mesh collider's grid (engine/sim/src/collision/collider.cpp): the same answers as looking at every
// triangle, in memory bounded by the triangle count whatever the mix of sizes.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include <glm/geometric.hpp>

#include "drape/sim/collider.hpp"

namespace drape::sim {
namespace {

TEST(MeshCollider, AFewLargeTrianglesAmongManyTinyOnesKeepTheGridSmallAndTheAnswersExact) {
  // Tiny triangles make small cells; each large one was then listed in every cell its box touches,
  // 2 million cells each: a 742 KB mesh took 4.3 GB. The cells now grow until the lists are small.
  auto mesh = std::make_shared<TriangleMesh>();
  const auto add = [&](Vec3 a, Vec3 b, Vec3 c) {
    const auto first = static_cast<unsigned>(mesh->vertices.size());
    mesh->vertices.insert(mesh->vertices.end(), {a, b, c});
    mesh->triangles.push_back({first, first + 1, first + 2});
  };
  for (int i = 0; i < 40000; ++i) {  // 1 mm triangles in a 4 cm patch near a corner
    const Vec3 at{-1.0 + 0.0002 * (i % 200), -1.0 + 0.0002 * (i / 200), -1.0};
    add(at, at + Vec3{0.001, 0.0, 0.0}, at + Vec3{0.0, 0.001, 0.0005});
  }
  for (int i = 0; i < 100; ++i) {  // 2 m triangles across the whole box, tilted every which way
    const Real t = 0.0628 * i;
    add(Vec3{-1.0, -1.0 + 0.02 * i, 1.0}, Vec3{1.0, std::sin(t), -1.0}, Vec3{std::cos(t), 1.0, 0.02 * i - 1.0});
  }
  ColliderSettings settings;
  settings.shape = ColliderShape::mesh;
  settings.mesh = mesh;
  const Collider collider(settings);
  EXPECT_LT(collider.gridBytes(), std::size_t{64} << 20);
  // Against every triangle, at points near the small ones, near the large ones and in between.
  for (int k = 0; k < 100; ++k) {
    const Vec3 p{-1.0 + 0.02 * k, std::sin(0.37 * k), -1.0 + 0.026 * (k % 75)};
    const Real reach = 0.5;
    Real nearest = reach;
    for (const glm::uvec3& t : mesh->triangles) {
      nearest = std::min(nearest, glm::distance(p, closestPointOnTriangle(p, mesh->vertices[t.x], mesh->vertices[t.y],
                                                                          mesh->vertices[t.z])));
    }
    EXPECT_EQ(collider.distance(p, reach).distance, nearest) << k;
  }
}

}  // namespace
}  // namespace drape::sim
