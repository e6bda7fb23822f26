// Fabrics by name: the presets a scene's "fabric" key, the lab (drape-cli fabric) and the app's
// picker offer. Where the numbers come from is in docs/fabric.md.
#pragma once

#include <optional>
#include <span>
#include <string_view>

#include "drape/sim/settings.hpp"

namespace drape::scene {

struct FabricPreset {
  std::string_view name;
  sim::Fabric fabric;
  std::string_view source;  // one line: measured or representative, and by whom
};

// Every preset, shortest bending length (B / (rho g))^(1/3) first.
std::span<const FabricPreset> fabricPresets();
std::optional<sim::Fabric> fabricPreset(std::string_view name);

}  // namespace drape::scene
