// An off-screen OpenGL context for drape-cli's pictures. Today it is OSMesa (Mesa's software
// rasteriser, no display needed); Mesa 25.1 removed OSMesa, and EGL surfaceless is the successor:
// a second implementation of this interface, chosen in create(), is all that change needs.
#pragma once

#include <memory>

#include "drape/render/renderer.hpp"

namespace drape::cli {

class OffscreenContext {
 public:
  virtual ~OffscreenContext() = default;
  virtual render::GetProcAddress procAddress() const = 0;
  virtual int width() const = 0;
  virtual int height() const = 0;

  // A current GL 3.3 core context with a width x height RGBA framebuffer and a 24-bit depth
  // buffer. Throws render::RenderError if none can be made.
  static std::unique_ptr<OffscreenContext> create(int width, int height);
};

}  // namespace drape::cli
