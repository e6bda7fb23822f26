#include "parallel/workers.hpp"

#include <algorithm>

namespace drape::sim {

namespace {
constexpr int kSpins = 20000;  // about 50 microseconds of polling before a helper sleeps

// One round of polling. Every 64th gives the core away, so that more threads than cores (or a
// busy machine) still make progress.
void pause(int round) {
  if (round % 64 == 63) {
    std::this_thread::yield();
    return;
  }
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}

std::pair<std::size_t, std::size_t> chunk(std::size_t n, int parts, int index) {
  const std::size_t begin = n * static_cast<std::size_t>(index) / static_cast<std::size_t>(parts);
  const std::size_t end = n * static_cast<std::size_t>(index + 1) / static_cast<std::size_t>(parts);
  return {begin, end};
}
}  // namespace

Workers::Workers(int threads) : shares_(static_cast<std::size_t>(std::max(threads, 1))) {
  for (int i = 1; i < std::max(threads, 1); ++i) helpers_.emplace_back([this, i] { loop(i); });
}

Workers::~Workers() {
  stop_.store(true, std::memory_order_release);
  state_.store((state_.load(std::memory_order_relaxed) / kStateParts + 1) * kStateParts, std::memory_order_release);
  state_.notify_all();
  for (std::thread& helper : helpers_) helper.join();
}

void Workers::part(Call call, void* task, std::size_t n, std::size_t block, int parts, int index) {
  if (block == 0) {
    const auto [begin, end] = chunk(n, parts, index);
    call(task, begin, end, index);
    return;
  }
  if (parts == 1) {
    for (std::size_t begin = 0; begin < n; begin += block) call(task, begin, std::min(begin + block, n), index);
    return;
  }
  // The next block of a share, from its front or its back; false when none is left.
  const auto take = [](Share& share, bool front, std::size_t& taken) {
    std::uint64_t blocks = share.blocks.load(std::memory_order_relaxed);
    while (true) {
      const std::uint64_t first = blocks & 0xffffffffu, last = blocks >> 32;
      if (first >= last) return false;
      const std::uint64_t next = front ? blocks + 1 : blocks - (std::uint64_t{1} << 32);
      if (share.blocks.compare_exchange_weak(blocks, next, std::memory_order_relaxed)) {
        taken = static_cast<std::size_t>(front ? first : last - 1);
        return true;
      }
    }
  };
  for (int i = 0; i < parts; ++i) {
    Share& share = shares_[static_cast<std::size_t>((index + i) % parts)];
    for (std::size_t k; take(share, i == 0, k);) call(task, k * block, std::min((k + 1) * block, n), index);
  }
}

void Workers::dispatch(std::size_t n, std::size_t grain, std::size_t block, Call call, void* task) {
  // A share counts its blocks in 32 bits: at most 2^31 of them.
  if (block != 0) block = std::max<std::size_t>(block, (n >> 31) + 1);
  std::size_t most = std::max<std::size_t>(n / std::max<std::size_t>(grain, 1), 1);
  if (block != 0) most = std::min(most, (n + block - 1) / block);  // no part without a block to take
  const int parts = static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(threads()), most));
  if (parts <= 1) {
    part(call, task, n, block, 1, 0);
    return;
  }
  call_ = call;
  task_ = task;
  items_ = n;
  block_ = block;
  if (block != 0) {  // published by the release store below
    const std::uint64_t blocks = (n + block - 1) / block;
    for (int i = 0; i < parts; ++i) {
      const std::uint64_t first = blocks * static_cast<std::uint64_t>(i) / static_cast<std::uint64_t>(parts);
      const std::uint64_t last = blocks * static_cast<std::uint64_t>(i + 1) / static_cast<std::uint64_t>(parts);
      shares_[static_cast<std::size_t>(i)].blocks.store(first | (last << 32), std::memory_order_relaxed);
    }
  }
  pending_.store(parts - 1, std::memory_order_relaxed);
  const std::uint64_t loop = state_.load(std::memory_order_relaxed) / kStateParts + 1;
  state_.store(loop * kStateParts + static_cast<std::uint64_t>(parts), std::memory_order_release);
  state_.notify_all();
  std::exception_ptr failure;
  try {
    part(call, task, n, block, parts, 0);
  } catch (...) {
    failure = std::current_exception();
  }
  // Even when this part failed, the helpers are still using the task: wait for them.
  for (int round = 0; pending_.load(std::memory_order_acquire) != 0; ++round) pause(round);
  task_ = nullptr;
  {
    const std::lock_guard<std::mutex> lock(failureMutex_);
    if (!failure) failure = failure_;
    failure_ = nullptr;
  }
  if (failure) std::rethrow_exception(failure);
}

void Workers::loop(int index) {
  std::uint64_t seen = 0;
  while (true) {
    std::uint64_t now = state_.load(std::memory_order_acquire);
    for (int spin = 0; now == seen && spin < kSpins; ++spin) {
      pause(spin);
      now = state_.load(std::memory_order_acquire);
    }
    if (now == seen) {
      state_.wait(seen, std::memory_order_acquire);
      continue;
    }
    seen = now;
    if (stop_.load(std::memory_order_acquire)) return;
    // Not taking part: nothing of the loop is read (the caller may already be setting up the next).
    const int parts = static_cast<int>(now % kStateParts);
    if (index >= parts) continue;
    try {
      part(call_, task_, items_, block_, parts, index);
    } catch (...) {
      const std::lock_guard<std::mutex> lock(failureMutex_);
      if (!failure_) failure_ = std::current_exception();
    }
    pending_.fetch_sub(1, std::memory_order_acq_rel);
  }
}

}  // namespace drape::sim
