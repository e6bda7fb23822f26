#include "drape/render/renderer.hpp"

// The loader comes first: it provides the GL declarations for everything below.
#include <glad/gl.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <string_view>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "collider_geometry.hpp"
#include "drape/sim/metrics.hpp"

namespace drape::render {

namespace shaders {
extern const std::string_view cloth_vert, cloth_frag, ground_vert, ground_frag, shadow_vert, shadow_frag, overlay_vert,
    overlay_frag, fxaa_vert, fxaa_frag;
}

namespace {

const glm::dvec3 kTowardsLight = glm::normalize(glm::dvec3{0.35, 1.0, 0.25});

// A GL info log as the one-line message of a RenderError.
[[noreturn]] void fail(const std::string& what, const char* log) {
  std::string message = what + ": " + log;
  std::replace(message.begin(), message.end(), '\n', ' ');
  throw RenderError(message);
}

GLuint compile(GLenum kind, std::string_view source, const char* name) {
  const GLuint shader = glCreateShader(kind);
  const char* text = source.data();
  const GLint length = static_cast<GLint>(source.size());
  glShaderSource(shader, 1, &text, &length);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    glGetShaderInfoLog(shader, sizeof log, nullptr, log);
    glDeleteShader(shader);
    fail(std::string("shader ") + name + " does not compile", log);
  }
  return shader;
}

// The source with `#define NAME` after its first line (the #version line).
std::string withDefine(std::string_view source, const char* name) {
  const std::size_t line = source.find('\n');
  if (line == std::string_view::npos) return std::string(source);
  return std::string(source.substr(0, line + 1)) + "#define " + name + "\n" + std::string(source.substr(line + 1));
}

GLuint link(std::string_view vertex, std::string_view fragment, const char* name) {
  const GLuint vs = compile(GL_VERTEX_SHADER, vertex, name);
  GLuint fs = 0;
  try {
    fs = compile(GL_FRAGMENT_SHADER, fragment, name);
  } catch (const RenderError&) {
    glDeleteShader(vs);
    throw;
  }
  const GLuint program = glCreateProgram();
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glLinkProgram(program);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = GL_FALSE;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    glGetProgramInfoLog(program, sizeof log, nullptr, log);
    glDeleteProgram(program);
    fail(std::string("program ") + name + " does not link", log);
  }
  return program;
}

GLint uniform(GLuint program, const char* name) { return glGetUniformLocation(program, name); }

void setMatrix(GLuint program, const char* name, const glm::mat4& m) {
  glUniformMatrix4fv(uniform(program, name), 1, GL_FALSE, glm::value_ptr(m));
}
void setVec3(GLuint program, const char* name, glm::vec3 v) {
  glUniform3fv(uniform(program, name), 1, glm::value_ptr(v));
}

// One cloth on the GPU: streamed positions, normals and strains, its rest coordinates and its
// (topology) indices.
struct GpuCloth {
  GLuint vao = 0, positions = 0, normals = 0, strains = 0, restCoordinates = 0, indices = 0;
  GLsizei triangleIndexCount = 0;
  // Drawn with the overlay program from the same positions: a chain's links, or a sheet's
  // triangle edges (the wireframe view).
  GLuint lineVao = 0, lineIndices = 0;
  GLsizei lineIndexCount = 0;
  bool chain = false;
  std::size_t particles = 0;
};

// Every particle's rest position in the cloth's rest plane (m): the plane's normal is the sum of
// the rest triangles' area vectors; its first axis is x where the plane allows (else z), so a
// sheet lying on the table or hanging in xy has its lattice's axes. The printed pattern follows
// these, stretching and shearing with the cloth; a tear's copies of a particle share its place.
std::vector<glm::vec2> restPlaneCoordinates(const sim::ClothRest& rest) {
  sim::Vec3 normal{0.0};
  for (const glm::uvec3& t : rest.triangles) {
    const sim::Vec3 a(rest.restOffsets[t.x]), b(rest.restOffsets[t.y]), c(rest.restOffsets[t.z]);
    normal += glm::cross(b - a, c - a);
  }
  normal = glm::length(normal) > 0.0 ? glm::normalize(normal) : sim::Vec3{0.0, 1.0, 0.0};
  const sim::Vec3 axis = std::abs(normal.x) < 0.9 ? sim::Vec3{1.0, 0.0, 0.0} : sim::Vec3{0.0, 0.0, 1.0};
  const sim::Vec3 u = glm::normalize(axis - normal * glm::dot(axis, normal)), v = glm::cross(normal, u);
  std::vector<glm::vec2> coordinates;
  coordinates.reserve(rest.restOffsets.size());
  for (const glm::vec3& offset : rest.restOffsets) {
    const sim::Vec3 p(offset);
    coordinates.emplace_back(static_cast<float>(glm::dot(p, u)), static_cast<float>(glm::dot(p, v)));
  }
  return coordinates;
}

// Each edge of the triangles once, as pairs of particle indices.
std::vector<std::uint32_t> triangleEdges(const std::vector<glm::uvec3>& triangles) {
  std::vector<std::uint64_t> keys;
  keys.reserve(triangles.size() * 3);
  for (const glm::uvec3& t : triangles) {
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = t[k], b = t[(k + 1) % 3];
      keys.push_back((static_cast<std::uint64_t>(std::min(a, b)) << 32) | std::max(a, b));
    }
  }
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  std::vector<std::uint32_t> pairs;
  pairs.reserve(keys.size() * 2);
  for (const std::uint64_t key : keys) {
    pairs.push_back(static_cast<std::uint32_t>(key >> 32));
    pairs.push_back(static_cast<std::uint32_t>(key & 0xffffffffu));
  }
  return pairs;
}

