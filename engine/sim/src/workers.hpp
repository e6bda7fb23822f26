// A fixed team of threads for the solver's parallel loops.
//
// run(n, f) splits [0, n) into one contiguous chunk per thread, calls f(begin, end, thread) on
// each (chunk 0 on the caller) and returns when all are done. The solver only hands it work whose
// items are independent (a batch of constraints no two of which share a particle, lines, single
// particles), so the result is the same bit for bit whatever the number of threads. Helpers spin
// briefly between loops (a substep has a dozen of them), then sleep.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <thread>
#include <type_traits>
#include <vector>

namespace drape::sim {

class Workers {
 public:
  explicit Workers(int threads);
  ~Workers();
  Workers(const Workers&) = delete;
  Workers& operator=(const Workers&) = delete;

  int threads() const { return static_cast<int>(helpers_.size()) + 1; }
  // Below `grain` items per thread the loop runs on the caller alone. `f` is called as
  // f(begin, end, thread); it is not copied (no allocation per loop).
  template <class F>
  void run(std::size_t n, F&& f, std::size_t grain = 512) {
    using Task = std::remove_reference_t<F>;
    dispatch(
        n, grain,
        [](void* task, std::size_t begin, std::size_t end, int thread) {
          (*static_cast<Task*>(task))(begin, end, thread);
        },
        static_cast<void*>(&f));
  }

 private:
  using Call = void (*)(void*, std::size_t, std::size_t, int);
  void dispatch(std::size_t n, std::size_t grain, Call call, void* task);
  void loop(int index);
  std::vector<std::thread> helpers_;
  Call call_ = nullptr;
  void* task_ = nullptr;
  std::size_t items_ = 0;
  int active_ = 1;  // threads taking part in the current loop
  std::atomic<std::uint64_t> generation_{0};
  std::atomic<int> pending_{0};
  std::atomic<bool> stop_{false};
};

}  // namespace drape::sim
