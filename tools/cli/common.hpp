// Pieces every drape-cli subcommand shares.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "commands.hpp"
#include "drape/scene/scene.hpp"
#include "drape/sim/world.hpp"

namespace drape::cli {

// Prints "drape-cli: error: MESSAGE" and returns kExitBadInput.
int badInput(const std::string& message);

scene::Scene loadScene(const SceneArguments& arguments);

// The engine validates too; its messages are a last line of defence behind the scene reader's.
sim::World makeWorld(const scene::Scene& scene);

// Steps to run: --steps, or --time / dt, or the scene's duration / dt; at most kMaxSteps.
std::int64_t stepCount(const scene::Scene& scene, std::optional<std::int64_t> steps, std::optional<double> seconds);

// Prints where the world diverged and returns kExitDiverged.
int reportDivergence(const scene::Scene& scene, const sim::World& world);

}  // namespace drape::cli
