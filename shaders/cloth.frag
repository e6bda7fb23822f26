#version 330 core
// Two-sided cloth: the front and back get their own colour so folds read clearly; lit by one
// directional light with a soft (percentage-closer filtered) shadow, a hemisphere ambient and a
// faint sheen. With strainMap on, colour shows stretch: blue at rest, green, yellow, red at
// strainScale and beyond. With woven on, the cloth is a gingham: bands of its colour across white
// threads both ways, 2.5 cm wide, printed in its rest coordinates so they stretch and shear with
// it, and a plain weave of 2 mm threads that shows when the camera comes close. Both are filtered
// over the pixel's footprint, so neither shimmers far away.
in vec3 worldPosition;
in vec3 worldNormal;
in vec4 lightSpacePosition;
in float vertexStrain;
in vec2 clothCoordinates;

uniform vec3 frontColour;
uniform vec3 backColour;
uniform vec3 lightDirection;  // unit, from the surface towards the light
uniform vec3 eyePosition;
uniform bool strainMap;
uniform bool twoSided;  // cloth: the back gets its own colour; colliders: one-sided solids
uniform float strainScale;
uniform bool woven;
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

// As render::strainColour (renderer.hpp), which the app's legend draws: keep the two the same.
vec3 strainColour(float s) {
  float t = clamp(s / strainScale, 0.0, 1.0);
  vec3 cold = vec3(0.15, 0.35, 0.85), mid = vec3(0.2, 0.8, 0.3), warm = vec3(0.95, 0.85, 0.2), hot = vec3(0.9, 0.1, 0.1);
  if (t < 0.33) return mix(cold, mid, t / 0.33);
  if (t < 0.66) return mix(mid, warm, (t - 0.33) / 0.33);
  return mix(warm, hot, (t - 0.66) / 0.34);
}

const float kCheck = 0.05;     // m, the gingham's period (a band of colour and one of white)
const float kThread = 0.002;   // m, between threads of the weave
const vec3 kWhite = vec3(0.96, 0.94, 0.90);

// The share of [x - w/2, x + w/2] (in periods) that lies in the first half of a period: a square
// wave box-filtered over the pixel's footprint w. Its integral is floor(x)/2 + min(fract(x), 1/2).
float band(float x, float w) {
  w = max(w, 1e-4);
  float a = x - 0.5 * w, b = x + 0.5 * w;
  return ((floor(b) * 0.5 + min(fract(b), 0.5)) - (floor(a) * 0.5 + min(fract(a), 0.5))) / w;
}

// Gingham colour and the weave's shading at a point of the cloth.
vec3 woven_colour(vec3 base, vec2 at) {
  vec2 p = at / kCheck;
  vec2 footprint = fwidth(p);
  float across = band(p.x, footprint.x), along = band(p.y, footprint.y);
  // White where neither band is, the colour half-strength where one is, full where both cross.
  vec3 colour = mix(kWhite, base, 0.18 + 0.41 * across + 0.41 * along);
  // Plain weave: in each thread cell the warp (along y) or the weft (along x) lies on top, by a
  // checkerboard; a thread is round, so it is lit in its middle and darker at its sides.
  vec2 q = at / kThread;
  vec2 cell = floor(q), f = fract(q) * 2.0 - 1.0;
  bool warpOnTop = mod(cell.x + cell.y, 2.0) < 1.0;
  float profile = sqrt(max(1.0 - (warpOnTop ? f.x * f.x : f.y * f.y), 0.0));
  float weave = 0.82 + 0.18 * profile;
  // Faded out where a thread is smaller than a pixel and a half: its mean there.
  float fade = clamp(1.6 - 1.6 * max(fwidth(q).x, fwidth(q).y), 0.0, 1.0);
  return colour * mix(0.935, weave, fade);
}

void main() {
  vec3 n = normalize(worldNormal);
  vec3 base = frontColour;
  if (twoSided && !gl_FrontFacing) {
    n = -n;
    base = backColour;
  }
  if (strainMap) {
    base = strainColour(vertexStrain);
  } else if (woven) {
    base = woven_colour(base, clothCoordinates);
  }
  float diffuse = max(dot(n, lightDirection), 0.0) * shadowFactor(n);
  float ambient = mix(0.30, 0.50, n.y * 0.5 + 0.5);
  vec3 toEye = normalize(eyePosition - worldPosition);
  float fill = 0.25 * max(dot(n, toEye), 0.0);  // a soft light from the viewer, so no side goes black
  float sheen = pow(1.0 - max(dot(n, toEye), 0.0), 3.0) * 0.15;
  fragmentColour = vec4(base * (ambient + fill + 0.7 * diffuse) + vec3(sheen), 1.0);
}
