// Batches: each kind's constraints reordered so that they come in runs ("batches") no two of
// whose constraints share a particle (greedy graph colouring). Within a batch the order does not
// matter, so a batch can be cut among threads and still give the same result bit for bit; and
// consecutive constraints never wait on each other, so even one core overlaps their square roots
// and divisions. On a lattice a kind takes four to six batches.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "drape/sim/cloth.hpp"

namespace drape::sim::batches {

// The last batch may be "sequential": constraints that found no free colour among the first 63
// (only a particle with more than 63 constraints of one kind can cause that); it runs on one thread.
inline constexpr std::uint32_t kColours = 64;

struct Batches {
  // Per kind: batch b holds constraints [start[b], start[b + 1]); the last batch is sequential if
  // sequentialTail is set.
  std::array<std::vector<std::uint32_t>, kConstraintKindCount> start;
  std::array<bool, kConstraintKindCount> sequentialTail{};
};

// Reorders rest.constraints in place (stable within a batch) and returns the batches. Applying it
// to constraints it has already ordered changes nothing. `source`, if given (a torn cloth's
// Topology::source: per constraint, the recipe it came from), is reordered along with them.
// Without `stretchToo` the stretch constraints are left as they are, with no batches (the lines
// order and solve them).
Batches colour(ClothRest& rest, std::array<std::vector<std::uint32_t>, kConstraintKindCount>* source = nullptr,
               bool stretchToo = true);

}  // namespace drape::sim::batches
