#include "render_scale.hpp"

#include <algorithm>
#include <cmath>

#include "drape/render/renderer.hpp"

namespace drape::app {
namespace {

double median(std::vector<double> values) {
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

double clampScale(double scale) {
  constexpr double lowest = render::FrameOptions::kLowestRenderScale;
  return scale >= lowest ? std::min(scale, 1.0) : lowest;  // a NaN to the lowest
}

}  // namespace

void RenderScale::setAutomatic(bool on) {
  automatic_ = on;
  work_.clear();
  scene_.clear();
}

void RenderScale::set(double scale) {
  scale_ = clampScale(scale);
  work_.clear();
  scene_.clear();
}

void RenderScale::frame(double workSeconds, double sceneSeconds) {
  if (!automatic_) return;
  if (!(std::isfinite(workSeconds) && std::isfinite(sceneSeconds) && workSeconds > 0.0 && sceneSeconds > 0.0 &&
        sceneSeconds <= workSeconds)) {
    return;
  }
  work_.push_back(workSeconds);
  scene_.push_back(sceneSeconds);
  if (static_cast<int>(work_.size()) < kWindow) return;
  const double work = median(work_), scene = median(scene_);
  work_.clear();
  scene_.clear();
  // The scene's cost taken as proportional to its pixels (the scale squared): what the rest of the
  // frame leaves it, over what it takes now, gives the scale that would fit. The real cost has a
  // part that does not shrink, so a frame over budget may take a few windows to fit; a frame well
  // under it rises only to where the same rule says it still fits with room to spare, so the scale
  // settles instead of swinging.
  const double others = work - scene;
  double wanted = scale_;
  if (work > kBudget) {
    const double room = std::max(kBudget - others, 0.25 * scene);
    wanted = scale_ * std::sqrt(room / scene);
    wanted = std::min(wanted, scale_ - kStep);  // over budget: down at least a step
  } else if (work < kRaiseBelow * kBudget && scale_ < 1.0) {
    const double room = kRaiseBelow * kBudget - others;
    wanted = std::min(scale_ * std::sqrt(room / scene), scale_ + 2.0 * kStep);
  }
  // Rounded down to a step going down, and to the nearest step going up (never past what it wanted
  // by more than half a step).
  const double steps = wanted < scale_ ? std::floor(wanted / kStep + 1e-9) : std::floor(wanted / kStep + 0.5);
  scale_ = clampScale(steps * kStep);
}

}  // namespace drape::app
