// Issue 21's harder self-contact cases (assets/cases/): eight fingers crumpling, folding twice, a
// full twist (narrow and wide), a fast corner drag, a pinch lifted and lowered, a long strip dropped on the table, ten
// cloths dropped on each other. Each is played as drape-cli plays it, the intersecting triangle
// pairs counted every 5 steps, and must keep 0 at each; and each must do what it says to the cloth.
// Here at the desk's 32 x 32 (the strip and the ten cloths coarser, so the sanitizer build
// runs them in seconds); tools/self-contact-cases plays them at 48 x 48 and 96 x 96 and counts every
// step (docs/self-contact-cases.md).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "drape/sim/metrics.hpp"
#include "played.hpp"

namespace drape {
namespace {

using sim::Real;
using test::highest;
using test::kAssets;
using test::lowest;
using test::Played;
using test::spread;

constexpr Real kDistance = 0.005;  // the cases' self-contact distance, m

Played deskCase(const std::string& gesture, const std::vector<std::string>& overrides = {}) {
  return Played(Played::Files{}, kAssets / "scenes" / "desk.json", kAssets / "cases" / (gesture + ".json"), overrides);
}

TEST(HardCase, EightFingersCrumpleTheClothWithoutPassingItThroughItself) {
  Played played = deskCase("crumple-eight");
  const Real before = spread(played.cloth());
  played.until(1.85);  // just before they let go
  EXPECT_LT(spread(played.cloth()), 0.6 * before);
  EXPECT_GT(highest(played.cloth()), 0.03);  // it rose in folds between the fingers
  played.until();
  EXPECT_GT(lowest(played.cloth()), 0.0);
  EXPECT_EQ(played.worstIntersections, 0u) << "at step " << played.worstStep;
}

TEST(HardCase, FoldingTwiceLeavesFourLayersOnAQuarterOfTheTable) {
  Played played = deskCase("fold-twice");
  played.until();
  // The near half went over the far half, then the right half over the left: what was a 60 cm
  // square lies on the quarter x < 0, z < 0, four layers a self-contact distance apart.
  Real mostX = -1.0, mostZ = -1.0;
  for (const sim::Vec3& x : played.cloth().state.position) {
    mostX = std::max(mostX, x.x);
    mostZ = std::max(mostZ, x.z);
  }
  EXPECT_LT(mostX, 0.06);
  EXPECT_LT(mostZ, 0.06);
  EXPECT_GT(highest(played.cloth()), 0.005 + 2.5 * kDistance);
  EXPECT_GT(lowest(played.cloth()), 0.0);
  EXPECT_EQ(played.worstIntersections, 0u) << "at step " << played.worstStep;
}

TEST(HardCase, AFullTwistOfTheLiftedClothNeverPassesItThroughItself) {
  Played played = deskCase("twist");
  played.until(3.2);  // the right grip has turned a full turn, 8 cm in
  EXPECT_GT(lowest(played.cloth()), 0.0);
  played.until();
  EXPECT_GT(lowest(played.cloth()), 0.0);
  EXPECT_EQ(played.worstIntersections, 0u) << "at step " << played.worstStep;
}

TEST(HardCase, AWideTwistLoweredOntoTheTableNeverPassesItThroughItself) {
  // Gripped 40 cm wide and brought 18 cm in while it turns, the cloth is wound tight and most of
  // its particles are in contact: the dearest case by far (about 15 s in Release, played up to
  // 4.4 s, past where it failed). It failed there at 3 pairs from step 254, just after the fingers
  // let go, before the fail-safe found its pairs again where a zone's move left its boxes.
  Played played = deskCase("twist-wide");
  played.until(4.4);
  EXPECT_EQ(played.worstIntersections, 0u) << "at step " << played.worstStep;
  // Not checked: that nothing lies under the table. Lowered onto it, the fingers drag impact zones
  // (which move as the fingers in them do) through it: a particle ends 1.3 cm under it (issue 21).
}

TEST(HardCase, TheTearGestureOnAFinerClothNeverPassesItThroughItself) {
  // desk-tear's tear at 36 x 36 (spacing 17 mm, the scene's 5 mm distance). It passed through
  // itself at 38 of its 210 steps (1 pair; 8 of the steps this counts), through a hole in the
  // fail-safe's rounds: a pair still through after its zone moved was not tested again when another
  // pair's join ended the round and its own corners had not moved (docs/self-contact.md).
  Played played(Played::Files{}, kAssets / "scenes" / "desk-tear.json", kAssets / "gestures" / "tear.json",
                {"cloths.0.grid.columns=36", "cloths.0.grid.rows=36"});
  played.until();
  EXPECT_GE(played.cloth().pieceCount, 2u);
  EXPECT_EQ(played.worstIntersections, 0u) << "at step " << played.worstStep;
}

TEST(HardCase, TheTearGestureOnAFinerClothAt44NeverFoldsATriangleThroughItsNeighbour) {
  // The same at 44 x 44 (spacing 14 mm) with a distance of 0.3 spacing, as the bench keeps it. In a
  // violent step of the pull a triangle turned over onto its neighbour in the table's plane; two
  // triangles that share an edge made no pair, so nothing saw it, and when the crack later split
  // their edge the halves were counted: 172 of 210 steps with pairs (2 at most). The fail-safe now
  // sees a fold pass through, and the counter two neighbours lying flat on each other.
  Played played(Played::Files{}, kAssets / "scenes" / "desk-tear.json", kAssets / "gestures" / "tear.json",
                {"cloths.0.grid.columns=44", "cloths.0.grid.rows=44", "selfCollision.distance=0.0041860465"});
  played.until();
  EXPECT_GE(played.cloth().pieceCount, 2u);
  EXPECT_EQ(played.worstIntersections, 0u) << "at step " << played.worstStep;
}

TEST(HardCase, NoSeamOfTheTearAt64LiesFrozenOnTheTable) {
  // desk-tear's tear at 64 x 64 with the bench's distance (0.3 of the 9.5 mm spacing). A seam lying
  // flat on the table, its two sides' copies on the same points, was drawn by the sweeps into an
  // overlap of its sides in the table's plane, which the fail-safe sent back every substep after:
  // two small pieces lay frozen from step 30 to the end, a link between them 1.64 times its length
  // (docs/design.md). Now a seam's sides are pushed apart along the line between their triangles.
  // Frozen: a free link over 30 % long whose two particles are exactly where they were 60 steps
  // before the end; none may be.
  Played played(Played::Files{}, kAssets / "scenes" / "desk-tear.json", kAssets / "gestures" / "tear.json",
                {"cloths.0.grid.columns=64", "cloths.0.grid.rows=64", "selfCollision.distance=0.00286"});
  played.until(played.script.length() - 1.0);
  const std::vector<sim::Vec3> before = played.cloth().state.position;
  played.until();
  const sim::Cloth& cloth = played.cloth();
  ASSERT_GE(cloth.pieceCount, 2u);
  int frozen = 0;
  for (const sim::DistanceConstraint& c : cloth.rest.of(sim::ConstraintKind::stretch)) {
    const std::vector<sim::Vec3>& x = cloth.state.position;
    if (c.a >= before.size() || c.b >= before.size()) continue;  // made in the last second: moved
    if (cloth.state.inverseMass[c.a] == 0.0 || cloth.state.inverseMass[c.b] == 0.0) continue;
    const bool still = x[c.a] == before[c.a] && x[c.b] == before[c.b];
    if (still && glm::length(x[c.b] - x[c.a]) > 1.3 * c.restLength) ++frozen;
  }
  EXPECT_EQ(frozen, 0);
  EXPECT_EQ(played.worstIntersections, 0u) << "at step " << played.worstStep;
}

TEST(HardCase, ACornerDraggedAcrossAt5MetresASecondBunchesTheClothWithoutPassingItThroughItself) {
  Played played = deskCase("corner-drag");
  played.until(0.45);  // the corner has crossed (0.8 m in 0.15 s) and is still held
  // The light cloth is dragged along and bunches up behind the corner, layer over layer.
  EXPECT_GT(highest(played.cloth()), 0.03);
  played.until();
  // Let go, it falls open (the spring-back of a crumple, docs/design.md), on the table.
  EXPECT_GT(lowest(played.cloth()), 0.0);
  EXPECT_EQ(played.worstIntersections, 0u) << "at step " << played.worstStep;
}

TEST(HardCase, APinchLiftedAndLoweredOntoTheRestLiesOnItWithoutPassingThrough) {
  Played played = deskCase("pinch-lift-lower");
  played.until(1.8);
  EXPECT_GT(highest(played.cloth()), 0.2);
  played.until();
  // Lowered and let go, it lies as a pile, far under the 25 cm it was lifted to. How tall the pile
  // stands is chance: 8.6 to 13.1 cm with the self-contact distance moved by 1e-7 of itself
  // (docs/self-contact.md).
  EXPECT_LT(highest(played.cloth()), 0.15);
  EXPECT_GT(lowest(played.cloth()), 0.0);
  EXPECT_EQ(played.worstIntersections, 0u) << "at step " << played.worstStep;
}

TEST(HardCase, ALongStripDroppedOnTheTablePilesWithoutPassingThroughItself) {
  // 2 m by 10 cm at 4 x 80 (2.5 cm, the desk's spacing when it shipped at 24 x 24).
  Played played(Played::Files{}, kAssets / "cases" / "strip.json", {},
                {"cloths.0.grid.columns=4", "cloths.0.grid.rows=80"});
  played.until(played.scene.duration);
  // It fell 2 m onto itself: it lies piled, far less than its length high, and on the table.
  EXPECT_LT(highest(played.cloth()), 0.5);
  EXPECT_GT(lowest(played.cloth()), 0.0);
  EXPECT_EQ(played.worstIntersections, 0u) << "at step " << played.worstStep;
}

TEST(HardCase, TenClothsDroppedOnEachOtherLieInLayers) {
  std::vector<std::string> coarse;
  for (int k = 0; k < 10; ++k) {
    coarse.push_back("cloths." + std::to_string(k) + ".grid.columns=8");
    coarse.push_back("cloths." + std::to_string(k) + ".grid.rows=8");
  }
  Played played(Played::Files{}, kAssets / "cases" / "ten-cloths.json", {}, coarse);
  played.until(played.scene.duration);
  // Each landed on those below: the cloth that fell last lies above the one that fell first, and
  // their middles a layer apart at least.
  const auto middleHeight = [&](int c) {
    const sim::Cloth& cloth = played.cloth(c);
    return cloth.state.position[cloth.state.position.size() / 2].y;
  };
  EXPECT_GT(middleHeight(9), middleHeight(0) + kDistance);
  for (int c = 0; c < 10; ++c) EXPECT_GT(lowest(played.cloth(c)), 0.0) << "cloth " << c;
  EXPECT_EQ(played.worstIntersections, 0u) << "at step " << played.worstStep;
}

}  // namespace
}  // namespace drape
