#version 330 core
// The table: a light neutral floor with a faint 10 cm grid, fading into the background with
// distance, darkened where the cloth's shadow falls. Built twice: with SHADOWED for the part of the
// table a shadow can reach, without it for the rest (a software rasteriser runs every branch of a
// shader, so a shadow lookup skipped by an `if` is still paid for: the renderer cuts the table and
// draws the part no shadow reaches with the shader that has none).
in vec3 worldPosition;
in vec4 lightSpacePosition;

uniform vec3 eyePosition;
uniform vec3 backgroundColour;
#ifdef SHADOWED
uniform sampler2DShadow shadowMap;
uniform int shadowRadius;  // the kernel is (2 r + 1)^2 taps over the same width: fewer are cheaper
#endif

out vec4 fragmentColour;

#ifdef SHADOWED
float shadowFactor() {
  vec3 p = lightSpacePosition.xyz / lightSpacePosition.w * 0.5 + 0.5;
  if (p.x < 0.0 || p.x > 1.0 || p.y < 0.0 || p.y > 1.0 || p.z > 1.0) return 1.0;
  vec2 texel = 1.0 / vec2(textureSize(shadowMap, 0));
  float lit = 0.0;
  float step = 6.0 / float(max(shadowRadius, 1));
  for (int x = -shadowRadius; x <= shadowRadius; ++x)
    for (int y = -shadowRadius; y <= shadowRadius; ++y)
      lit += texture(shadowMap, vec3(p.xy + vec2(x, y) * texel * step, p.z - 0.002));
  float side = float(2 * shadowRadius + 1);
  return lit / (side * side);
}
#endif

void main() {
  vec2 cell = abs(fract(worldPosition.xz * 10.0 - 0.5) - 0.5) / fwidth(worldPosition.xz * 10.0);
  // Grid lines fade out where they get denser than the pixels (no moire far away).
  float line = (1.0 - min(min(cell.x, cell.y), 1.0)) * clamp(1.5 - length(fwidth(worldPosition.xz * 10.0)), 0.0, 1.0);
  vec3 floorColour = vec3(0.78, 0.78, 0.76) - line * 0.06;
#ifdef SHADOWED
  floorColour *= 0.55 + 0.45 * shadowFactor();
#endif
  float fade = clamp(length(worldPosition - eyePosition) / 25.0, 0.0, 1.0);
  fragmentColour = vec4(mix(floorColour, backgroundColour, fade), 1.0);
}
