#include "drape/sim/state.hpp"

#include "solver/solver_scratch.hpp"

#include <limits>
#include <stdexcept>

namespace drape::sim {

MassReal toMass(Real mass) {
  if (!(mass > 0.0 && mass <= static_cast<Real>(std::numeric_limits<MassReal>::max()))) {
    throw std::invalid_argument("a particle's mass must be a positive finite number of kilograms, at most 3.4e38");
  }
  // Normal floats only: a tear halves masses (topology.cpp, takeShare), which a subnormal one
  // could not survive.
  if (mass < static_cast<Real>(std::numeric_limits<MassReal>::min())) {
    throw std::invalid_argument("a particle's mass must be at least 1.2e-38 kg");
  }
  return static_cast<MassReal>(mass);
}

std::vector<SolverScratch::Tethers::Tether> SolverScratch::Tethers::list() const {
  std::vector<Tether> tethers;
  tethers.reserve(size());
  for (const Run& r : run) {
    for (std::uint32_t i = 0; i < r.count; ++i) {
      for (std::uint32_t j = 0; j < r.pinCount; ++j) {
        tethers.push_back({r.first + i, pin[r.pins + j], length[r.lengths + i * r.pinCount + j]});
      }
    }
  }
  return tethers;
}

void SolverScratch::Tethers::assign(const std::vector<Tether>& tethers) {
  clear();
  length.reserve(tethers.size());
  for (std::size_t k = 0; k < tethers.size();) {
    const ParticleIndex particle = tethers[k].particle;
    std::size_t last = k + 1;
    while (last < tethers.size() && tethers[last].particle == particle) ++last;
    const auto pinCount = static_cast<std::uint32_t>(last - k);
    // The particle joins the run before it if it follows that run's last particle and has the
    // same pins in the same order.
    bool joins = !run.empty() && run.back().first + run.back().count == particle && run.back().pinCount == pinCount;
    for (std::uint32_t j = 0; joins && j < pinCount; ++j) joins = pin[run.back().pins + j] == tethers[k + j].pin;
    if (joins) {
      ++run.back().count;
    } else {
      const std::uint32_t before = run.empty() ? 0 : run.back().before + run.back().count;
      run.push_back({particle, 1, static_cast<std::uint32_t>(pin.size()), pinCount,
                     static_cast<std::uint32_t>(length.size()), before});
      for (std::size_t j = k; j < last; ++j) pin.push_back(tethers[j].pin);
    }
    for (std::size_t j = k; j < last; ++j) length.push_back(tethers[j].length);
    k = last;
  }
  run.shrink_to_fit();
  pin.shrink_to_fit();
}

}  // namespace drape::sim
