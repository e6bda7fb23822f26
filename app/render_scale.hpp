#pragma once
// Dynamic resolution: the render scale (FrameOptions::renderScale) the app draws its scene at,
// chosen from what its frames cost so that a frame fits in 1/60 s. A software renderer (llvmpipe)
// pays for every pixel, a GPU hardly notices them: on one the scale goes down until the frame fits,
// on the other it stays at 1. Window-free, so it is tested with made-up frame times.
#include <vector>

namespace drape::app {

class RenderScale {
 public:
  static constexpr int kWindow = 20;          // frames whose median cost moves the scale once
  static constexpr double kBudget = 0.0150;   // s of work a frame may take (1/60 s less presenting)
  static constexpr double kRaiseBelow = 0.8;  // the scale rises only while frames take under this share of it
  static constexpr double kStep = 0.05;       // scales are multiples of this (a new size is a new picture)

  // One drawn frame: the work it took (simulation, scene and panels, in s) and the scene's part
  // of it. Frames that are not finite or not positive are left out.
  void frame(double workSeconds, double sceneSeconds);

  double scale() const { return scale_; }
  bool automatic() const { return automatic_; }
  // Off: the scale stays where set (clamped to [lowest, 1]); on again: it is chosen from the frames.
  void setAutomatic(bool on);
  void set(double scale);

 private:
  std::vector<double> work_, scene_;
  double scale_ = 1.0;
  bool automatic_ = true;
};

}  // namespace drape::app
