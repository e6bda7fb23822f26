#include "drape/render/camera.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

namespace drape::render {

glm::dvec3 Camera::forward() const {
  return -glm::dvec3{std::cos(pitch) * std::sin(yaw), std::sin(pitch), std::cos(pitch) * std::cos(yaw)};
}

glm::dvec3 Camera::eye() const { return target - forward() * distance; }

glm::mat4 Camera::view() const { return glm::mat4(glm::lookAt(eye(), target, glm::dvec3{0.0, 1.0, 0.0})); }

glm::mat4 Camera::projection(double aspect) const {
  const double near = std::max(0.01, distance * 0.01);
  return glm::mat4(glm::perspective(fieldOfView, aspect, near, distance * 20.0 + 50.0));
}

void Camera::orbit(double deltaYaw, double deltaPitch) {
  yaw += deltaYaw;
  pitch = std::clamp(pitch + deltaPitch, -1.5, 1.5);
}

void Camera::pan(double right, double up) {
  const glm::dvec3 f = forward();
  const glm::dvec3 r = glm::normalize(glm::cross(f, glm::dvec3{0.0, 1.0, 0.0}));
  const glm::dvec3 u = glm::cross(r, f);
  target += (r * right + u * up) * distance;
}

void Camera::zoom(double factor) {
  if (factor > 0.0 && std::isfinite(factor)) distance = std::clamp(distance / factor, 0.05, 1000.0);
}

Ray Camera::ray(double x, double y, double aspect) const {
  const glm::dvec3 f = forward();
  const glm::dvec3 r = glm::normalize(glm::cross(f, glm::dvec3{0.0, 1.0, 0.0}));
  const glm::dvec3 u = glm::cross(r, f);
  const double halfHeight = std::tan(fieldOfView / 2.0);
  const double ndcX = 2.0 * x - 1.0, ndcY = 1.0 - 2.0 * y;
  return {eye(), glm::normalize(f + r * (ndcX * halfHeight * aspect) + u * (ndcY * halfHeight))};
}

std::optional<glm::dvec2> Camera::project(glm::dvec3 point, double aspect) const {
  const glm::dvec3 f = forward();
  const glm::dvec3 r = glm::normalize(glm::cross(f, glm::dvec3{0.0, 1.0, 0.0}));
  const glm::dvec3 u = glm::cross(r, f);
  const glm::dvec3 d = point - eye();
  const double depth = glm::dot(d, f);
  if (!(depth > 1e-9)) return std::nullopt;
  const double halfHeight = std::tan(fieldOfView / 2.0);
  // The inverse of ray(): ndc = (d . r, d . u) / (depth * halfHeight * (aspect, 1)).
  const double ndcX = glm::dot(d, r) / (depth * halfHeight * aspect);
  const double ndcY = glm::dot(d, u) / (depth * halfHeight);
  return glm::dvec2{(ndcX + 1.0) / 2.0, (1.0 - ndcY) / 2.0};
}

Camera Camera::framing(glm::dvec3 lower, glm::dvec3 upper, double yaw, double pitch, double aspect) {
  Camera camera;
  camera.yaw = yaw;
  camera.pitch = pitch;
  camera.target = (lower + upper) * 0.5;
  // Distance at which the bounding sphere fits the narrower of the two fields of view, with a margin.
  const double radius = std::max(0.05, glm::length(upper - lower) * 0.5);
  const double halfAngle = std::atan(std::tan(camera.fieldOfView / 2.0) * std::min(1.0, aspect));
  camera.distance = std::clamp(radius / std::sin(halfAngle) * 1.05, 0.05, 1000.0);
  return camera;
}

}  // namespace drape::render
