// orderConstraints (drape/sim/cloth.hpp): the one order a cloth's constraints are kept in, made of
// the lines' order for stretch and the batches' for shear and bend.
#include "drape/sim/cloth.hpp"
#include "solver/batches.hpp"
#include "solver/lines.hpp"

namespace drape::sim {

void orderConstraints(ClothRest& rest, std::array<std::vector<std::uint32_t>, kConstraintKindCount>* source,
                      std::vector<float>* stretchTension) {
  batches::order(rest, source, false);
  lines::order(rest, source ? &(*source)[static_cast<std::size_t>(ConstraintKind::stretch)] : nullptr, stretchTension);
}

}  // namespace drape::sim
