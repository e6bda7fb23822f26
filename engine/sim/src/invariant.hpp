// The engine's invariants, checked in the checking build and compiled out of the others.
//
// DRAPE_INVARIANT(condition, why) states what must hold at that point (a plan up to date before
// the sweeps, a batch whose constraints share no particle). Where DRAPE_CHECK_INVARIANTS is
// defined (the CMake option of that name; on in the sanitizer build tools/test runs) a broken one
// prints the condition, the reason and where, and aborts. Elsewhere the condition is not evaluated
// (it still names what it reads, so nothing goes unused) and costs nothing.
#pragma once

namespace drape::sim {

// For checks longer than a condition: `if constexpr (kCheckInvariants) { ... }`.
#if defined(DRAPE_CHECK_INVARIANTS)
inline constexpr bool kCheckInvariants = true;
#else
inline constexpr bool kCheckInvariants = false;
#endif

[[noreturn]] void invariantBroken(const char* condition, const char* why, const char* file, int line);

}  // namespace drape::sim

#if defined(DRAPE_CHECK_INVARIANTS)
#define DRAPE_INVARIANT(condition, why) \
  ((condition) ? static_cast<void>(0) : ::drape::sim::invariantBroken(#condition, why, __FILE__, __LINE__))
#else
#define DRAPE_INVARIANT(condition, why) static_cast<void>(sizeof((condition) ? 1 : 0))
#endif