// The pixels (x, y, width, height from the bottom left) that the box [lower, upper] (the cloths
// and the finite colliders) covers in the picture, two pixels wider each way: FXAA looks for edges
// there only (overlay lines outside it, a seam or a ring, are not smoothed). The whole picture
// where the box is empty or a corner is behind the eye.
std::array<int, 4> coveredPixels(const Camera& camera, int width, int height, glm::dvec3 lower, glm::dvec3 upper) {
  const std::array<int, 4> whole{0, 0, width, height};
  if (!(lower.x <= upper.x)) return whole;
  const double aspect = static_cast<double>(width) / height;
  double left = 1.0, right = 0.0, top = 1.0, bottom = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const glm::dvec3 p{corner & 1 ? upper.x : lower.x, corner & 2 ? upper.y : lower.y, corner & 4 ? upper.z : lower.z};
    const std::optional<glm::dvec2> at = camera.project(p, aspect);
    if (!at) return whole;
    left = std::min(left, at->x);
    right = std::max(right, at->x);
    top = std::min(top, at->y);
    bottom = std::max(bottom, at->y);
  }
  // Clamped as doubles before they become ints: a corner just in front of the eye projects
  // beyond any int (a NaN, from a corner on the eye, goes to the whole picture's edge).
  const auto pixel = [](double at, int size, double pad) {
    const double p = at * size + pad;
    return p >= 0.0 ? static_cast<int>(std::min(p, static_cast<double>(size))) : 0;
  };
  const int x0 = pixel(left, width, -2.0), x1 = std::max(pixel(right, width, 3.0), x0);
  const int y0 = pixel(1.0 - bottom, height, -2.0), y1 = std::max(pixel(1.0 - top, height, 3.0), y0);
  return {x0, y0, x1 - x0, y1 - y0};
}

// The level plane through the origin is the table the renderer draws (collider_geometry.hpp).
bool hasTable(const sim::World& world) {
  return std::any_of(world.colliders().begin(), world.colliders().end(), [](const sim::Collider& c) {
    return c.settings().shape == sim::ColliderShape::plane && showsAsTable(c);
  });
}

// Where on the table (y = 0) a shadow can fall: the box [lower, upper] around everything that casts
// one, each corner also swept along the light down to the table, grown by `margin` (how far the
// shadow's filter reaches). {x0, z0, x1, z1}.
glm::dvec4 shadowFootprint(const glm::dvec3& lower, const glm::dvec3& upper, double margin) {
  glm::dvec2 low{std::numeric_limits<double>::max()}, high{std::numeric_limits<double>::lowest()};
  for (int corner = 0; corner < 8; ++corner) {
    const glm::dvec3 p{corner & 1 ? upper.x : lower.x, corner & 2 ? upper.y : lower.y, corner & 4 ? upper.z : lower.z};
    const glm::dvec3 onTable = p - kTowardsLight * (p.y / kTowardsLight.y);
    low = glm::min(low, glm::min(glm::dvec2{p.x, p.z}, glm::dvec2{onTable.x, onTable.z}));
    high = glm::max(high, glm::max(glm::dvec2{p.x, p.z}, glm::dvec2{onTable.x, onTable.z}));
  }
  return {low.x - margin, low.y - margin, high.x + margin, high.y + margin};
}

// The table, a square of half-width `extent` around `middle`, cut at the edges of the shadow's
// footprint {x0, z0, x1, z1} into up to nine rectangles, two triangles each: first the one a shadow
// can fall on (`shadowed` vertices, none when the footprint is off the table), then the rest.
struct TableCells {
  std::vector<glm::vec3> vertices;
  GLsizei shadowed = 0;
};

// A coordinate clamped into [lo, hi] as a double before it becomes a float (a NaN goes to lo).
float within(double v, float lo, float hi) { return v >= lo ? (v <= hi ? static_cast<float>(v) : hi) : lo; }

TableCells tableCells(glm::vec3 middle, float extent, const glm::dvec4& footprint) {
  const float x0 = within(footprint.x, middle.x - extent, middle.x + extent);
  const float x1 = within(footprint.z, x0, middle.x + extent);
  const float z0 = within(footprint.y, middle.z - extent, middle.z + extent);
  const float z1 = within(footprint.w, z0, middle.z + extent);
  const float xs[4] = {middle.x - extent, x0, x1, middle.x + extent};
  const float zs[4] = {middle.z - extent, z0, z1, middle.z + extent};
  TableCells cells;
  // The middle rectangle (i = j = 1) first.
  for (const auto& [i, j] : {std::pair{1, 1}, {0, 0}, {0, 1}, {0, 2}, {1, 0}, {1, 2}, {2, 0}, {2, 1}, {2, 2}}) {
    if (xs[i + 1] <= xs[i] || zs[j + 1] <= zs[j]) continue;  // empty where the footprint meets the table's edge
    const glm::vec3 a{xs[i], 0.0f, zs[j]}, b{xs[i + 1], 0.0f, zs[j]}, c{xs[i], 0.0f, zs[j + 1]},
        d{xs[i + 1], 0.0f, zs[j + 1]};
    cells.vertices.insert(cells.vertices.end(), {a, b, c, c, b, d});
    if (i == 1 && j == 1) cells.shadowed = 6;
  }
  return cells;
}

}  // namespace

void Overlay::addRing(glm::dvec3 centre, double radius, glm::dvec3 normal, glm::vec4 colour, int segments) {
  const glm::dvec3 n = glm::length(normal) > 0.0 ? glm::normalize(normal) : glm::dvec3{0.0, 1.0, 0.0};
  const glm::dvec3 helper = std::abs(n.y) < 0.9 ? glm::dvec3{0.0, 1.0, 0.0} : glm::dvec3{1.0, 0.0, 0.0};
  const glm::dvec3 u = glm::normalize(glm::cross(n, helper)), v = glm::cross(n, u);
  for (int i = 0; i < segments; ++i) {
    for (int end = 0; end < 2; ++end) {
      const double angle = 2.0 * 3.14159265358979 * (i + end) / segments;
      lines.push_back({glm::vec3(centre + (u * std::cos(angle) + v * std::sin(angle)) * radius), colour});
    }
  }
}

void Overlay::addStroke(const std::vector<glm::dvec3>& stroke, glm::vec4 colour) {
  for (std::size_t i = 1; i < stroke.size(); ++i) {
    lines.push_back({glm::vec3(stroke[i - 1]), colour});
    lines.push_back({glm::vec3(stroke[i]), colour});
  }
}

glm::vec3 strainColour(float strain, float scale) {
  const float t = std::clamp(strain / std::max(scale, 1e-6f), 0.0f, 1.0f);
  const glm::vec3 cold{0.15f, 0.35f, 0.85f}, mid{0.2f, 0.8f, 0.3f}, warm{0.95f, 0.85f, 0.2f}, hot{0.9f, 0.1f, 0.1f};
  if (t < 0.33f) return glm::mix(cold, mid, t / 0.33f);
  if (t < 0.66f) return glm::mix(mid, warm, (t - 0.33f) / 0.33f);
  return glm::mix(warm, hot, (t - 0.66f) / 0.34f);
}

