#version 330 core
in vec4 vertexColour;
uniform bool roundPoints;
out vec4 fragmentColour;
void main() {
  if (roundPoints) {
    vec2 d = gl_PointCoord * 2.0 - 1.0;
    float r = dot(d, d);
    if (r > 1.0) discard;
    fragmentColour = vec4(vertexColour.rgb * (r > 0.55 ? 0.35 : 1.0), vertexColour.a);  // dark rim
    return;
  }
  fragmentColour = vertexColour;
}
