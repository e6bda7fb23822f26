// The orbit camera: pure geometry, checked against what it must mean on screen.
#include <gtest/gtest.h>

#include <cmath>

#include <glm/geometric.hpp>

#include "drape/render/camera.hpp"

namespace drape::render {
namespace {

glm::dvec3 project(const Camera& camera, glm::dvec3 point, double aspect) {
  const glm::vec4 clip = camera.projection(aspect) * camera.view() * glm::vec4(glm::vec3(point), 1.0f);
  return glm::dvec3(clip) / static_cast<double>(clip.w);
}

TEST(Camera, LooksAtItsTargetFromItsDistance) {
  Camera camera;
  camera.target = {1.0, 2.0, 3.0};
  camera.yaw = 0.0;
  camera.pitch = 0.0;
  camera.distance = 4.0;
  const glm::dvec3 eye = camera.eye();
  EXPECT_NEAR(eye.x, 1.0, 1e-12);
  EXPECT_NEAR(eye.y, 2.0, 1e-12);
  EXPECT_NEAR(eye.z, 7.0, 1e-12);  // yaw 0 looks along -z
  const glm::dvec3 centre = project(camera, camera.target, 1.5);
  EXPECT_NEAR(centre.x, 0.0, 1e-6);
  EXPECT_NEAR(centre.y, 0.0, 1e-6);
}

TEST(Camera, RayThroughThePictureCentreHitsTheTargetAndCornersFollowTheScreen) {
  Camera camera;
  camera.target = {0.0, 1.0, 0.0};
  const Ray centre = camera.ray(0.5, 0.5, 4.0 / 3.0);
  const double along = glm::dot(camera.target - centre.origin, centre.direction);
  EXPECT_NEAR(glm::length(centre.origin + centre.direction * along - camera.target), 0.0, 1e-9);
  // A point on the ray through the top-left corner projects to the top-left of clip space.
  const Ray corner = camera.ray(0.0, 0.0, 4.0 / 3.0);
  const glm::dvec3 ndc = project(camera, corner.origin + corner.direction * camera.distance, 4.0 / 3.0);
  EXPECT_NEAR(ndc.x, -1.0, 1e-4);
  EXPECT_NEAR(ndc.y, 1.0, 1e-4);
}

TEST(Camera, FramingKeepsTheWholeBoxInView) {
  const glm::dvec3 lower{-2.0, 0.0, -1.0}, upper{3.0, 2.5, 1.0};
  for (double aspect : {0.5, 1.0, 2.0}) {
    const Camera camera = Camera::framing(lower, upper, 0.7, 0.3, aspect);
    for (int corner = 0; corner < 8; ++corner) {
      const glm::dvec3 p{corner & 1 ? upper.x : lower.x, corner & 2 ? upper.y : lower.y,
                         corner & 4 ? upper.z : lower.z};
      const glm::dvec3 ndc = project(camera, p, aspect);
      EXPECT_LE(std::abs(ndc.x), 1.0) << aspect;
      EXPECT_LE(std::abs(ndc.y), 1.0) << aspect;
    }
  }
}

TEST(Camera, OrbitPanZoomMoveAsAUserExpects) {
  Camera camera;
  const double distance = camera.distance;
  camera.zoom(2.0);
  EXPECT_NEAR(camera.distance, distance / 2.0, 1e-12);
  camera.orbit(0.0, 10.0);
  EXPECT_LE(camera.pitch, 1.5);  // never over the pole
  const glm::dvec3 before = camera.target;
  camera.pan(0.1, 0.0);
  EXPECT_NEAR(glm::length(camera.target - before), 0.1 * camera.distance, 1e-12);
  EXPECT_NEAR(camera.target.y, before.y, 1e-12);  // panning right stays level
  camera.zoom(0.0);                               // refused
  EXPECT_GT(camera.distance, 0.0);
}

}  // namespace
}  // namespace drape::render
