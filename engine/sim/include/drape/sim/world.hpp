// The world: cloths, their settings, and the fixed-step pipeline that advances them.
//
// Stepping is deterministic: the same settings and the same calls give bit-identical states.
// Nothing non-finite escapes: after every step a guard checks every position; the first step
// that produced a non-finite or runaway value is recorded, the state is restored to what it was
// before that step, and the world refuses to step further. The caller decides what to tell whom.
#pragma once

#include <compare>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <iterator>
#include <memory>
#include <optional>
#include <ranges>
#include <vector>

#include "drape/sim/cloth.hpp"
#include "drape/sim/pipeline.hpp"
#include "drape/sim/settings.hpp"
#include "drape/sim/state.hpp"
#include "drape/sim/topology.hpp"

namespace drape::sim {

struct Cloth {
  ClothRest rest;
  ParticleState state;
  ClothSettings settings;
  Topology topology;  // built the first time the cloth tears or is cut
  // Per particle: which connected piece it belongs to (0, 1, ... in order of the lowest particle).
  // Empty while the cloth is in one piece: a cloth that is never torn or cut pays nothing for it.
  std::vector<std::uint32_t> piece;
  std::uint32_t pieceCount = 1;
  std::uint32_t pieceOf(std::size_t particle) const { return piece.empty() ? 0 : piece[particle]; }
  // The pins the tethers (solver.tethers) go to: the cloth's own, as it was built (ClothSettings::
  // pins), less those taken out since. A particle pinned by hand gets none: it may have been put
  // anywhere, where its rest distances cannot all hold.
  std::vector<ParticleIndex> tetherPins;
  // With a stretch target (solver.maxStretch): each stretch constraint's tension times h^2 (N s^2,
  // negative when pulled) as the line solve last summed it, over a substep's first sweep, which
  // the next substep's geometric stiffness reads. It is state carried from step to step, like the
  // previous positions: a copy (undo, a snapshot) goes on bit for bit with it. Kept in the order of
  // the stretch constraints (moved with them where orderConstraints orders them); empty where the solve
  // keeps none, and emptied where the cloth is torn or cut. Single precision: it only scales the
  // geometric stiffness.
  std::vector<float> stretchTension;
  // m: the spacing the cloth was made with (topology::madeSpacing), kept by its copies and
  // snapshots, whose settings no longer hold the drawn mesh it came from: the scale cuts snap at
  // and a fabric's substeps follow (substepsFor). 0 only for a cloth read from an older snapshot,
  // until a world takes it (restoreCloths works it out).
  Real spacing = 0.0;
  // s: the substep its previous positions lie behind its positions by (x - x_prev = v h), so that
  // a copy put back into a world whose substep has changed since (World::restoreCloths: a redo
  // that brings back the finest fabric) is rescaled to it. 0: the world's substep.
  Real historyStep = 0.0;
};

// A finger holding particles (the seed's sticky finger). Each held particle keeps its offset from
// the finger and moves rigidly with it; the world moves it, no force or constraint does.
struct FingerGrip {
  int cloth;
  ParticleIndex particle;
  Vec3 offset;  // m, from the finger
};

struct Finger {
  int id = 0;          // the caller's name for it
  Vec3 position{0.0};  // m, where it is now
  Vec3 target{0.0};    // m, where the next step takes it (along a straight line)
  Real radius = 0.0;   // m
  std::vector<FingerGrip> grips;
};

struct Divergence {
  std::int64_t step;  // 1-based number of the step that produced the bad value
  int cloth;          // which cloth
  ParticleIndex particle;
};

enum class StepStatus : std::uint8_t { ok, diverged };

// What self-contact between triangles (selfCollision.method triangles) did.
struct SelfContactStats {
  std::int64_t pairs = 0;          // last substep: vertex-triangle and edge-edge pairs the broad phase found
  std::int64_t pushed = 0;         // last substep: of them, pushed apart
  std::int64_t tested = 0;         // since the world was made: pairs not proven apart, tested exactly
  std::int64_t zoned = 0;          // since made: particles the fail-safe moved as one body with others (a zone)
  std::int64_t fallbacks = 0;      // since made: substeps where a zone stayed at x0, or all went back there
  std::int64_t searches = 0;       // since made: broad-phase searches (the pairs found anew)
  std::int64_t refreshes = 0;      // since made: the pairs of particles that strayed found anew, not all
  std::int64_t triangleTests = 0;  // since made: exact triangle-triangle tests by the fail-safe
  std::int64_t boxTests = 0;       // since made: boxes the broad phase compared (its tree's nodes and primitives)
};

class Workers;
struct ClothWork;  // src/cloth_work.hpp: what a world keeps for one cloth alone
struct SelfCollisionScratch;
class PartClock;
namespace contact {
class SelfContact;
}

// Bytes a world keeps (every array's capacity), by what they are for.
struct MemoryUse {
  std::size_t state = 0;        // positions, previous positions, velocities, masses, pins
  std::size_t rest = 0;         // rest positions and triangles
  std::size_t constraints = 0;  // stretch, shear, bend
  std::size_t topology = 0;     // tearing's adjacency and recipes (once torn or cut), pieces
  std::size_t tethers = 0;
  std::size_t lines = 0;   // the fast sweep's rows and columns
  std::size_t solver = 0;  // scratch: contacts, wind, multipliers, batches, line solves, fingers, self-collision
  std::size_t guard = 0;   // the copy of the last good positions a divergence goes back to
  std::size_t total() const { return state + rest + constraints + topology + tethers + lines + solver + guard; }
};

// A cloth in a world, with what the world keeps for that cloth alone (its solver's plan and working
// arrays, which of its particles fingers hold, the guard's copy of its positions): one record, so
// that nothing kept per cloth can fall out of step with the cloths as they are added, removed,
// restored, torn or cut.
struct ClothRecord {
  Cloth cloth;
  std::unique_ptr<ClothWork> work;  // never null

