#version 330 core
// Two-sided cloth: the front and back get their own colour so folds read clearly; lit by one
// directional light with a soft (percentage-closer filtered) shadow, a hemisphere ambient and a
// faint sheen. With strainMap on, colour shows stretch: blue at rest, green, yellow, red at
// strainScale and beyond.
in vec3 worldPosition;
in vec3 worldNormal;
in vec4 lightSpacePosition;
in float vertexStrain;

uniform vec3 frontColour;
uniform vec3 backColour;
uniform vec3 lightDirection;  // unit, from the surface towards the light
uniform vec3 eyePosition;
uniform bool strainMap;
uniform bool twoSided;  // cloth: the back gets its own colour; colliders: one-sided solids
uniform float strainScale;
uniform sampler2DShadow shadowMap;
uniform int shadowRadius;  // the kernel is (2 r + 1)^2 taps over the same width

out vec4 fragmentColour;

float shadowFactor(vec3 normal) {
  vec3 p = lightSpacePosition.xyz / lightSpacePosition.w * 0.5 + 0.5;
  if (p.x < 0.0 || p.x > 1.0 || p.y < 0.0 || p.y > 1.0 || p.z > 1.0) return 1.0;
  float bias = 0.0015 + 0.003 * (1.0 - abs(dot(normal, lightDirection)));
  vec2 texel = 1.0 / vec2(textureSize(shadowMap, 0));
  float lit = 0.0;
  float step = 3.0 / float(max(shadowRadius, 1));
  for (int x = -shadowRadius; x <= shadowRadius; ++x)
    for (int y = -shadowRadius; y <= shadowRadius; ++y)
      lit += texture(shadowMap, vec3(p.xy + vec2(x, y) * texel * step, p.z - bias));
  float side = float(2 * shadowRadius + 1);
  return lit / (side * side);
}

vec3 strainColour(float s) {
  float t = clamp(s / strainScale, 0.0, 1.0);
  vec3 cold = vec3(0.15, 0.35, 0.85), mid = vec3(0.2, 0.8, 0.3), warm = vec3(0.95, 0.85, 0.2), hot = vec3(0.9, 0.1, 0.1);
  if (t < 0.33) return mix(cold, mid, t / 0.33);
  if (t < 0.66) return mix(mid, warm, (t - 0.33) / 0.33);
  return mix(warm, hot, (t - 0.66) / 0.34);
}

void main() {
  vec3 n = normalize(worldNormal);
  vec3 base = frontColour;
  if (twoSided && !gl_FrontFacing) {
    n = -n;
    base = backColour;
  }
  if (strainMap) base = strainColour(vertexStrain);
  float diffuse = max(dot(n, lightDirection), 0.0) * shadowFactor(n);
  float ambient = mix(0.30, 0.50, n.y * 0.5 + 0.5);
  vec3 toEye = normalize(eyePosition - worldPosition);
  float fill = 0.25 * max(dot(n, toEye), 0.0);  // a soft light from the viewer, so no side goes black
  float sheen = pow(1.0 - max(dot(n, toEye), 0.0), 3.0) * 0.15;
  fragmentColour = vec4(base * (ambient + fill + 0.7 * diffuse) + vec3(sheen), 1.0);
}
