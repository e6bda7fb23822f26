#include "drape/scene/fabric.hpp"

#include <array>

namespace drape::scene {

namespace {
// {areal density kg/m^2, bending rigidity N m, stretch N/m, shear N/m}
constexpr std::array<FabricPreset, 5> kPresets = {{
    {"silk",
     {0.045, 2.0e-6, 5.0e3, 30.0},
     "representative of a light habotai (45 g/m^2; KES-F bending 0.02 gf cm^2/cm), not one measured sample"},
    {"jersey",
     {0.187, 2.3e-5, 1.0e3, 30.0},
     "grey interlock knit, Wang, O'Brien and Ramamoorthi 2011 (density and bending measured)"},
    {"cotton", sim::Fabric{},
     "representative of a mid-weight cotton twill (200 g/m^2; KES-F bending 0.3 gf cm^2/cm), not one measured sample"},
    {"denim",
     {0.324, 6.4e-5, 5.0e4, 150.0},
     "11 oz denim, Wang, O'Brien and Ramamoorthi 2011 (density and bending measured)"},
    {"polyester",
     {0.128, 5.2e-5, 2.0e4, 100.0},
     "polyester tablecloth, Wang, O'Brien and Ramamoorthi 2011 (density and bending measured)"},
}};
}  // namespace

std::span<const FabricPreset> fabricPresets() { return kPresets; }

std::optional<sim::Fabric> fabricPreset(std::string_view name) {
  for (const FabricPreset& preset : kPresets) {
    if (preset.name == name) return preset.fabric;
  }
  return std::nullopt;
}

}  // namespace drape::scene