  explicit ClothRecord(Cloth cloth);
  ClothRecord(ClothRecord&&) noexcept;
  ClothRecord& operator=(ClothRecord&&) noexcept;
  ~ClothRecord();
};

// A world's cloths, in order (World::cloths()): read like a vector of them, copied with copy().
// It reads the world's records, so it sees the cloths as they are, and is valid while the world
// is; a reference to a cloth or an iterator from it is not, once a cloth is added, removed or
// restored (as for a vector).
class ClothList {
 public:
  class Iterator {
   public:
    using iterator_category = std::random_access_iterator_tag;
    using value_type = Cloth;
    using difference_type = std::ptrdiff_t;
    using pointer = const Cloth*;
    using reference = const Cloth&;
    Iterator() = default;
    explicit Iterator(std::vector<ClothRecord>::const_iterator at) : at_(at) {}
    reference operator*() const { return at_->cloth; }
    pointer operator->() const { return &at_->cloth; }
    reference operator[](difference_type k) const { return at_[k].cloth; }
    Iterator& operator++() { return ++at_, *this; }
    Iterator operator++(int) { return Iterator(at_++); }
    Iterator& operator--() { return --at_, *this; }
    Iterator operator--(int) { return Iterator(at_--); }
    Iterator& operator+=(difference_type k) { return at_ += k, *this; }
    Iterator& operator-=(difference_type k) { return at_ -= k, *this; }
    friend Iterator operator+(Iterator i, difference_type k) { return i += k; }
    friend Iterator operator+(difference_type k, Iterator i) { return i += k; }
    friend Iterator operator-(Iterator i, difference_type k) { return i -= k; }
    friend difference_type operator-(const Iterator& l, const Iterator& r) { return l.at_ - r.at_; }
    friend auto operator<=>(const Iterator& l, const Iterator& r) = default;
    friend bool operator==(const Iterator& l, const Iterator& r) = default;

   private:
    std::vector<ClothRecord>::const_iterator at_;
  };

  explicit ClothList(const std::vector<ClothRecord>& records) : records_(&records) {}
  std::size_t size() const { return records_->size(); }
  bool empty() const { return records_->empty(); }
  const Cloth& operator[](std::size_t i) const { return (*records_)[i].cloth; }
  const Cloth& at(std::size_t i) const { return records_->at(i).cloth; }
  const Cloth& front() const { return records_->front().cloth; }
  const Cloth& back() const { return records_->back().cloth; }
  Iterator begin() const { return Iterator(records_->begin()); }
  Iterator end() const { return Iterator(records_->end()); }
  // The cloths as they are now, each copied (to keep, to change, to restore later).
  std::vector<Cloth> copy() const;

