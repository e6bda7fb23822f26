#version 330 core
// The table: world position, and where it lies in the light's view (for its shadow).
layout(location = 0) in vec3 position;

uniform mat4 viewProjection;
uniform mat4 lightViewProjection;

out vec3 worldPosition;
out vec4 lightSpacePosition;

void main() {
  worldPosition = position;
  lightSpacePosition = lightViewProjection * vec4(position, 1.0);
  gl_Position = viewProjection * vec4(position, 1.0);
}
