// PNG encoding through Debian's stb_image_write.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace drape::cli {

// RGBA8 pixels, top row first, as the bytes of a PNG file.
std::string encodePng(const std::vector<std::uint8_t>& rgba, int width, int height);

}  // namespace drape::cli
