#include "png.hpp"

#include <stb_image_write.h>

namespace drape::cli {

std::string encodePng(const std::vector<std::uint8_t>& rgba, int width, int height) {
  std::string bytes;
  const auto append = [](void* context, void* data, int size) {
    static_cast<std::string*>(context)->append(static_cast<const char*>(data), static_cast<std::size_t>(size));
  };
  stbi_write_png_to_func(append, &bytes, width, height, 4, rgba.data(), width * 4);
  return bytes;
}

}  // namespace drape::cli
