// Which pins each particle is tethered to (engine/sim/src/solver/tethers.cpp).
#include <gtest/gtest.h>

#include <algorithm>

#include <glm/geometric.hpp>

#include "drape/sim/world.hpp"
#include "solver/tethers.hpp"
#include "world_builder.hpp"

namespace drape::sim {
namespace {

using Tether = SolverScratch::Tethers::Tether;

// What the tethers must be, found the slow way: every pin of the particle's piece, nearest first
// (ties to the lower index), the first kMaxTethersPerParticle of them, in index order.
std::vector<Tether> nearestByBruteForce(const Cloth& cloth) {
  std::vector<Tether> tethers;
  for (std::size_t i = 0; i < cloth.state.position.size(); ++i) {
    if (cloth.state.pinned[i]) continue;
    std::vector<std::pair<Real, ParticleIndex>> pins;
    for (const ParticleIndex p : cloth.tetherPins) {
      if (!cloth.state.pinned[p] || cloth.pieceOf(p) != cloth.pieceOf(i)) continue;
      const Vec3 d = cloth.rest.restPosition(p) - cloth.rest.restPosition(i);
      pins.push_back({glm::dot(d, d), p});
    }
    std::sort(pins.begin(), pins.end());
    pins.resize(std::min(pins.size(), kMaxTethersPerParticle));
    std::sort(pins.begin(), pins.end(), [](const auto& x, const auto& y) { return x.second < y.second; });
    for (const auto& [distance2, p] : pins) {
      tethers.push_back({static_cast<ParticleIndex>(i), p,
                         toRestLengthAtLeast(glm::distance(cloth.rest.restPosition(i), cloth.rest.restPosition(p)))});
    }
  }
  return tethers;
}

void expectSame(const std::vector<Tether>& got, const std::vector<Tether>& want) {
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t k = 0; k < got.size(); ++k) {
    EXPECT_EQ(got[k].particle, want[k].particle) << k;
    EXPECT_EQ(got[k].pin, want[k].pin) << k;
    EXPECT_EQ(got[k].length, want[k].length) << k;
  }
}

// A sheet with its whole top row pinned, and a few pins scattered over it.
WorldSettings pinnedAlongTheTop(int n) {
  WorldSettings settings = test::hangingSheet(n, 1, 1);
  settings.solver.tethers = true;
  settings.cloths[0].pins.clear();
  for (int column = 0; column < n; ++column) settings.cloths[0].pins.push_back({column, 0, std::nullopt});
  for (const int k : {3, 7, 11}) settings.cloths[0].pins.push_back({(k * 5) % n, (k * 3) % n, std::nullopt});
  return settings;
}

TEST(Tethers, EachParticleIsTiedToTheNearestPinsOfItsPieceAtMost) {
  const int n = 30;
  World world(pinnedAlongTheTop(n));
  const Cloth& cloth = world.cloths()[0];
  expectSame(nearestPinTethers(cloth), nearestByBruteForce(cloth));
  const std::size_t free = cloth.state.position.size() - (n + 3);
  EXPECT_EQ(world.tetherCount(), kMaxTethersPerParticle * free);
  // Cut in two across the middle: the lower half has only its scattered pins (fewer than the most,
  // all of them), the upper its own; none across the cut.
  ASSERT_GE(world.cut(Vec3{-0.7, 1.5, 0.01}, Vec3{0.7, 1.5, 0.01}, Vec3{0.0, -1.0, 0.0}), 1);
  ASSERT_EQ(cloth.pieceCount, 2u);
  expectSame(nearestPinTethers(cloth), nearestByBruteForce(cloth));
  expectSame(nearestPinTethers(cloth), [&] {
    SolverScratch::Tethers runs;
    runs.assign(nearestPinTethers(cloth));
    return runs.list();
  }());
}

TEST(Tethers, AWideSheetPinnedAlongItsTopKeepsAFewTethersAParticle) {
  // Every particle tied to every pin: 256 x 255 x 256 = 16.7 million tethers here (and on a
  // 512 x 512 sheet 2.15 GB and 8.5 s a step). Tied to the nearest: four each.
  const int n = 256;
  WorldSettings settings = pinnedAlongTheTop(n);
  settings.cloths[0].pins.resize(n);
  World world(settings);
  EXPECT_EQ(world.tetherCount(), kMaxTethersPerParticle * static_cast<std::size_t>(n * (n - 1)));
  ASSERT_EQ(world.run(2), StepStatus::ok);
}

}  // namespace
}  // namespace drape::sim
