#version 330 core
// Cloth and ground share this vertex stage: world position, normal, and a scalar (strain).
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in float strain;

uniform mat4 viewProjection;
uniform mat4 lightViewProjection;

out vec3 worldPosition;
out vec3 worldNormal;
out vec4 lightSpacePosition;
out float vertexStrain;

void main() {
  worldPosition = position;
  worldNormal = normal;
  vertexStrain = strain;
  lightSpacePosition = lightViewProjection * vec4(position, 1.0);
  gl_Position = viewProjection * vec4(position, 1.0);
}
