#version 330 core
// Pins, finger rings and the outline stroke: coloured points and lines drawn over the scene.
layout(location = 0) in vec3 position;
layout(location = 1) in vec4 colour;
uniform mat4 viewProjection;
uniform float pointSize;
out vec4 vertexColour;
void main() {
  vertexColour = colour;
  gl_Position = viewProjection * vec4(position, 1.0);
  gl_PointSize = pointSize;
}
