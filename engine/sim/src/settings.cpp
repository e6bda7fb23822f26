#include "drape/sim/settings.hpp"

#include "drape/sim/pipeline.hpp"

#include <algorithm>
#include <cmath>

namespace drape::sim {

namespace {
constexpr std::array kModelNames = {std::pair{Model::position, std::string_view{"position"}},
                                    std::pair{Model::force, std::string_view{"force"}}};
constexpr std::array kIntegratorNames = {std::pair{Integrator::explicitEuler, std::string_view{"explicit-euler"}},
                                         std::pair{Integrator::symplecticEuler, std::string_view{"symplectic-euler"}},
                                         std::pair{Integrator::verlet, std::string_view{"verlet"}},
                                         std::pair{Integrator::midpoint, std::string_view{"midpoint"}},
                                         std::pair{Integrator::rk4, std::string_view{"rk4"}}};
constexpr std::array kStretchSolverNames = {std::pair{StretchSolver::gaussSeidel, std::string_view{"gauss-seidel"}},
                                            std::pair{StretchSolver::lines, std::string_view{"lines"}}};

template <typename Table, typename Enum>
std::string_view lookupName(const Table& table, Enum value) {
  for (const auto& [entry, text] : table) {
    if (entry == value) return text;
  }
  return "?";
}

template <typename Enum, typename Table>
std::optional<Enum> lookupValue(const Table& table, std::string_view text) {
  for (const auto& [entry, entryText] : table) {
    if (entryText == text) return entry;
  }
  return std::nullopt;
}
}  // namespace

std::string_view name(Model model) { return lookupName(kModelNames, model); }
std::string_view name(Integrator integrator) { return lookupName(kIntegratorNames, integrator); }
std::string_view name(StretchSolver solver) { return lookupName(kStretchSolverNames, solver); }
std::optional<Model> parseModel(std::string_view text) { return lookupValue<Model>(kModelNames, text); }
std::optional<StretchSolver> parseStretchSolver(std::string_view text) {
  return lookupValue<StretchSolver>(kStretchSolverNames, text);
}
std::optional<Integrator> parseIntegrator(std::string_view text) {
  return lookupValue<Integrator>(kIntegratorNames, text);
}

namespace {
constexpr std::array<std::pair<SelfContactMethod, std::string_view>, 2> kSelfContactNames{{
    {SelfContactMethod::triangles, "triangles"},
    {SelfContactMethod::particles, "particles"},
}};
}  // namespace

std::string_view name(SelfContactMethod method) { return lookupName(kSelfContactNames, method); }
std::optional<SelfContactMethod> parseSelfContactMethod(std::string_view text) {
  return lookupValue<SelfContactMethod>(kSelfContactNames, text);
}

std::optional<SolverConflict> conflict(const SolverSettings& solver) {
  if (solver.model == Model::position && solver.integrator != Integrator::verlet) {
    return SolverConflict{"integrator",
                          "\"verlet\" for the position model (the others belong to \"model\": \"force\")"};
  }
  if (solver.model == Model::force) {
    constexpr std::string_view kPositionOnly = "false for the force model (it belongs to the position model)";
    if (solver.xpbd) return SolverConflict{"xpbd", kPositionOnly};
    if (solver.tethers) return SolverConflict{"tethers", kPositionOnly};
    if (solver.lines()) {
      return SolverConflict{"stretchSolver",
                            "\"gauss-seidel\" for the force model (\"lines\" belongs to the position model)"};
    }
    if (solver.maxStretch > 0.0)
      return SolverConflict{"maxStretch", "0 for the force model (it belongs to the position model)"};
  }
  if (solver.maxStretch > 0.0 && !solver.lines()) {
    return SolverConflict{"maxStretch", "0 unless \"stretchSolver\" is \"lines\" (the line solve works to it)"};
  }
  if (solver.maxStretch > 0.0 && solver.xpbd) {
    return SolverConflict{"maxStretch",
                          "0 with \"xpbd\" (a compliant cloth stretches as its compliance says, not to a target)"};
  }
  return std::nullopt;
}

SolverSettings consistent(SolverSettings solver) {
  if (solver.model == Model::position) solver.integrator = Integrator::verlet;
  if (solver.model == Model::force) {
    solver.xpbd = solver.tethers = false;
    solver.stretchSolver = StretchSolver::gaussSeidel;
  }
  if (!solver.lines() || solver.xpbd) solver.maxStretch = 0.0;
  return solver;
}

int substepsFor(const SolverSettings& solver, Real spacing) {
  if (solver.model != Model::position || !(solver.fabricSubstepSpeed > 0.0) || !(spacing > 0.0)) {
    return solver.substeps;
  }
  // (A step of 0.0166666667 s, as scene files write 1/60, at 12.5 mm asks for 10, not 11.)
  const double needed = std::ceil(solver.dt * static_cast<double>(solver.fabricSubstepSpeed) /
                                  static_cast<double>(spacing) * (1.0 - 1e-6));
  // Never more than kMaxSubsteps, nor a substep under the 1e-9 s a world accepts.
  const double most = std::max(static_cast<double>(solver.substeps),
                               std::min(static_cast<double>(kMaxSubsteps), std::floor(solver.dt / 1e-9)));
  if (!(needed < most)) return static_cast<int>(most);
  return std::max(solver.substeps, static_cast<int>(needed));
}

std::string_view name(Stage stage) {
  switch (stage) {
    case Stage::windPressure: return "wind pressure";
    case Stage::verletIntegrate: return "verlet integrate";
    case Stage::projectConstraints: return "project constraints";
    case Stage::dampConstraints: return "damp constraints";
    case Stage::clampTravel: return "clamp travel";
    case Stage::collide: return "collide";
    case Stage::friction: return "friction";
    case Stage::selfCollide: return "self-collide";
    case Stage::selfContact: return "self-contact";
    case Stage::collideForces: return "collide (forces)";
    case Stage::explicitEuler: return "explicit euler";
    case Stage::symplecticEuler: return "symplectic euler";
    case Stage::verletForces: return "verlet (forces)";
    case Stage::midpoint: return "midpoint";
    case Stage::rk4: return "rk4";
    case Stage::fingers: return "fingers";
    case Stage::guard: return "guard";
    case Stage::tear: return "tear";
    case Stage::plan: return "plan";
    case Stage::tethers: return "tethers";
    case Stage::bendStencils: return "bend stencils";
    case Stage::bend: return "bend";
    case Stage::shear: return "shear";
    case Stage::stretch: return "stretch";
    case Stage::looseLinks: return "loose links";
    case Stage::contactPlanes: return "contact planes";
    case Stage::layerContacts: return "layer contacts";
    case Stage::broadPhase: return "broad phase";
    case Stage::narrowPhase: return "narrow phase";
    case Stage::contactSweep: return "contact sweep";
    case Stage::sweepAfter: return "sweep after";
    case Stage::failSafe: return "fail-safe";
  }
  return "?";
}

}  // namespace drape::sim
