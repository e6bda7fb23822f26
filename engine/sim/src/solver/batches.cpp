#include "solver/batches.hpp"

#include <algorithm>
#include <bit>

#include "invariant.hpp"
#include "solver/pair_order.hpp"

namespace drape::sim::batches {

namespace {

// One kind's constraints coloured greedily in the order they come: each takes the first colour
// neither of its particles has yet (colour 63, the sequential tail, is never marked used).
struct Colouring {
  std::vector<std::uint8_t> colourOf;
  std::array<std::uint32_t, kColours + 1> count{};  // count[c + 1]: constraints of colour c
};

Colouring colourAll(const std::vector<DistanceConstraint>& constraints, std::size_t particles) {
  Colouring result;
  std::vector<std::uint64_t> used(particles, 0);
  result.colourOf.resize(constraints.size());
  for (std::size_t k = 0; k < constraints.size(); ++k) {
    const DistanceConstraint& c = constraints[k];
    const std::uint64_t taken = used[c.a] | used[c.b];
    const std::uint32_t colour =
        std::min<std::uint32_t>(static_cast<std::uint32_t>(std::countr_one(taken)), kColours - 1);
    if (colour < kColours - 1) {
      used[c.a] |= std::uint64_t{1} << colour;
      used[c.b] |= std::uint64_t{1} << colour;
    }
    result.colourOf[k] = static_cast<std::uint8_t>(colour);
    ++result.count[colour + 1];
  }
  return result;
}

bool skipped(std::size_t kind, bool stretchToo) {
  return !stretchToo && kind == static_cast<std::size_t>(ConstraintKind::stretch);
}

}  // namespace

void order(ClothRest& rest, std::array<std::vector<std::uint32_t>, kConstraintKindCount>* source, bool stretchToo) {
  for (std::size_t kind = 0; kind < kConstraintKindCount; ++kind) {
    if (skipped(kind, stretchToo)) continue;
    std::vector<DistanceConstraint>& constraints = rest.constraints[kind];
    // First by particle pair, each from its lower particle: so the order does not depend on the
    // order they came in, nor on which way round each was given.
    const std::vector<std::uint32_t> byPair = byParticlePair(constraints);
    std::vector<DistanceConstraint> paired(constraints.size());
    for (std::size_t k = 0; k < byPair.size(); ++k) {
      const DistanceConstraint& c = constraints[byPair[k]];
      paired[k] = {std::min(c.a, c.b), std::max(c.a, c.b), c.restLength};
    }
    // Then coloured in that order, and put in runs by colour, in that order within a run.
    Colouring colouring = colourAll(paired, rest.particleCount());
    std::array<std::uint32_t, kColours + 1>& fill = colouring.count;
    for (std::uint32_t c = 0; c < kColours; ++c) fill[c + 1] += fill[c];
    // Into a list of their own, exactly as long (a list grown by push_back has room to spare).
    std::vector<DistanceConstraint> sorted(constraints.size());
    std::vector<std::uint32_t> from(constraints.size());  // where each ends up came from
    for (std::size_t k = 0; k < paired.size(); ++k) {
      const std::uint32_t to = fill[colouring.colourOf[k]]++;
      sorted[to] = paired[k];
      from[to] = byPair[k];
    }
    constraints.swap(sorted);
    if (source && (*source)[kind].size() == from.size()) {
      std::vector<std::uint32_t> moved(from.size());
      for (std::size_t k = 0; k < from.size(); ++k) moved[k] = (*source)[kind][from[k]];
      (*source)[kind].swap(moved);
    }
  }
}

Batches find(const ClothRest& rest, bool stretchToo) {
  Batches result;
  const std::size_t n = rest.particleCount();
  for (std::size_t kind = 0; kind < kConstraintKindCount; ++kind) {
    if (skipped(kind, stretchToo)) continue;
    const std::vector<DistanceConstraint>& constraints = rest.constraints[kind];
    // Coloured again in the order they are in, each keeps its colour (order is stable within a
    // colour, and a constraint's colour depends only on those before it of lower colour): so the
    // colours come in runs.
    Colouring colouring = colourAll(constraints, n);
    if constexpr (kCheckInvariants) {
      DRAPE_INVARIANT(std::is_sorted(colouring.colourOf.begin(), colouring.colourOf.end()),
                      "the constraints are in batch order (orderConstraints)");
    }
    std::array<std::uint32_t, kColours + 1>& count = colouring.count;
    for (std::uint32_t c = 0; c < kColours; ++c) count[c + 1] += count[c];
    std::vector<std::uint32_t>& start = result.start[kind];
    start.assign(1, 0);
    for (std::uint32_t c = 1; c <= kColours; ++c) {
      if (count[c] != start.back()) start.push_back(count[c]);  // empty colours make no batch
    }
    result.sequentialTail[kind] = count[kColours] != count[kColours - 1];
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
  }
  return result;
}

}  // namespace drape::sim::batches
