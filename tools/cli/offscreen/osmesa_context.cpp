// OSMesa: request a core profile, its version and depth bits explicitly, or Mesa hands out a 1.0
// compatibility context without depth (see ../shared/docs/references.md). This unit includes only
// OSMesa's header, never the GL loader, and the binary links libOSMesa and never libGL.
#include <GL/osmesa.h>

#include <vector>

#include "context.hpp"

namespace drape::cli {

namespace {

class OsmesaContext final : public OffscreenContext {
 public:
  OsmesaContext(int width, int height)
      : width_(width), height_(height), buffer_(static_cast<std::size_t>(width) * height * 4) {
    const int attributes[] = {OSMESA_FORMAT,
                              OSMESA_RGBA,
                              OSMESA_DEPTH_BITS,
                              24,
                              OSMESA_STENCIL_BITS,
                              0,
                              OSMESA_ACCUM_BITS,
                              0,
                              OSMESA_PROFILE,
                              OSMESA_CORE_PROFILE,
                              OSMESA_CONTEXT_MAJOR_VERSION,
                              3,
                              OSMESA_CONTEXT_MINOR_VERSION,
                              3,
                              0};
    context_ = OSMesaCreateContextAttribs(attributes, nullptr);
    if (!context_) throw render::RenderError("OSMesa cannot create a GL 3.3 core context");
    if (!OSMesaMakeCurrent(context_, buffer_.data(), GL_UNSIGNED_BYTE, width, height)) {
      OSMesaDestroyContext(context_);
      throw render::RenderError("OSMesa cannot make its context current");
    }
  }
  ~OsmesaContext() override { OSMesaDestroyContext(context_); }

  render::GetProcAddress procAddress() const override {
    return [](const char* name) { return reinterpret_cast<void*>(OSMesaGetProcAddress(name)); };
  }
  int width() const override { return width_; }
  int height() const override { return height_; }

 private:
  int width_, height_;
  std::vector<unsigned char> buffer_;
  OSMesaContext context_ = nullptr;
};

}  // namespace

std::unique_ptr<OffscreenContext> OffscreenContext::create(int width, int height) {
  return std::make_unique<OsmesaContext>(width, height);
}

}  // namespace drape::cli
