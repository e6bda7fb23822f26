// Batches: each kind's constraints in an order where they come in runs ("batches") no two of
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

// Puts each kind's constraints in batch order, in place, the stretch constraints only with
// `stretchToo`: by particle pair (each turned to run from its lower particle), coloured greedily in
// that order, then in runs by colour, by pair within a run. So the order depends only on which
// constraints there are, not on the order they came in. Part of the one order a cloth's constraints
// are kept in (orderConstraints, cloth.hpp; it leaves stretch to the lines). Putting them in order
// again changes nothing. `source`, if given (a torn cloth's Topology::source: per constraint, the
// recipe it came from), moves with them.
void order(ClothRest& rest, std::array<std::vector<std::uint32_t>, kConstraintKindCount>* source, bool stretchToo);

// The batches of constraints already in batch order (order): each kind's, the stretch
// constraints' only with `stretchToo` (else none).
Batches find(const ClothRest& rest, bool stretchToo);

}  // namespace drape::sim::batches
