#version 330 core
// Cloth, colliders and the table share this vertex stage: world position, normal, a scalar
// (strain) and the cloth's own coordinates at rest (m, in its rest plane; 0 elsewhere).
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in float strain;
layout(location = 3) in vec2 restCoordinates;

uniform mat4 viewProjection;
uniform mat4 lightViewProjection;
uniform vec3 lightDirection;      // unit, towards the light
uniform float shadowNormalOffset;  // m: the shadow is looked up this far off the surface, on the lit side

out vec3 worldPosition;
out vec3 worldNormal;
out vec4 lightSpacePosition;
out float vertexStrain;
out vec2 clothCoordinates;

void main() {
  worldPosition = position;
  worldNormal = normal;
  vertexStrain = strain;
  clothCoordinates = restCoordinates;
  // Normal-offset shadows: looked up a little towards the light, a thin two-sided surface does not
  // shadow itself in stripes ("acne") where it turns away from the light in a crease.
  float side = dot(normal, lightDirection) >= 0.0 ? 1.0 : -1.0;
  lightSpacePosition = lightViewProjection * vec4(position + normal * (side * shadowNormalOffset), 1.0);
  gl_Position = viewProjection * vec4(position, 1.0);
}
