// The OpenGL 3.3 core renderer. It knows nothing of SDL or OSMesa: whoever made the context hands
// it a get-proc-address function, and the same code draws in a window and off-screen.
//
// What it draws: each cloth as a smooth two-sided lit surface (normals recomputed every frame, a
// front and a back colour with a woven gingham printed in the cloth's rest coordinates, or a
// strain colour map; optionally its triangles' edges and its particles); a chain as links and
// beads; the table (y = 0), where the world has one, with a soft shadow of the cloth; colliders as
// grey solids inside the cloth's thickness; pins as round markers; and an overlay of finger rings
// and strokes. Frames are multisampled and resolved into the framebuffer that was bound on entry,
// or, without multisampling, drawn into a picture that FXAA filters into it. Positions and normals
// stream every frame into buffers allocated once; index buffers are re-uploaded only when the
// world's topology version changes.
#pragma once

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "drape/render/camera.hpp"
#include "drape/sim/world.hpp"

namespace drape::render {

class RenderError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

using GetProcAddress = void* (*)(const char* name);

struct OverlayVertex {
  glm::vec3 position;
  glm::vec4 colour;
};

// Markers drawn over the scene, unlit and always visible.
struct Overlay {
  std::vector<OverlayVertex> points;  // round markers
  std::vector<OverlayVertex> lines;   // pairs of vertices

  // A ring of `radius` around `centre` in the plane with normal `normal` (a finger).
  void addRing(glm::dvec3 centre, double radius, glm::dvec3 normal, glm::vec4 colour, int segments = 48);
  // A polyline through `points` (an outline being drawn).
  void addStroke(const std::vector<glm::dvec3>& points, glm::vec4 colour);
};

struct FrameOptions {
  bool strainMap = false;     // colour by stretch instead of the front/back colours
  float strainScale = 0.10f;  // strain shown fully red
  bool showPins = true;
  bool woven = true;         // a gingham check and a weave printed on the cloth (not with strainMap)
  bool wireframe = false;    // the triangles' edges over the surface
  bool particles = false;    // every particle as a dot
  bool multisample = true;   // 4x MSAA when the context has it
  bool fxaa = true;          // without MSAA: FXAA, one cheap filter pass over the picture
  int shadowSoftness = 3;    // 0..3: shadow filter taps (2s+1)^2 on the table; a software renderer pays for each
  int shadowMapSize = 2048;  // texels a side, 256..4096
  // The scene is drawn at this fraction of the picture's width and height and stretched over it
  // (dynamic resolution: a software renderer pays per pixel); 1 draws every pixel. Clamped to
  // [kLowestRenderScale, 1].
  float renderScale = 1.0f;
  static constexpr float kLowestRenderScale = 0.5f;
  // Pixels at the picture's right edge that something opaque drawn afterwards covers (the app's
  // panel): the scene is not drawn there, only the background colour.
  int hiddenRight = 0;
  glm::vec3 frontColour{0.85f, 0.33f, 0.18f};
  glm::vec3 backColour{0.20f, 0.52f, 0.62f};
  glm::vec3 backgroundColour{0.62f, 0.66f, 0.70f};
  glm::vec3 colliderColour{0.55f, 0.56f, 0.60f};
};

// The strain colour map, as shaders/cloth.frag computes it (keep the two the same): blue at rest,
// green at a third of `scale`, yellow at two thirds, red at `scale` and beyond; for legends.
glm::vec3 strainColour(float strain, float scale);

class Renderer {
 public:
  // Needs a current context of at least GL 3.3 core. Throws RenderError if GL cannot be loaded or
  // a shader does not compile.
  explicit Renderer(GetProcAddress getProcAddress);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Draws one frame into the framebuffer bound now, over a viewport of width x height pixels.
  void render(const sim::World& world, const Camera& camera, int width, int height, const FrameOptions& options,
              const Overlay& overlay = {});

  // Waits until GL has drawn everything asked of it (glFinish): for timing what drawing costs.
  void finish() const;

  // RGBA8 pixels of the bound read framebuffer, top row first.
  std::vector<std::uint8_t> readPixels(int width, int height) const;

  std::string description() const;  // "4.5 (Core Profile) Mesa ..., llvmpipe ..."
  int uploadsOfTopology() const;    // how often index buffers were (re)built: for tests

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The box around every particle and finite collider of the world (and the table at y = 0 under it);
// with `ahead` (s), each moving collider also where its velocity takes it in that time.
void sceneBounds(const sim::World& world, glm::dvec3& lower, glm::dvec3& upper, double ahead = 0.0);
// The box around every particle of the world; lower > upper where there is none.
void clothBounds(const sim::World& world, glm::dvec3& lower, glm::dvec3& upper);

}  // namespace drape::render
