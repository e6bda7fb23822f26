// Constraints by particle pair: by their lower particle, then their higher, whichever way round
// each is given (ties in the order they come). The seed's sweep takes each kind so (the lattice's
// own order), a tear's relaxation too, and the one order a cloth keeps its constraints in
// (orderConstraints) starts from it, so none of them depends on the order the lists come in.
#pragma once

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <utility>
#include <vector>

#include "drape/sim/cloth.hpp"

namespace drape::sim {

// Sorts `indices` (into `constraints`) by particle pair, stably.
inline void sortByPair(std::vector<std::uint32_t>& indices, const std::vector<DistanceConstraint>& constraints) {
  const auto pair = [&](std::uint32_t k) {
    const DistanceConstraint& c = constraints[k];
    return std::pair{std::min(c.a, c.b), std::max(c.a, c.b)};
  };
  std::stable_sort(indices.begin(), indices.end(), [&](std::uint32_t l, std::uint32_t r) { return pair(l) < pair(r); });
}

// The indices of every constraint of `constraints`, by particle pair.
inline std::vector<std::uint32_t> byParticlePair(const std::vector<DistanceConstraint>& constraints) {
  std::vector<std::uint32_t> indices(constraints.size());
  std::iota(indices.begin(), indices.end(), 0u);
  sortByPair(indices, constraints);
  return indices;
}

}  // namespace drape::sim
