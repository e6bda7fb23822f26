// Times the parts of a stage into its profile entry (StageTiming::parts, pipeline.hpp).
#pragma once

#include <chrono>
#include <cstddef>
#include <utility>

#include "drape/sim/pipeline.hpp"

namespace drape::sim {

class PartClock {
 public:
  PartClock() = default;  // times nothing: the work just runs
  // Parts are added to `stage` the first time they run. Room is kept for every kind of part, so
  // that a part running inside another does not move the other's entry.
  explicit PartClock(StageTiming& stage) : stage_(&stage) { stage.parts.reserve(kRoom); }

  // Runs `work` as `part`. Time spent in a part timed inside it is that part's, not this one's.
  template <class Work>
  void time(Stage part, Work&& work) {
    if (!stage_) {
      std::forward<Work>(work)();
      return;
    }
    StageTiming* const outer = current_;
    StageTiming* const entry = find(part);
    const Clock::time_point start = Clock::now();
    if (outer) outer->lastSeconds += std::chrono::duration<double>(start - since_).count();
    current_ = entry;
    since_ = start;
    std::forward<Work>(work)();
    const Clock::time_point end = Clock::now();
    entry->lastSeconds += std::chrono::duration<double>(end - since_).count();
    current_ = outer;
    since_ = end;
  }

 private:
  using Clock = std::chrono::steady_clock;
  static constexpr std::size_t kRoom = 16;  // more than there are kinds of part

  StageTiming* find(Stage part) {
    for (StageTiming& entry : stage_->parts) {
      if (entry.stage == part) return &entry;
    }
    if (stage_->parts.size() == kRoom) return &stage_->parts.back();  // (never: kRoom covers them all)
    stage_->parts.push_back({part, stage_->perSubstep, 0.0, 0.0, {}});
    return &stage_->parts.back();
  }

  StageTiming* stage_ = nullptr;
  StageTiming* current_ = nullptr;
  Clock::time_point since_{};
};

}  // namespace drape::sim
