// The world: cloths, their settings, and the fixed-step pipeline that advances them.
//
// Stepping is deterministic: the same settings and the same calls give bit-identical states.
// Nothing non-finite escapes: after every step a guard checks every position; the first step
// that produced a non-finite or runaway value is recorded, the state is restored to what it was
// before that step, and the world refuses to step further. The caller decides what to tell whom.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "drape/sim/cloth.hpp"
#include "drape/sim/pipeline.hpp"
#include "drape/sim/settings.hpp"
#include "drape/sim/state.hpp"

namespace drape::sim {

struct Cloth {
  ClothRest rest;
  ParticleState state;
  ClothSettings settings;
  Real particleMass = 0.0;  // kg, mass of every unpinned particle
};

struct Divergence {
  std::int64_t step;  // 1-based number of the step that produced the bad value
  int cloth;          // which cloth
  ParticleIndex particle;
};

enum class StepStatus : std::uint8_t { ok, diverged };

class World {
 public:
  // Throws std::invalid_argument if the settings are outside what the engine accepts.
  explicit World(WorldSettings settings);

  StepStatus step();
  StepStatus run(std::int64_t steps);

  const WorldSettings& settings() const { return settings_; }
  const std::vector<Cloth>& cloths() const { return cloths_; }
  const std::vector<Collider>& colliders() const { return colliders_; }
  std::int64_t stepCount() const { return stepCount_; }
  double time() const { return static_cast<double>(stepCount_) * settings_.solver.dt; }
  double substepDt() const { return settings_.solver.dt / settings_.solver.substeps; }
  const std::optional<Divergence>& divergence() const { return divergence_; }
  const Profile& profile() const { return profile_; }
  bool hasStage(Stage stage) const;
  // Changes whenever the set of cloths or any cloth's triangles or constraints change (tearing,
  // cutting, spawning), and differs between worlds: a renderer re-uploads index buffers only then.
  std::uint64_t topologyVersion() const { return topologyVersion_; }

  // Velocity of a particle, m/s: stored in the force model, (x - x_prev) / h in the position model.
  Vec3 velocity(int cloth, ParticleIndex particle) const;

 private:
  void runStage(Stage stage);
  void startHistory();
  void moveColliders();
  std::optional<Divergence> findBadParticle() const;

  WorldSettings settings_;
  std::vector<Cloth> cloths_;
  Profile profile_;
  std::int64_t stepCount_ = 0;
  std::uint64_t topologyVersion_ = 0;
  bool historyStarted_ = false;
  std::optional<Divergence> divergence_;
  std::vector<SolverScratch> scratch_;  // per cloth
  std::vector<Collider> colliders_;
  SelfCollisionScratch selfCollisionScratch_;
  int substep_ = 0;  // within the current step
  struct Snapshot {
    std::vector<Vec3> position, previousPosition, velocity;
  };
  std::vector<Snapshot> lastGood_;  // what the current step changes, as it was before it
};

}  // namespace drape::sim