void clothBounds(const sim::World& world, glm::dvec3& lower, glm::dvec3& upper) {
  lower = glm::dvec3{std::numeric_limits<double>::max()};
  upper = glm::dvec3{std::numeric_limits<double>::lowest()};
  for (const sim::Cloth& cloth : world.cloths()) {
    for (const sim::Vec3& x : cloth.state.position) {
      lower = glm::min(lower, x);
      upper = glm::max(upper, x);
    }
  }
}

namespace {

// The cloths' box [lower, upper] grown to sceneBounds: the finite colliders, the table under it.
void growToScene(const sim::World& world, glm::dvec3& lower, glm::dvec3& upper, double ahead) {
  for (const sim::Collider& collider : world.colliders()) {
    const sim::ColliderSettings& s = collider.settings();
    // A bounding sphere of each finite shape (planes are endless; meshes use their vertices).
    double radius = 0.0;
    if (s.shape == sim::ColliderShape::sphere) radius = s.radius;
    if (s.shape == sim::ColliderShape::capsule) radius = s.radius + glm::length(s.halfAxis);
    if (s.shape == sim::ColliderShape::box) radius = glm::length(s.halfExtents);
    if (s.shape == sim::ColliderShape::mesh) {
      for (const sim::Vec3& v : s.mesh->vertices) radius = std::max(radius, glm::length(v));
    }
    if (radius == 0.0) continue;
    lower = glm::min(lower, collider.centre() - radius);
    upper = glm::max(upper, collider.centre() + radius);
    const glm::dvec3 later = collider.centre() + s.velocity * ahead;
    if (ahead > 0.0 && std::isfinite(later.x + later.y + later.z)) {
      lower = glm::min(lower, later - radius);
      upper = glm::max(upper, later + radius);
    }
  }
  if (lower.x > upper.x) {  // nothing in the world: frame the table around the origin
    lower = glm::dvec3{-1.0, 0.0, -1.0};
    upper = glm::dvec3{1.0, 1.0, 1.0};
  }
  lower.y = std::min(lower.y, 0.0);
}

}  // namespace

void sceneBounds(const sim::World& world, glm::dvec3& lower, glm::dvec3& upper, double ahead) {
  clothBounds(world, lower, upper);
  growToScene(world, lower, upper, ahead);
}

struct Renderer::Impl {
  GLuint clothProgram = 0, groundProgram = 0, groundShadowedProgram = 0, shadowProgram = 0, overlayProgram = 0,
         fxaaProgram = 0;
  // FXAA: the part of the finished picture it filters is copied here, then filtered back over it.
  GLuint pictureColour = 0, fullScreenVao = 0;
  int pictureWidth = 0, pictureHeight = 0;
  GLuint shadowFramebuffer = 0, shadowTexture = 0;
  GLuint sampleFramebuffer = 0, sampleColour = 0, sampleDepth = 0;
  // The scene drawn at a fraction of the picture's size (FrameOptions::renderScale), stretched over it.
  GLuint scaledFramebuffer = 0, scaledColour = 0, scaledDepth = 0;
  int scaledWidth = 0, scaledHeight = 0;
  bool scaledComplete = false;
  float pixelScale = 1.0f;  // the picture's pixels per pixel of the caller's: markers keep their size on screen
  int sampleWidth = 0, sampleHeight = 0, samples = 0;
  int shadowMapSize = 0;
  GLuint groundVao = 0, groundBuffer = 0;
  GLuint overlayVao = 0, overlayBuffer = 0;
  GLuint colliderVao = 0, colliderPositions = 0, colliderNormals = 0, colliderIndices = 0;
  ColliderGeometry colliderGeometry;
  std::size_t overlayCapacity = 0;
  std::vector<GpuCloth> cloths;
  std::uint64_t topologyVersion = 0;
  int topologyUploads = 0;
  // Staging arrays reused every frame (single precision for the GPU).
  std::vector<glm::vec3> positions, normals;
  std::vector<float> strains;
  std::vector<sim::Vec3> normalScratch;
  std::vector<OverlayVertex> overlayScratch;

  void releaseCloths() {
    for (GpuCloth& c : cloths) {
      glDeleteVertexArrays(1, &c.vao);
      glDeleteVertexArrays(1, &c.lineVao);
      const GLuint buffers[] = {c.positions, c.normals, c.strains, c.restCoordinates, c.indices, c.lineIndices};
      glDeleteBuffers(6, buffers);
    }
    cloths.clear();
  }

