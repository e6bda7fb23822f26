#include "solver/batches.hpp"

#include <algorithm>
#include <bit>

#include "invariant.hpp"

namespace drape::sim::batches {

Batches colour(ClothRest& rest, std::array<std::vector<std::uint32_t>, kConstraintKindCount>* source, bool stretchToo) {
  Batches result;
  const std::size_t n = rest.particleCount();
  std::vector<std::uint64_t> used(n);
  std::vector<std::uint8_t> colourOf;
  std::vector<DistanceConstraint> sorted;
  for (std::size_t kind = 0; kind < kConstraintKindCount; ++kind) {
    if (!stretchToo && kind == static_cast<std::size_t>(ConstraintKind::stretch)) continue;
    std::vector<DistanceConstraint>& constraints = rest.constraints[kind];
    std::fill(used.begin(), used.end(), 0);
    colourOf.resize(constraints.size());
    std::array<std::uint32_t, kColours + 1> count{};
    for (std::size_t k = 0; k < constraints.size(); ++k) {
      const DistanceConstraint& c = constraints[k];
      const std::uint64_t taken = used[c.a] | used[c.b];
      // Colour 63 is the sequential tail: it is never marked used.
      const std::uint32_t colour =
          std::min<std::uint32_t>(static_cast<std::uint32_t>(std::countr_one(taken)), kColours - 1);
      if (colour < kColours - 1) {
        used[c.a] |= std::uint64_t{1} << colour;
        used[c.b] |= std::uint64_t{1} << colour;
      }
      colourOf[k] = static_cast<std::uint8_t>(colour);
      ++count[colour + 1];
    }
    for (std::uint32_t c = 0; c < kColours; ++c) count[c + 1] += count[c];
    std::vector<std::uint32_t>& start = result.start[kind];
    start.assign(1, 0);
    for (std::uint32_t c = 1; c <= kColours; ++c) {
      if (count[c] != start.back()) start.push_back(count[c]);  // empty colours make no batch
    }
    result.sequentialTail[kind] = count[kColours] != count[kColours - 1];
    sorted.resize(constraints.size());
    std::array<std::uint32_t, kColours + 1> fill = count;
    std::vector<std::uint32_t> to(constraints.size());
    for (std::size_t k = 0; k < constraints.size(); ++k) {
      to[k] = fill[colourOf[k]]++;
      sorted[to[k]] = constraints[k];
    }
    constraints.swap(sorted);
    if constexpr (kCheckInvariants) {
      // What lets a batch be shared among threads: no particle twice in it (but the tail).
      std::vector<std::uint32_t> lastBatch(n, UINT32_MAX);
      for (std::size_t b = 0; b + 1 < start.size(); ++b) {
        if (result.sequentialTail[kind] && b + 2 == start.size()) break;
        for (std::uint32_t k = start[b]; k < start[b + 1]; ++k) {
          for (const ParticleIndex p : {constraints[k].a, constraints[k].b}) {
            DRAPE_INVARIANT(lastBatch[p] != b, "a batch's constraints share no particle");
            lastBatch[p] = static_cast<std::uint32_t>(b);
          }
        }
      }
    }
    if (source && (*source)[kind].size() == to.size()) {
      std::vector<std::uint32_t> moved(to.size());
      for (std::size_t k = 0; k < to.size(); ++k) moved[to[k]] = (*source)[kind][k];
      (*source)[kind].swap(moved);
    }
  }
  return result;
}

}  // namespace drape::sim::batches