 private:
  const std::vector<ClothRecord>* records_;
};

inline constexpr int kMaxThreads = 64;
// Fingers down at once: more hands than a table has room for, few enough that what compares every
// finger with every other (pinch-lift) stays cheap.
inline constexpr int kMaxFingers = 256;

// How many lines the full Newton line step (with solver.maxStretch) solves side by side on this
// CPU: 8 where it has AVX (chosen at run time, in the portable build too), else 4. The results are
// the same bit for bit either way.
int stiffSolveLanes();

class World {
 public:
  // Throws std::invalid_argument if the settings are outside what the engine accepts.
  explicit World(WorldSettings settings);
  ~World();
  World(World&&) noexcept;
  World& operator=(World&&) noexcept;

  // How many threads step the world (1 at first). The result is the same bit for bit whatever the
  // number. Throws std::invalid_argument outside 1..kMaxThreads.
  void setThreads(int threads);
  int threads() const;
  // Bytes the world keeps for its cloths (every array's capacity: state, rest data, constraints,
  // solver scratch, the guard's copy of the last good positions).
  std::size_t memoryBytes() const;
  MemoryUse memoryUse() const;
  std::size_t tetherCount() const;
  // Line steps the sweeps of the cloths there are now have taken beyond their two, because a
  // cloth was stretched beyond solver.maxStretch, since the world was made or its cloths replaced.
  std::int64_t extraLineSteps() const;

  // One step. If it leaves a position non-finite or beyond kRunawayDistance (the guard stage), the
  // cloths go back to where they were before it, at rest (their velocities ran away: they are not
  // given back), and the step returns diverged and does not count.
  StepStatus step();
  StepStatus run(std::int64_t steps);

  // The world's settings as it runs now. Its cloths are not kept here (the list is empty): each
  // cloth's own are cloths()[i].settings, with it in its record, as the world uses them (a
  // fabric's stretch and shear as XPBD compliances, its bend links none).
  const WorldSettings& settings() const { return settings_; }
  ClothList cloths() const { return ClothList(records_); }
  const std::vector<Collider>& colliders() const { return colliders_; }
  std::int64_t stepCount() const { return stepCount_; }
  double time() const { return static_cast<double>(stepCount_) * settings_.solver.dt; }
  // The substeps a step runs: solver.substeps, or more for a fine fabric (substepsFor, with the
  // finest spacing of its cloths that have a fabric).
  int substeps() const { return substeps_; }
  double substepDt() const { return settings_.solver.dt / substeps_; }
  const std::optional<Divergence>& divergence() const { return divergence_; }
  const Profile& profile() const { return profile_; }
  SelfContactStats selfContactStats() const;
  bool hasStage(Stage stage) const;
  // Changes whenever the set of cloths or any cloth's triangles or constraints change (tearing,
  // cutting, spawning), and differs between worlds: a renderer re-uploads index buffers only then.
  std::uint64_t topologyVersion() const { return topologyVersion_; }

  // Velocity of a particle, m/s: stored in the force model, (x - x_prev) / h in the position model.
  Vec3 velocity(int cloth, ParticleIndex particle) const;

  // The force model: the longest substep (s) its integrator is stable at on these cloths' springs,
  // by Gershgorin's bound on the fastest mode: omega^2 <= 2 (sum of k) / m and a decay rate <= 2 (sum
  // of kd) / m + drag, sums over each free particle's springs; stable while h (omega + rate) stays
  // within the integrator's interval (2.78 for RK4, else 2; explicit Euler and midpoint are never
  // quite stable undamped). Infinity in the position model or without springs.
  Real stableForceSubstep() const;