  void uploadTopology(const sim::World& world) {
    releaseCloths();
    for (const sim::Cloth& cloth : world.cloths()) {
      GpuCloth gpu;
      gpu.particles = cloth.state.position.size();
      const auto bytes3 = static_cast<GLsizeiptr>(gpu.particles * sizeof(glm::vec3));
      glGenVertexArrays(1, &gpu.vao);
      glBindVertexArray(gpu.vao);
      const auto attribute = [](GLuint& buffer, GLuint location, GLint size, GLsizeiptr bytes) {
        glGenBuffers(1, &buffer);
        glBindBuffer(GL_ARRAY_BUFFER, buffer);
        glBufferData(GL_ARRAY_BUFFER, bytes, nullptr, GL_STREAM_DRAW);
        glVertexAttribPointer(location, size, GL_FLOAT, GL_FALSE, 0, nullptr);
        glEnableVertexAttribArray(location);
      };
      attribute(gpu.positions, 0, 3, bytes3);
      attribute(gpu.normals, 1, 3, bytes3);
      attribute(gpu.strains, 2, 1, static_cast<GLsizeiptr>(gpu.particles * sizeof(float)));
      const std::vector<glm::vec2> coordinates = restPlaneCoordinates(cloth.rest);
      attribute(gpu.restCoordinates, 3, 2, static_cast<GLsizeiptr>(coordinates.size() * sizeof(glm::vec2)));
      glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(coordinates.size() * sizeof(glm::vec2)),
                      coordinates.data());
      glGenBuffers(1, &gpu.indices);
      glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, gpu.indices);
      glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(cloth.rest.triangles.size() * sizeof(glm::uvec3)),
                   cloth.rest.triangles.data(), GL_STATIC_DRAW);
      gpu.triangleIndexCount = static_cast<GLsizei>(cloth.rest.triangles.size() * 3);
      // A chain: its stretch links as lines; a sheet: its triangles' edges (for the wireframe).
      // Positions come from the same buffer; the colour is set as each is drawn.
      gpu.chain = cloth.rest.triangles.empty();
      std::vector<std::uint32_t> links;
      if (gpu.chain) {
        for (const sim::DistanceConstraint& c : cloth.rest.of(sim::ConstraintKind::stretch)) {
          links.push_back(c.a);
          links.push_back(c.b);
        }
      } else {
        links = triangleEdges(cloth.rest.triangles);
      }
      {
        glGenVertexArrays(1, &gpu.lineVao);
        glBindVertexArray(gpu.lineVao);
        glBindBuffer(GL_ARRAY_BUFFER, gpu.positions);
        glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
        glEnableVertexAttribArray(0);
        glGenBuffers(1, &gpu.lineIndices);
        glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, gpu.lineIndices);
        glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(links.size() * sizeof(std::uint32_t)),
                     links.data(), GL_STATIC_DRAW);
        gpu.lineIndexCount = static_cast<GLsizei>(links.size());
      }
      cloths.push_back(gpu);
    }
    glBindVertexArray(0);
    topologyVersion = world.topologyVersion();
    ++topologyUploads;
  }

  void streamCloth(const sim::Cloth& cloth, const GpuCloth& gpu, bool strainMap) {
    const std::size_t n = cloth.state.position.size();
    positions.resize(n);
    for (std::size_t i = 0; i < n; ++i) positions[i] = glm::vec3(cloth.state.position[i]);
    sim::vertexNormals(cloth, normalScratch);
    normals.resize(n);
    for (std::size_t i = 0; i < n; ++i) normals[i] = glm::vec3(normalScratch[i]);
    strains.assign(n, 0.0f);
    if (strainMap) {
      // A particle shows the largest stretch among its structural links.
      for (const sim::DistanceConstraint& c : cloth.rest.of(sim::ConstraintKind::stretch)) {
        if (!(c.restLength > 0.0)) continue;
        const auto e =
            static_cast<float>(glm::length(cloth.state.position[c.b] - cloth.state.position[c.a]) / c.restLength - 1.0);
        strains[c.a] = std::max(strains[c.a], e);
        strains[c.b] = std::max(strains[c.b], e);
      }
    }
    glBindBuffer(GL_ARRAY_BUFFER, gpu.positions);
    glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(n * sizeof(glm::vec3)), positions.data());
    glBindBuffer(GL_ARRAY_BUFFER, gpu.normals);
    glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(n * sizeof(glm::vec3)), normals.data());
    glBindBuffer(GL_ARRAY_BUFFER, gpu.strains);
    glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(n * sizeof(float)), strains.data());
  }

  void resizeShadowMap(int size) {
    size = std::clamp(size, 256, 4096);
    if (size == shadowMapSize) return;
    shadowMapSize = size;
    glBindTexture(GL_TEXTURE_2D, shadowTexture);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, size, size, 0, GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, nullptr);
  }

  // False where the context cannot make it (then the scene is drawn at full size).
  bool ensureScaledTarget(int width, int height) {
    if (scaledFramebuffer && width == scaledWidth && height == scaledHeight) return scaledComplete;
    if (!scaledFramebuffer) {
      glGenFramebuffers(1, &scaledFramebuffer);
      glGenRenderbuffers(1, &scaledColour);
      glGenRenderbuffers(1, &scaledDepth);
    }
    glBindRenderbuffer(GL_RENDERBUFFER, scaledColour);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
    glBindRenderbuffer(GL_RENDERBUFFER, scaledDepth);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, scaledFramebuffer);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, scaledColour);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, scaledDepth);
    scaledComplete = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    scaledWidth = width;
    scaledHeight = height;
    return scaledComplete;
  }

  void ensureSampleTarget(int width, int height) {
    if (samples == 0 || (width == sampleWidth && height == sampleHeight)) return;
    if (!sampleFramebuffer) {
      glGenFramebuffers(1, &sampleFramebuffer);
      glGenRenderbuffers(1, &sampleColour);
      glGenRenderbuffers(1, &sampleDepth);
    }
    glBindRenderbuffer(GL_RENDERBUFFER, sampleColour);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, width, height);
    glBindRenderbuffer(GL_RENDERBUFFER, sampleDepth);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH_COMPONENT24, width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, sampleFramebuffer);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, sampleColour);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, sampleDepth);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) samples = 0;  // draw without MSAA
    sampleWidth = width;
    sampleHeight = height;
  }

  // The copy FXAA reads, as large as the picture (only the part it filters is ever written),
  // bound to the active unit.
  void bindPictureTexture(int width, int height) {
    if (!pictureColour) glGenTextures(1, &pictureColour);
    glBindTexture(GL_TEXTURE_2D, pictureColour);
    if (width == pictureWidth && height == pictureHeight) return;
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width, height, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    pictureWidth = width;
    pictureHeight = height;
  }

  void drawOverlay(const std::vector<OverlayVertex>& vertices, GLenum mode) {
    if (vertices.empty()) return;
    glBindVertexArray(overlayVao);
    glBindBuffer(GL_ARRAY_BUFFER, overlayBuffer);
    if (vertices.size() > overlayCapacity) {
      overlayCapacity = std::max(vertices.size(), overlayCapacity * 2);
      glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(overlayCapacity * sizeof(OverlayVertex)), nullptr,
                   GL_STREAM_DRAW);
    }
    glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(vertices.size() * sizeof(OverlayVertex)),
                    vertices.data());
    glDrawArrays(mode, 0, static_cast<GLsizei>(vertices.size()));
  }
};

