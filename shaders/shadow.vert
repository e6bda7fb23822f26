#version 330 core
// Depth-only pass from the light.
layout(location = 0) in vec3 position;
uniform mat4 lightViewProjection;
void main() { gl_Position = lightViewProjection * vec4(position, 1.0); }
