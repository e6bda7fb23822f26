#version 330 core
// Fast approximate antialiasing (after Lottes, "FXAA", NVIDIA 2009), one pass over the finished
// picture: where the colour around a pixel changes enough to be an edge, the pixel is blended
// along the edge's direction, by two taps near it, or four reaching further where those stay
// within the neighbourhood's range. FXAA reads edges from brightness; here the scalar is the
// colour's position along the neighbourhood's largest colour difference instead, so an edge
// between two colours of one brightness (the orange cloth on the grey sky) is found too.
// Five unfiltered reads a pixel, four filtered ones more on an edge.
uniform sampler2D picture;
uniform vec2 texel;  // 1 / the picture's size in pixels

out vec4 fragmentColour;

vec3 at(vec2 p) { return texture(picture, p).rgb; }

void main() {
  vec2 p = gl_FragCoord.xy * texel;
  // The pixel and its diagonal neighbours, read unfiltered (cheaper on a software rasteriser:
  // most pixels are no edge and stop here). Texture rows run upwards, as gl_FragCoord's.
  ivec2 q = ivec2(gl_FragCoord.xy), last = textureSize(picture, 0) - 1;
  vec3 centre = texelFetch(picture, q, 0).rgb;
  vec3 downLeft = texelFetch(picture, clamp(q + ivec2(-1, -1), ivec2(0), last), 0).rgb;
  vec3 downRight = texelFetch(picture, clamp(q + ivec2(1, -1), ivec2(0), last), 0).rgb;
  vec3 upLeft = texelFetch(picture, clamp(q + ivec2(-1, 1), ivec2(0), last), 0).rgb;
  vec3 upRight = texelFetch(picture, clamp(q + ivec2(1, 1), ivec2(0), last), 0).rgb;
  vec3 axis = downLeft - centre;
  for (int i = 0; i < 3; ++i) {
    vec3 d = (i == 0 ? downRight : i == 1 ? upLeft : upRight) - centre;
    if (dot(d, d) > dot(axis, axis)) axis = d;
  }
  // Too little difference to be an edge (about 20 of 255 in one channel): left alone.
  if (dot(axis, axis) < 0.0064) discard;
  axis = normalize(axis);
  float dl = dot(downLeft - centre, axis), dr = dot(downRight - centre, axis);
  float ul = dot(upLeft - centre, axis), ur = dot(upRight - centre, axis);
  float lowest = min(0.0, min(min(dl, dr), min(ul, ur)));
  float highest = max(0.0, max(max(dl, dr), max(ul, ur)));
  // The gradient turned a quarter: the direction along the edge.
  vec2 gradient = vec2((ur + dr) - (ul + dl), (ul + ur) - (dl + dr));
  vec2 along = vec2(-gradient.y, gradient.x);
  float damping = max(abs(dl + dr + ul + ur) / 32.0, 1.0 / 128.0);
  along = clamp(along / (min(abs(along.x), abs(along.y)) + damping), vec2(-8.0), vec2(8.0)) * texel;
  vec3 near = 0.5 * (at(p - along / 6.0) + at(p + along / 6.0));
  vec3 further = 0.5 * near + 0.25 * (at(p - along * 0.5) + at(p + along * 0.5));
  float b = dot(further - centre, axis);
  // Reaching further may cross another edge: then the near blend is kept.
  fragmentColour = vec4(b < lowest || b > highest ? near : further, 1.0);
}
