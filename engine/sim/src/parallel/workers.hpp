// A fixed team of threads for the solver's parallel loops.
//
// run(n, f) splits [0, n) into one contiguous chunk per thread, calls f(begin, end, thread) on
// each (chunk 0 on the caller) and returns when all are done (runShared hands out short blocks
// instead). The solver only hands it work whose items are independent (a batch of constraints no
// two of which share a particle, lines, single particles), so the result is the same bit for bit
// whatever the number of threads. Helpers spin briefly between loops (a substep has a dozen of
// them), then sleep. A loop cut into fewer parts than there are threads waits only for the helpers
// it uses. If a part throws (say, bad_alloc), the loop still waits for every part, then rethrows
// the first exception on the caller's thread; the pool stays usable.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <mutex>
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
    dispatch(n, grain, 0, caller<F>(), static_cast<void*>(&f));
  }
  // As run, but [0, n) is cut into blocks of `block` items, f called once a block, and the blocks
  // go to whichever thread is free: for loops whose items cost more in one part of the range than
  // in another (the tethers of particles near the pins), or whose threads run at different speeds
  // (a core shared with another machine). Each thread has a share of the blocks, as even as run's
  // chunks but in whole blocks: it takes its own from the front, then helps the others from their
  // backs. So a thread works on much the same particles loop after loop, and they stay in its
  // core's cache (on hang2 256 with 2 threads, taking the blocks in turn from one shared counter
  // made the steps about a fifth slower).
  template <class F>
  void runShared(std::size_t n, std::size_t block, F&& f, std::size_t grain = 512) {
    dispatch(n, grain, std::max<std::size_t>(block, 1), caller<F>(), static_cast<void*>(&f));
  }

 private:
  using Call = void (*)(void*, std::size_t, std::size_t, int);
  template <class F>
  static Call caller() {
    return [](void* task, std::size_t begin, std::size_t end, int thread) {
      (*static_cast<std::remove_reference_t<F>*>(task))(begin, end, thread);
    };
  }
  void dispatch(std::size_t n, std::size_t grain, std::size_t block, Call call, void* task);
  // Part `index` of `parts` of the loop of n items.
  void part(Call call, void* task, std::size_t n, std::size_t block, int parts, int index);
  void loop(int index);
  std::vector<std::thread> helpers_;
  // The current loop. Written only while no helper uses them: before a loop is announced, and after
  // every helper taking part has said it is done.
  Call call_ = nullptr;
  void* task_ = nullptr;
  std::size_t items_ = 0;
  std::size_t block_ = 0;  // 0: each part one contiguous chunk; else blocks this long (runShared)
  // runShared: each part's own share of the blocks, the ones not yet taken: [front, back), front in
  // the low 32 bits. A part takes its own from the front, then other parts' from their backs.
  struct alignas(64) Share {
    std::atomic<std::uint64_t> blocks{0};
  };
  std::vector<Share> shares_;
  // The loop's number times kStateParts, plus the threads taking part in it (the caller and helpers
  // 1 .. parts - 1): one word, so a helper never pairs one loop's number with another's parts.
  static constexpr std::uint64_t kStateParts = 128;
  std::atomic<std::uint64_t> state_{0};
  std::atomic<int> pending_{0};  // helpers taking part that have not finished
  std::mutex failureMutex_;
  std::exception_ptr failure_;  // the first exception a helper's part threw in the current loop
  std::atomic<bool> stop_{false};
};

}  // namespace drape::sim
