// An orbit camera: it looks at `target` from `distance` away, turned `yaw` about the vertical and
// raised `pitch` above the horizon. Pure math (GLM), no GL: the app's input layer uses it to turn
// screen points into rays, the renderer to build its matrices.
#pragma once

#include <optional>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace drape::render {

struct Ray {
  glm::dvec3 origin;
  glm::dvec3 direction;  // unit
};

struct Camera {
  glm::dvec3 target{0.0, 0.8, 0.0};  // m, the point looked at
  double yaw = 0.6;                  // rad, 0 looks along -z (from +z), positive turns to the right
  double pitch = 0.4;                // rad, above the horizon; kept within +-1.5
  double distance = 3.0;             // m, from the target; kept within [0.05, 1000]
  double fieldOfView = 0.7854;       // rad, vertical

  glm::dvec3 eye() const;
  glm::dvec3 forward() const;  // unit, from the eye towards the target
  glm::mat4 view() const;
  glm::mat4 projection(double aspect) const;

  void orbit(double deltaYaw, double deltaPitch);
  // Moves eye and target together by (right, up) fractions of the distance.
  void pan(double right, double up);
  // Divides the distance by `factor` (> 1 comes closer).
  void zoom(double factor);

  // The ray through a point of the image, in normalised coordinates x, y in [0, 1] from the top left.
  Ray ray(double x, double y, double aspect) const;

  // Where `point` appears in the image, in the normalised coordinates ray() takes; nothing if it
  // is behind the eye.
  std::optional<glm::dvec2> project(glm::dvec3 point, double aspect) const;

  // Looks at the box [lower, upper] from (yaw, pitch), far enough that all of it is in view.
  static Camera framing(glm::dvec3 lower, glm::dvec3 upper, double yaw, double pitch, double aspect);
};

}  // namespace drape::render