Renderer::Renderer(GetProcAddress getProcAddress) : impl_(std::make_unique<Impl>()) {
  const int version = gladLoadGL(reinterpret_cast<GLADloadfunc>(getProcAddress));
  if (version == 0) throw RenderError("cannot load OpenGL functions");
  if (GLAD_VERSION_MAJOR(version) * 10 + GLAD_VERSION_MINOR(version) < 33) {
    throw RenderError("OpenGL 3.3 core is needed, the context has " + std::to_string(GLAD_VERSION_MAJOR(version)) +
                      "." + std::to_string(GLAD_VERSION_MINOR(version)));
  }
  Impl& r = *impl_;
  r.clothProgram = link(shaders::cloth_vert, shaders::cloth_frag, "cloth");
  r.groundProgram = link(shaders::ground_vert, shaders::ground_frag, "ground");
  r.groundShadowedProgram =
      link(shaders::ground_vert, withDefine(shaders::ground_frag, "SHADOWED"), "ground (shadowed)");
  r.shadowProgram = link(shaders::shadow_vert, shaders::shadow_frag, "shadow");
  r.overlayProgram = link(shaders::overlay_vert, shaders::overlay_frag, "overlay");
  r.fxaaProgram = link(shaders::fxaa_vert, shaders::fxaa_frag, "fxaa");
  glGenVertexArrays(1, &r.fullScreenVao);

  // Shadow map: a depth texture compared in hardware, filtered linearly (then PCF in the shader).
  glGenTextures(1, &r.shadowTexture);
  glBindTexture(GL_TEXTURE_2D, r.shadowTexture);
  r.resizeShadowMap(FrameOptions{}.shadowMapSize);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
  glGenFramebuffers(1, &r.shadowFramebuffer);
  glBindFramebuffer(GL_FRAMEBUFFER, r.shadowFramebuffer);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, r.shadowTexture, 0);
  glDrawBuffer(GL_NONE);
  glReadBuffer(GL_NONE);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    throw RenderError("the shadow-map framebuffer is incomplete");
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);

  GLint maxSamples = 0;
  glGetIntegerv(GL_MAX_SAMPLES, &maxSamples);
  r.samples = std::min(4, static_cast<int>(maxSamples));

  // The table: its cells' corners (tableCells), streamed each frame.
  glGenVertexArrays(1, &r.groundVao);
  glBindVertexArray(r.groundVao);
  glGenBuffers(1, &r.groundBuffer);
  glBindBuffer(GL_ARRAY_BUFFER, r.groundBuffer);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  glEnableVertexAttribArray(0);

  glGenVertexArrays(1, &r.colliderVao);
  glBindVertexArray(r.colliderVao);
  glGenBuffers(1, &r.colliderPositions);
  glBindBuffer(GL_ARRAY_BUFFER, r.colliderPositions);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  glEnableVertexAttribArray(0);
  glGenBuffers(1, &r.colliderNormals);
  glBindBuffer(GL_ARRAY_BUFFER, r.colliderNormals);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttrib1f(2, 0.0f);
  glGenBuffers(1, &r.colliderIndices);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, r.colliderIndices);

  glGenVertexArrays(1, &r.overlayVao);
  glBindVertexArray(r.overlayVao);
  glGenBuffers(1, &r.overlayBuffer);
  glBindBuffer(GL_ARRAY_BUFFER, r.overlayBuffer);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(OverlayVertex), nullptr);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, sizeof(OverlayVertex),
                        reinterpret_cast<const void*>(offsetof(OverlayVertex, colour)));
  glEnableVertexAttribArray(1);
  glBindVertexArray(0);
  if (glGetError() != GL_NO_ERROR) throw RenderError("OpenGL reported an error while setting up the renderer");
}

Renderer::~Renderer() {
  Impl& r = *impl_;
  r.releaseCloths();
  for (GLuint program :
       {r.clothProgram, r.groundProgram, r.groundShadowedProgram, r.shadowProgram, r.overlayProgram, r.fxaaProgram}) {
    glDeleteProgram(program);
  }
  glDeleteTextures(1, &r.pictureColour);
  glDeleteVertexArrays(1, &r.fullScreenVao);
  glDeleteFramebuffers(1, &r.shadowFramebuffer);
  glDeleteTextures(1, &r.shadowTexture);
  glDeleteFramebuffers(1, &r.sampleFramebuffer);
  glDeleteFramebuffers(1, &r.scaledFramebuffer);
  glDeleteRenderbuffers(1, &r.scaledColour);
  glDeleteRenderbuffers(1, &r.scaledDepth);
  glDeleteRenderbuffers(1, &r.sampleColour);
  glDeleteRenderbuffers(1, &r.sampleDepth);
  glDeleteVertexArrays(1, &r.groundVao);
  glDeleteBuffers(1, &r.groundBuffer);
  glDeleteVertexArrays(1, &r.overlayVao);
  glDeleteVertexArrays(1, &r.colliderVao);
  const GLuint colliderBuffers[] = {r.colliderPositions, r.colliderNormals, r.colliderIndices};
  glDeleteBuffers(3, colliderBuffers);
  glDeleteBuffers(1, &r.overlayBuffer);
}

