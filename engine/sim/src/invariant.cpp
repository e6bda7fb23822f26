#include "invariant.hpp"

#include <cstdio>
#include <cstdlib>

namespace drape::sim {

void invariantBroken(const char* condition, const char* why, const char* file, int line) {
  std::fprintf(stderr, "%s:%d: drape invariant broken: %s (%s)\n", file, line, condition, why);
  std::abort();
}

}  // namespace drape::sim