  // Fingers. Up to kMaxFingers may be down at once, each under the caller's id. A finger call that
  // cannot be done (an id not down, or down already; too many fingers; numbers not finite) changes
  // nothing and says so the same way every time: it returns nothing (std::nullopt, or false where
  // there is nothing else to return). None throws.
  // press: every particle within `radius` of `point` on the piece of the particle nearest to it
  // sticks to the finger, except particles another finger already holds (the first finger keeps
  // them). Returns how many it holds (a finger that touches nothing is still down), or nothing if
  // the id is already down, kMaxFingers are down, or the numbers are not finite and positive.
  std::optional<int> pressFinger(int id, Vec3 point, Real radius);
  // As press, at the point of the ray (origin + t direction, t > 0) nearest to the first particle
  // the ray passes within `radius` of. Returns that point, or nothing if the ray meets no cloth (the
  // finger is then not down).
  std::optional<Vec3> pressFingerAlongRay(int id, Vec3 origin, Vec3 direction, Real radius);
  // The next step carries the finger (and what it holds) in a straight line to `target`. False if
  // the id is not down or the target is not finite.
  bool moveFinger(int id, Vec3 target);
  // Lets go: the particles fly on with the finger's last velocity (a flick throws the cloth).
  bool releaseFinger(int id);
  // Lifts the finger but leaves what it held pinned where it is. Returns how many particles were
  // pinned, or nothing if the id is not down. No tethers go to these pins (Cloth::tetherPins); the
  // pinned particles lose their own.
  std::optional<int> pinFinger(int id);
  // Frees the pinned particles within `radius` of `point` (not those a finger holds). Returns how
  // many (none where there are none, or the numbers are not finite).
  int unpin(Vec3 point, Real radius);
  const std::vector<Finger>& fingers() const { return fingers_; }
  const Finger* finger(int id) const;

  // Cuts every cloth along the surface swept by the segment a-b moved along `depth` (a swipe seen
  // along the view direction). Returns how many cloths it opened.
  int cut(Vec3 a, Vec3 b, Vec3 depth);
  // Tearing can be switched and tuned while the world runs. Throws std::invalid_argument on a
  // threshold that is not a finite number above 1.
  void setTearing(const TearSettings& tearing);

  // Changes, while the world runs, what can change without rebuilding it: the solver's step,
  // substeps, iterations, damping, XPBD and tethers; gravity; the air; self-collision; tearing;
  // the colliders' friction. The model, the integrator, the colliders' shapes and the cloths stay
  // (`next.cloths` is ignored). Velocities are kept across a change of step. Throws
  // std::invalid_argument, changing nothing, when `next` is not valid or changes what cannot.
  void tune(const WorldSettings& next);
  // After a divergence the world holds its last good positions, at rest, and refuses to step; this
  // lets it go on from there (after tuning it, say).
  void clearDivergence() { divergence_.reset(); }

  // Adds a cloth while the world runs (it starts at rest) and returns its index; throws
  // std::invalid_argument like the constructor. Removing a cloth drops what fingers held of it.
  int addCloth(const ClothSettings& cloth);
  void removeCloth(int index);
  // Puts back cloths as they were (from cloths(), before a cut, say, or read from a file): every
  // finger lets go first. Throws std::invalid_argument, changing nothing, if a cloth is not
  // consistent (array sizes, indices out of range, a non-finite or non-positive number) or the
  // particles pass the limit.
  void restoreCloths(std::vector<Cloth> cloths);
  // Puts the clock at `steps` steps from the start (a snapshot taken then), and every collider
  // where that time takes it, so that a world loaded from a snapshot goes on as the one saved did.
  // Throws std::invalid_argument, changing nothing, for a negative count.
  void restoreStepCount(std::int64_t steps);