void Renderer::render(const sim::World& world, const Camera& camera, int width, int height, const FrameOptions& options,
                      const Overlay& overlay) {
  Impl& r = *impl_;
  if (width <= 0 || height <= 0) return;  // a minimised window: nothing to draw
  GLint target = 0;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &target);

  // At a render scale under 1 the scene is drawn smaller, into a picture of its own, and stretched
  // (linearly filtered) over the caller's: a software rasteriser pays per pixel.
  const float scale = options.renderScale >= FrameOptions::kLowestRenderScale
                          ? std::min(options.renderScale, 1.0f)
                          : FrameOptions::kLowestRenderScale;  // a NaN too
  const int scaledWidth = std::max(1, static_cast<int>(std::lround(static_cast<double>(width) * scale)));
  const int scaledHeight = std::max(1, static_cast<int>(std::lround(static_cast<double>(height) * scale)));
  if ((scaledWidth < width || scaledHeight < height) && r.ensureScaledTarget(scaledWidth, scaledHeight)) {
    FrameOptions full = options;
    full.renderScale = 1.0f;
    full.hiddenRight =
        static_cast<int>(std::lround(static_cast<double>(std::clamp(options.hiddenRight, 0, width)) * scale));
    glBindFramebuffer(GL_FRAMEBUFFER, r.scaledFramebuffer);
    r.pixelScale = static_cast<float>(scaledHeight) / static_cast<float>(height);
    render(world, camera, scaledWidth, scaledHeight, full, overlay);
    r.pixelScale = 1.0f;
    glBindFramebuffer(GL_READ_FRAMEBUFFER, r.scaledFramebuffer);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(target));
    glViewport(0, 0, width, height);
    const int shown = width - std::clamp(options.hiddenRight, 0, width);
    if (shown < width) {  // the hidden strip gets the background colour, the blit spares it
      glClearColor(options.backgroundColour.r, options.backgroundColour.g, options.backgroundColour.b, 1.0f);
      glClear(GL_COLOR_BUFFER_BIT);
      glEnable(GL_SCISSOR_TEST);
      glScissor(0, 0, shown, height);
    }
    glBlitFramebuffer(0, 0, scaledWidth, scaledHeight, 0, 0, width, height, GL_COLOR_BUFFER_BIT, GL_LINEAR);
    glDisable(GL_SCISSOR_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, static_cast<GLuint>(target));
    return;
  }

  if (world.topologyVersion() != r.topologyVersion || r.cloths.size() != world.cloths().size()) {
    r.uploadTopology(world);
  }
  for (std::size_t c = 0; c < world.cloths().size(); ++c) {
    r.streamCloth(world.cloths()[c], r.cloths[c], options.strainMap);
  }
  // Colliders are drawn inside the thinnest cloth's thickness (collider_geometry.hpp).
  double inset = std::numeric_limits<double>::max();
  for (const sim::Cloth& cloth : world.cloths()) inset = std::min(inset, cloth.settings.thickness);
  if (world.cloths().empty()) inset = 0.0;
  r.colliderGeometry.clear();
  for (const sim::Collider& collider : world.colliders()) appendColliderGeometry(collider, r.colliderGeometry, inset);
  const auto colliderIndexCount = static_cast<GLsizei>(r.colliderGeometry.indices.size());
  if (colliderIndexCount > 0) {
    const ColliderGeometry& g = r.colliderGeometry;
    glBindVertexArray(r.colliderVao);
    glBindBuffer(GL_ARRAY_BUFFER, r.colliderPositions);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(g.positions.size() * sizeof(glm::vec3)), g.positions.data(),
                 GL_STREAM_DRAW);
    glBindBuffer(GL_ARRAY_BUFFER, r.colliderNormals);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(g.normals.size() * sizeof(glm::vec3)), g.normals.data(),
                 GL_STREAM_DRAW);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(g.indices.size() * sizeof(std::uint32_t)),
                 g.indices.data(), GL_STREAM_DRAW);
  }

  // The light looks at the scene from kTowardsLight with an orthographic box around it. One pass
  // over the particles serves it and FXAA's rectangle (the cloths alone where nothing else stands).
  glm::dvec3 clothLower, clothUpper;
  clothBounds(world, clothLower, clothUpper);
  glm::dvec3 lower = clothLower, upper = clothUpper;
  growToScene(world, lower, upper, 0.0);
  const glm::dvec3 centre = (lower + upper) * 0.5;
  const double radius = std::max(0.5, glm::length(upper - lower) * 0.5) * 1.1;
  const glm::mat4 lightView =
      glm::mat4(glm::lookAt(centre + kTowardsLight * (radius * 2.0), centre, glm::dvec3{0.0, 0.0, -1.0}));
  const glm::mat4 lightProjection =
      glm::ortho<float>(static_cast<float>(-radius), static_cast<float>(radius), static_cast<float>(-radius),
                        static_cast<float>(radius), 0.0f, static_cast<float>(radius * 4.0));
  const glm::mat4 lightViewProjection = lightProjection * lightView;

  glEnable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);  // cloth is two-sided
  glDisable(GL_BLEND);

  // Shadow pass, its depths pushed back by their slope: with the normal offset below, a crease
  // facing away from the light is not striped by its own shadow.
  glBindFramebuffer(GL_FRAMEBUFFER, r.shadowFramebuffer);
  r.resizeShadowMap(options.shadowMapSize);
  glViewport(0, 0, r.shadowMapSize, r.shadowMapSize);
  glClear(GL_DEPTH_BUFFER_BIT);
  glEnable(GL_POLYGON_OFFSET_FILL);
  glPolygonOffset(1.5f, 2.0f);
  glUseProgram(r.shadowProgram);
  setMatrix(r.shadowProgram, "lightViewProjection", lightViewProjection);
  for (const GpuCloth& gpu : r.cloths) {
    if (gpu.triangleIndexCount == 0) continue;
    glBindVertexArray(gpu.vao);
    glDrawElements(GL_TRIANGLES, gpu.triangleIndexCount, GL_UNSIGNED_INT, nullptr);
  }
  if (colliderIndexCount > 0) {
    glBindVertexArray(r.colliderVao);
    glDrawElements(GL_TRIANGLES, colliderIndexCount, GL_UNSIGNED_INT, nullptr);
  }
  glDisable(GL_POLYGON_OFFSET_FILL);
  // Two shadow-map texels of the light's box: how far off the surface shadows are looked up.
  const auto shadowNormalOffset = static_cast<float>(2.0 * 2.0 * radius / r.shadowMapSize);

  // Main pass, multisampled when the context can, or straight into the caller's framebuffer (FXAA
  // filters part of it afterwards).
  const double aspect = static_cast<double>(width) / height;
  const glm::mat4 viewProjection = camera.projection(aspect) * camera.view();
  const bool multisample = options.multisample && r.samples > 0;
  if (multisample) r.ensureSampleTarget(width, height);
  const bool fxaa = !(multisample && r.samples > 0) && options.fxaa;
  glBindFramebuffer(GL_FRAMEBUFFER, multisample && r.samples > 0 ? r.sampleFramebuffer : static_cast<GLuint>(target));
  glViewport(0, 0, width, height);
  glClearColor(options.backgroundColour.r, options.backgroundColour.g, options.backgroundColour.b, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  // What is drawn from here on stays left of the hidden strip: a software rasteriser skips the
  // tiles a scissor leaves out.
  const int shown = width - std::clamp(options.hiddenRight, 0, width);
  if (shown < width) {
    glEnable(GL_SCISSOR_TEST);
    glScissor(0, 0, shown, height);
  }
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, r.shadowTexture);

  const glm::vec3 eye(camera.eye());
  const glm::vec3 towardsLight(kTowardsLight);
  // Attributes a drawing does not stream keep one value for the whole draw (not the VAO's state
  // in GL: set here, before each kind of drawing that relies on them).
  glVertexAttrib3f(1, 0.0f, 1.0f, 0.0f);
  glVertexAttrib1f(2, 0.0f);
  glVertexAttrib2f(3, 0.0f, 0.0f);

  glUseProgram(r.clothProgram);
  setMatrix(r.clothProgram, "viewProjection", viewProjection);
  setMatrix(r.clothProgram, "lightViewProjection", lightViewProjection);
  setVec3(r.clothProgram, "lightDirection", towardsLight);
  setVec3(r.clothProgram, "eyePosition", eye);
  setVec3(r.clothProgram, "frontColour", options.frontColour);
  setVec3(r.clothProgram, "backColour", options.backColour);
  glUniform1i(uniform(r.clothProgram, "strainMap"), options.strainMap ? 1 : 0);
  glUniform1f(uniform(r.clothProgram, "strainScale"), std::max(1e-6f, options.strainScale));
  glUniform1i(uniform(r.clothProgram, "shadowMap"), 0);
  glUniform1i(uniform(r.clothProgram, "shadowRadius"), std::clamp(options.shadowSoftness - 1, 0, 2));
  glUniform1f(uniform(r.clothProgram, "shadowNormalOffset"), shadowNormalOffset);
  if (colliderIndexCount > 0) {
    glUniform1i(uniform(r.clothProgram, "twoSided"), 0);
    glUniform1i(uniform(r.clothProgram, "strainMap"), 0);
    glUniform1i(uniform(r.clothProgram, "woven"), 0);
    setVec3(r.clothProgram, "frontColour", options.colliderColour);
    glBindVertexArray(r.colliderVao);
    glDrawElements(GL_TRIANGLES, colliderIndexCount, GL_UNSIGNED_INT, nullptr);
    setVec3(r.clothProgram, "frontColour", options.frontColour);
    glUniform1i(uniform(r.clothProgram, "strainMap"), options.strainMap ? 1 : 0);
  }
  glUniform1i(uniform(r.clothProgram, "twoSided"), 1);
  glUniform1i(uniform(r.clothProgram, "woven"), options.woven ? 1 : 0);
  // Under a wireframe the surface sits a hair back, so its edges are not lost in it.
  if (options.wireframe) {
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(1.0f, 1.0f);
  }
  for (const GpuCloth& gpu : r.cloths) {
    if (gpu.triangleIndexCount == 0) continue;
    glBindVertexArray(gpu.vao);
    glDrawElements(GL_TRIANGLES, gpu.triangleIndexCount, GL_UNSIGNED_INT, nullptr);
  }
  glDisable(GL_POLYGON_OFFSET_FILL);

  // The table, only where the world has one: a scene without it is not drawn standing on a floor
  // that a cloth would fall through. Drawn after what stands on it, so the depth test spares the
  // shading of the table under them; only the part a shadow can reach looks the shadow up, and
  // only the part around where the camera looks has the grid.
  if (hasTable(world)) {
    const float extent = static_cast<float>(std::max(20.0, camera.distance * 10.0));
    const glm::vec3 middle(static_cast<float>(camera.target.x), 0.0f, static_cast<float>(camera.target.z));
    // The ground's filter reaches 6 texels (shaders/ground.frag), its linear lookup one more.
    const double filterReach = 8.0 * 2.0 * radius / r.shadowMapSize;
    const TableCells cells = tableCells(middle, extent, shadowFootprint(lower, upper, filterReach));
    glBindVertexArray(r.groundVao);
    glBindBuffer(GL_ARRAY_BUFFER, r.groundBuffer);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(cells.vertices.size() * sizeof(glm::vec3)),
                 cells.vertices.data(), GL_STREAM_DRAW);
    // The table sits a hair below y = 0 so cloth lying on it is never hidden by it.
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(1.0f, 1.0f);
    const GLuint programs[2] = {r.groundShadowedProgram, r.groundProgram};
    const GLsizei counts[2] = {cells.shadowed, static_cast<GLsizei>(cells.vertices.size()) - cells.shadowed};
    GLint first = 0;
    for (int kind = 0; kind < 2; ++kind) {
      const GLuint program = programs[kind];
      const GLsizei count = counts[kind];
      glUseProgram(program);
      setMatrix(program, "viewProjection", viewProjection);
      setMatrix(program, "lightViewProjection", lightViewProjection);
      setVec3(program, "eyePosition", eye);
      setVec3(program, "backgroundColour", options.backgroundColour);
      if (program == r.groundShadowedProgram) {
        glUniform1i(uniform(program, "shadowMap"), 0);
        glUniform1i(uniform(program, "shadowRadius"), std::clamp(options.shadowSoftness, 0, 3));
      }
      if (count > 0) glDrawArrays(GL_TRIANGLES, first, count);
      first += count;
    }
    glDisable(GL_POLYGON_OFFSET_FILL);
  }

  // Chains, pins and the overlay.
  glUseProgram(r.overlayProgram);
  setMatrix(r.overlayProgram, "viewProjection", viewProjection);
  glEnable(GL_PROGRAM_POINT_SIZE);
  glUniform1i(uniform(r.overlayProgram, "roundPoints"), 0);
  // A wireframe drawn at a fraction of the window's pixels is scaled up with it, each line as
  // wide as 1 / pixelScale of the window's: faded by pixelScale, it lays as much ink as at full
  // size (at half size the app's desk went near black under its lines, with moire). The picture's
  // own alpha stays as it was.
  glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
  for (const GpuCloth& gpu : r.cloths) {
    if (gpu.lineIndexCount == 0 || !(gpu.chain || options.wireframe)) continue;
    if (gpu.chain) {
      glVertexAttrib4f(1, 0.15f, 0.15f, 0.18f, 1.0f);
    } else {
      glVertexAttrib4f(1, 0.08f, 0.08f, 0.10f, r.pixelScale);
    }
    const bool faded = !gpu.chain && r.pixelScale < 1.0f;
    if (faded) glEnable(GL_BLEND);
    glBindVertexArray(gpu.lineVao);
    glDrawElements(GL_LINES, gpu.lineIndexCount, GL_UNSIGNED_INT, nullptr);
    if (faded) glDisable(GL_BLEND);
  }
  const float pixelsPerMetre =
      static_cast<float>(height / (2.0 * std::tan(camera.fieldOfView / 2.0) * camera.distance));
  if (options.particles) {  // every particle of a sheet as a dot, a few pixels wide
    glUniform1i(uniform(r.overlayProgram, "roundPoints"), 1);
    glUniform1f(uniform(r.overlayProgram, "pointSize"), 5.0f * r.pixelScale);
    glVertexAttrib4f(1, 0.95f, 0.95f, 0.95f, 1.0f);
    for (const GpuCloth& gpu : r.cloths) {
      if (gpu.chain) continue;
      glBindVertexArray(gpu.lineVao);
      glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(gpu.particles));
    }
  }
  r.overlayScratch.clear();
  for (const sim::Cloth& cloth : world.cloths()) {
    if (!cloth.rest.triangles.empty()) continue;  // beads of a chain
    for (const sim::Vec3& x : cloth.state.position)
      r.overlayScratch.push_back({glm::vec3(x), glm::vec4(options.frontColour, 1.0f)});
  }
  glUniform1i(uniform(r.overlayProgram, "roundPoints"), 1);
  glUniform1f(uniform(r.overlayProgram, "pointSize"),
              std::clamp(pixelsPerMetre * 0.03f, 4.0f * r.pixelScale, 24.0f * r.pixelScale));
  r.drawOverlay(r.overlayScratch, GL_POINTS);

  glDisable(GL_DEPTH_TEST);  // markers stay visible through the cloth
  glUniform1i(uniform(r.overlayProgram, "roundPoints"), 0);
  glEnable(GL_BLEND);  // a line's alpha fades it (a cut's seam)
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  r.drawOverlay(overlay.lines, GL_LINES);
  glDisable(GL_BLEND);
  r.overlayScratch.clear();
  if (options.showPins) {
    for (const sim::Cloth& cloth : world.cloths()) {
      for (std::size_t i = 0; i < cloth.state.position.size(); ++i) {
        if (cloth.state.pinned[i]) {  // pinned, not merely held by a finger
          r.overlayScratch.push_back({glm::vec3(cloth.state.position[i]), glm::vec4(0.95f, 0.85f, 0.25f, 1.0f)});
        }
      }
    }
  }
  r.overlayScratch.insert(r.overlayScratch.end(), overlay.points.begin(), overlay.points.end());
  glUniform1i(uniform(r.overlayProgram, "roundPoints"), 1);
  glUniform1f(uniform(r.overlayProgram, "pointSize"), 11.0f * r.pixelScale);
  r.drawOverlay(r.overlayScratch, GL_POINTS);
  glEnable(GL_DEPTH_TEST);

  glDisable(GL_SCISSOR_TEST);
  if (multisample && r.samples > 0) {  // resolve into the caller's framebuffer (the hidden strip too: cleared)
    glBindFramebuffer(GL_READ_FRAMEBUFFER, r.sampleFramebuffer);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(target));
    glBlitFramebuffer(0, 0, width, height, 0, 0, width, height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  }
  if (fxaa) {
    // Filtered over the part of the picture the cloths and colliders cover (elsewhere are the
    // table and the sky: no edges; a pass over the whole picture cost about 20 ms a frame at
    // 1280 x 800 on llvmpipe). That part, and the few pixels around it the filter reads (it reaches
    // 4 pixels along an edge, its linear reads one more), is copied out and filtered back in.
    const std::array<int, 4> covered = world.colliders().empty()
                                           ? coveredPixels(camera, width, height, clothLower, clothUpper)
                                           : coveredPixels(camera, width, height, lower, upper);
    constexpr int kReach = 6;
    const int x0 = std::max(covered[0] - kReach, 0), y0 = std::max(covered[1] - kReach, 0);
    const int x1 = std::min(covered[0] + covered[2] + kReach, width);
    const int y1 = std::min(covered[1] + covered[3] + kReach, height);
    glActiveTexture(GL_TEXTURE0);
    r.bindPictureTexture(width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, static_cast<GLuint>(target));
    if (x1 > x0 && y1 > y0) glCopyTexSubImage2D(GL_TEXTURE_2D, 0, x0, y0, x0, y0, x1 - x0, y1 - y0);
    glViewport(0, 0, width, height);
    glEnable(GL_SCISSOR_TEST);
    glScissor(covered[0], covered[1], std::max(0, std::min(covered[2], shown - covered[0])), covered[3]);
    glDisable(GL_DEPTH_TEST);
    glUseProgram(r.fxaaProgram);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, r.pictureColour);
    glUniform1i(uniform(r.fxaaProgram, "picture"), 0);
    glUniform2f(uniform(r.fxaaProgram, "texel"), 1.0f / static_cast<float>(width), 1.0f / static_cast<float>(height));
    glBindVertexArray(r.fullScreenVao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glDisable(GL_SCISSOR_TEST);
    glEnable(GL_DEPTH_TEST);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, static_cast<GLuint>(target));
  glBindVertexArray(0);
}

void Renderer::finish() const { glFinish(); }

std::vector<std::uint8_t> Renderer::readPixels(int width, int height) const {
  std::vector<std::uint8_t> pixels(static_cast<std::size_t>(width) * height * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, pixels.data());
  // GL's rows run bottom-up; images are written top-down.
  const std::size_t stride = static_cast<std::size_t>(width) * 4;
  std::vector<std::uint8_t> row(stride);
  for (int y = 0; y < height / 2; ++y) {
    std::uint8_t* a = pixels.data() + static_cast<std::size_t>(y) * stride;
    std::uint8_t* b = pixels.data() + static_cast<std::size_t>(height - 1 - y) * stride;
    std::memcpy(row.data(), a, stride);
    std::memcpy(a, b, stride);
    std::memcpy(b, row.data(), stride);
  }
  return pixels;
}

std::string Renderer::description() const {
  const auto text = [](GLenum name) {
    const auto* value = reinterpret_cast<const char*>(glGetString(name));
    return std::string(value ? value : "?");
  };
  return text(GL_VERSION) + ", " + text(GL_RENDERER);
}

int Renderer::uploadsOfTopology() const { return impl_->topologyUploads; }

}  // namespace drape::render
