#pragma once
// A picture kept from frame to frame: drawn into only when what it shows changed, and otherwise
// copied onto the screen (a straight copy, no shading: on a software renderer much cheaper than
// drawing the same pixels again). The app keeps its panel in one. Needs the GL functions a
// Renderer loaded, in the context it was made in.
#include <cstdint>

namespace drape::render {

class Layer {
 public:
  Layer() = default;
  ~Layer();
  Layer(const Layer&) = delete;
  Layer& operator=(const Layer&) = delete;

  // Whether the layer holds a picture drawn with this key at this size.
  bool holds(std::uint64_t key, int width, int height) const {
    return drawn_ && key == key_ && width == width_ && height == height_;
  }
  // Binds the layer (width x height pixels of colour, depth and stencil, cleared; the colour to
  // transparent black) for drawing; end()
  // binds again the framebuffer that was bound, and records the key. False where the context
  // cannot make the layer (then nothing is bound and the caller draws as it would without one).
  bool begin(std::uint64_t key, int width, int height);
  void end();
  // Copies the rectangle (x, y, w, h in pixels from the bottom left, clipped to the layer) to the
  // same place in the framebuffer bound now.
  void copyTo(int x, int y, int w, int h) const;
  // Forgets the picture: the next holds() is false.
  void invalidate() { drawn_ = false; }

 private:
  unsigned framebuffer_ = 0, colour_ = 0, depth_ = 0;
  int previous_ = 0, previousViewport_[4] = {0, 0, 0, 0};
  int width_ = 0, height_ = 0;
  std::uint64_t key_ = 0;
  bool drawn_ = false, complete_ = false;
};

}  // namespace drape::render