 private:
  void buildPipeline();
  void buildTethers(std::size_t cloth);
  // The finest spacing of a cloth with a fabric (0: none has one); and substeps_ made what the
  // settings and the cloths ask for now, the Verlet histories rescaled from a substep of hBefore.
  Real finestFabricSpacing() const;
  void followSpacing(Real hBefore);
  // The cloth's previous positions moved so that x - x_prev spans a substep of `to` s, not `from`
  // (the velocity kept), and its historyStep made `to`.
  static void rescaleHistory(Cloth& cloth, Real from, Real to);
  // The cloth's solver plan, once per topology (and after setThreads or tune): with lines, the
  // batches and lines read off the order the cloth keeps its constraints in (orderConstraints);
  // with the seed's sweep, the order it takes them in (by particle pair). It reorders nothing. A
  // plan that is already up to date costs nothing.
  void plan(std::size_t cloth);
  // Plans every cloth, where the pipeline projects constraints: at once, whenever what a plan is
  // made of changes (the world made, a cloth added, removed, restored, torn or cut, the threads
  // or the solver changed), so that the sweeps never plan inside their own stage (a tear's or a
  // cut's plan is timed with it). (A build that does not check invariants still plans, in the
  // constraint stage as its part `plan`, a cloth whose plan a path left out of date.)
  void planAll();
  void afterTopologyChange(std::size_t cloth, const std::vector<ParticleSplit>& splits,
                           const std::vector<ParticleInsert>& inserted = {});
  void moveFingers(Real h);
  // The turn (radians, about fingersAxis) that best carries `finger`'s hand (the fingers holding the
  // same piece of the same cloth) from their positions to their targets, about their centre. 0
  // where it holds nothing, its hand is one finger, its fingers are closer together than about a
  // patch's diameter, or the move turns them a quarter turn or more; at most kMostTwist.
  Real fingersTwist(const Finger& finger) const;
  // The axis hands turn about: against gravity, or +y without it.
  Vec3 fingersAxis() const;
  void tear();
  // Runs `change` (a tear or a cut) on every cloth, and what follows a cloth's change; the cloths
  // it changed.
  int changeTopology(const std::function<bool(Cloth&, std::size_t, std::vector<ParticleSplit>&,
                                              std::vector<ParticleInsert>&)>& change);
  void grab(Finger& finger, std::size_t cloth, ParticleIndex nearest);
  std::size_t particleCount() const;
  // The step's rows of stages (world.cpp): a substep of either model, each stage where the
  // pipeline has it, timed into its entry.
  void positionSubstep(Real h);
  void forceSubstep(Real h);
  template <class Work>
  void timed(Stage stage, Work&& work);
  void startHistory();
  void startHistory(std::size_t cloth);
  void moveColliders();
  std::optional<Divergence> findBadParticle() const;
  // Aborts where the world breaks what each step must leave (world.cpp; the checking build only:
  // src/invariant.hpp).
  void checkInvariants() const;
  Finger* findFinger(int id);

  WorldSettings settings_;            // cloths: none (each record's cloth has its own)
  std::vector<ClothRecord> records_;  // one a cloth
  Profile profile_;
  std::int64_t stepCount_ = 0;
  std::uint64_t topologyVersion_ = 0;
  bool historyStarted_ = false;
  std::optional<Divergence> divergence_;
  std::vector<Collider> colliders_;
  std::unique_ptr<SelfCollisionScratch> selfCollisionScratch_;  // made with the world
  std::unique_ptr<contact::SelfContact> selfContact_;           // made at the first substep that needs it
  // Self-contact is on: a held particle may lag its finger where the finger would drive it through
  // cloth (moveFingers).
  bool selfContactHolds_ = false;
  int substeps_ = 1;           // what a step runs (substeps())
  int substep_ = 0;            // within the current step
  std::ptrdiff_t rowAt_ = -1;  // the profile entry of the stage the row last ran (timed)
  std::size_t rowRan_ = 0;     // stages the row ran in this substep
  // Where the guard finds the positions before the current step (World::step).
  enum class GuardCopy : std::uint8_t {
    none,         // in the previous positions: one substep's integration left them there untouched
    integration,  // in each record's ClothWork::lastGood, copied by the first substep's integration
    before,       // in each record's ClothWork::lastGood, copied before the step
  };
  GuardCopy guardCopy_ = GuardCopy::before;  // (into each record's ClothWork::lastGood)
  std::vector<Finger> fingers_;
  bool isHeld(std::size_t cloth, std::size_t particle) const;
  std::unique_ptr<Workers> workers_;
};

}  // namespace drape::sim

// A ClothList's iterators point into the world, not into the list: they outlive it.
template <>
inline constexpr bool std::ranges::enable_borrowed_range<drape::sim::ClothList> = true;
