#include "drape/bench/hang2.hpp"

#include <stdexcept>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "drape/scene/scene.hpp"

namespace drape::bench {

namespace embedded {
extern const std::string_view hang2_json;  // assets/scenes/hang2.json, as built (cmake/embed.cmake)
}

sim::WorldSettings hang2(int n, const Hang2Solver& solver) {
  if (n < 2) throw std::invalid_argument("hang2 needs at least 2 x 2 particles, not " + std::to_string(n));
  static const sim::WorldSettings file =
      scene::parseScene(nlohmann::json::parse(embedded::hang2_json), "assets/scenes/hang2.json").world;
  sim::WorldSettings world = file;
  sim::ClothSettings& cloth = world.cloths.at(0);
  cloth.lattice.columns = cloth.lattice.rows = n;
  cloth.pins = {{0, 0, std::nullopt}, {n - 1, 0, std::nullopt}};
  sim::SolverSettings& s = world.solver;
  s.substeps = solver.substeps.value_or(s.substeps);
  s.iterations = solver.iterations.value_or(s.iterations);
  s.stretchSolver = solver.stretchSolver.value_or(s.stretchSolver);
  s.tethers = solver.tethers.value_or(s.tethers);
  s.maxStretch = solver.maxStretch.value_or(s.maxStretch);
  return world;
}

}  // namespace drape::bench
