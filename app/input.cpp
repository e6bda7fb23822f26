#include "input.hpp"

#include <algorithm>
#include <cmath>

namespace drape::app {

namespace {

bool finite(double x, double y) { return std::isfinite(x) && std::isfinite(y); }

}  // namespace

InputMapper::InputMapper(interact::Interaction& interaction, render::Camera& camera, InputOptions options)
    : interaction_(interaction), camera_(camera), options_(options) {}

void InputMapper::report(std::string problem) {
  problems_.push_back(std::move(problem));
  if (problems_.size() > 100) problems_.erase(problems_.begin());
}

bool InputMapper::parked(int id) const {
  return std::any_of(parked_.begin(), parked_.end(), [id](const Parked& p) { return p.id == id; });
}

double InputMapper::liftPerNotch() const {
  return std::clamp(options_.wheelLift * camera_.distance, options_.wheelLiftMin, options_.wheelLiftMax);
}

void InputMapper::liftBy(int id, double& height, double notches) {
  height = std::max(0.0, height + notches * liftPerNotch());
  if (interaction_.lift(id, height)) ++fingerMoves_;
}

void InputMapper::forgetLifted() {
  // The session may have lifted fingers behind our back (a divergence, an undo, a reset): forget
  // those, so the wheel does not keep lifting a finger that is gone.
  const std::vector<interact::TouchView> down = interaction_.touches();
  const auto isDown = [&](int id) {
    return std::any_of(down.begin(), down.end(), [id](const interact::TouchView& t) { return t.id == id; });
  };
  std::erase_if(parked_, [&](const Parked& p) { return !isDown(p.id); });
  std::erase_if(touchIds_, [&](const auto& entry) { return !isDown(entry.second); });
  if (drag_ == Drag::finger && !isDown(dragFinger_)) drag_ = Drag::none;
}

void InputMapper::handle(const InputEvent& event, bool uiWantsMouse) {
  using Kind = InputEvent::Kind;
  forgetLifted();
  const auto key = std::make_pair(event.touch, event.finger);
  const interact::Pointer pointer =
      event.world ? interact::Pointer::at(*event.world) : interact::Pointer::onScreen(event.x, event.y);
  switch (event.kind) {
    case Kind::touchDown: {
      if (!finite(event.x, event.y)) return report("a touch at a point that is not finite");
      if (touchIds_.count(key)) {
        // A second down for a touch that is down: the first one's up went missing. Start afresh.
        interaction_.up(touchIds_[key]);
        touchIds_.erase(key);
      }
      const int id = nextTouchId_;
      nextTouchId_ = nextTouchId_ + 1 < kMouseIds ? nextTouchId_ + 1 : 1;
      if (!interaction_.down(id, pointer, event.radius)) return report("touch: " + interaction_.lastError());
      touchIds_[key] = id;
      return;
    }
    case Kind::touchMove: {
      const auto found = touchIds_.find(key);
      if (found == touchIds_.end()) return;  // a touch that began on no finger (or was lifted): nothing to move
      if (!finite(event.x, event.y)) return report("a touch moved to a point that is not finite");
      if (interaction_.move(found->second, pointer)) ++fingerMoves_;
      return;
    }
    case Kind::touchUp: {
      const auto found = touchIds_.find(key);
      if (found == touchIds_.end()) return report("a touch ended that never began");
      if (!interaction_.up(found->second)) report("touch: " + interaction_.lastError());
      touchIds_.erase(found);
      return;
    }
    case Kind::mouseDown: {
      if (drag_ != Drag::none || uiWantsMouse || !finite(event.x, event.y)) return;
      lastX_ = event.x;
      lastY_ = event.y;
      if (event.button == 3) {
        drag_ = Drag::orbit;
      } else if (event.button == 2) {
        drag_ = Drag::pan;
      } else if (event.button == 1 && event.ctrl) {
        // Lift the parked finger whose ring, where it is now in the picture, is nearest the pointer.
        const std::vector<interact::TouchView> down = interaction_.touches();
        const double aspect = interaction_.aspect();
        auto nearest = parked_.end();
        double best = options_.parkedReach;
        for (auto p = parked_.begin(); p != parked_.end(); ++p) {
          const auto view = std::find_if(down.begin(), down.end(), [&](const auto& t) { return t.id == p->id; });
          if (view == down.end()) continue;
          const std::optional<glm::dvec2> at = camera_.project(view->position, aspect);
          if (!at) continue;
          // In window heights, so the reach is a circle on the screen whatever the aspect.
          const double apart = std::hypot((at->x - event.x) * aspect, at->y - event.y);
          if (apart <= best) {
            best = apart;
            nearest = p;
          }
        }
        if (nearest != parked_.end()) {
          interaction_.up(nearest->id);
          parked_.erase(nearest);
        }
      } else if (event.button == 1) {
        const int id = nextMouseId_++;
        if (!interaction_.down(id, pointer)) return report("mouse: " + interaction_.lastError());
        drag_ = Drag::finger;
        dragFinger_ = id;
        dragHeight_ = 0.0;
        parkOnRelease_ = event.shift;
      }
      return;
    }
    case Kind::mouseMove: {
      if (!finite(event.x, event.y)) return;
      const double dx = event.x - lastX_, dy = event.y - lastY_;
      lastX_ = event.x;
      lastY_ = event.y;
      if (drag_ == Drag::finger) {
        if (interaction_.move(dragFinger_, pointer)) ++fingerMoves_;
      } else if (drag_ == Drag::orbit) {
        camera_.orbit(dx * options_.orbitSpeed, dy * options_.orbitSpeed);
      } else if (drag_ == Drag::pan) {
        camera_.pan(-dx, dy);
      }
      return;
    }
    case Kind::mouseUp: {
      if (drag_ == Drag::finger && event.button == 1) {
        if (parkOnRelease_) {
          parked_.push_back({dragFinger_, dragHeight_});
        } else if (!interaction_.up(dragFinger_)) {
          report("mouse: " + interaction_.lastError());
        }
        drag_ = Drag::none;
      } else if ((drag_ == Drag::orbit && event.button == 3) || (drag_ == Drag::pan && event.button == 2)) {
        drag_ = Drag::none;
      }
      return;
    }
    case Kind::wheel: {
      if (!std::isfinite(event.wheel)) return;
      if (drag_ == Drag::finger) {
        liftBy(dragFinger_, dragHeight_, event.wheel);
      } else if (uiWantsMouse) {
        return;  // the panel scrolls
      } else if (!parked_.empty()) {
        liftBy(parked_.back().id, parked_.back().height, event.wheel);
      } else {
        camera_.zoom(std::pow(options_.zoomPerNotch, event.wheel));
      }
      return;
    }
    case Kind::focusLost: {
      // Whatever was held is let go: the up events will never come.
      interaction_.cancelAll();
      touchIds_.clear();
      parked_.clear();
      drag_ = Drag::none;
      return;
    }
  }
}

}  // namespace drape::app
