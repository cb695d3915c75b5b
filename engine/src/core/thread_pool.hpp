// SPDX-License-Identifier: MIT
// A small fork-join pool for the CPU solver. A job is [0, n) cut into blocks; the caller and the
// workers claim blocks one at a time (an atomic counter), so a thread the OS delays does not hold
// the others up: whoever runs takes the next block, and the caller waits only for blocks already
// claimed. Work items are independent per particle and the blocks do not depend on which thread
// runs them, so results do not depend on the thread count or on scheduling.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <thread>
#include <vector>

namespace vkcloth::detail {

class ThreadPool {
public:
  using Fn = std::function<void(std::size_t, std::size_t)>;

  /// The cores this process may run on: its CPU affinity (taskset, a container's cpuset), which
  /// std::thread::hardware_concurrency() does not see; at least 1.
  static unsigned available_cores();

  /// `threads` = total threads including the caller's (1 = run everything inline).
  explicit ThreadPool(unsigned threads);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  unsigned size() const { return static_cast<unsigned>(workers_.size()) + 1; }

  /// Calls fn(begin, end) over [0, n) split into one contiguous chunk per thread; returns when
  /// all are done.
  void parallel_for(std::size_t n, const Fn& fn);
  /// The same with chunks of about `block` items (at least `block`, at most 2 x `block` - 1), so
  /// that the threads share the work by what each actually gets done.
  void parallel_blocks(std::size_t n, std::size_t block, const Fn& fn);
  /// parallel_for calling body(i) for each i in [0, n).
  template <typename Body> void for_each(std::size_t n, Body&& body) {
    parallel_for(n, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i)
        body(i);
    });
  }

private:
  void run(std::size_t n, std::uint32_t blocks, const Fn& fn);
  void claim_loop(std::uint32_t generation);
  void worker();

  std::vector<std::thread> workers_;
  // The job: valid for the generation stored in claim_'s high 32 bits; claim_'s low 32 bits are
  // the next unclaimed block. Workers read the job after seeing the generation and only run a
  // block after claiming it with a compare-exchange that also checks the generation.
  std::atomic<const Fn*> fn_{nullptr};
  std::atomic<std::size_t> n_{0};
  std::atomic<std::uint32_t> blocks_{0};
  std::atomic<std::uint64_t> claim_{0};
  std::atomic<std::uint32_t> finished_{0};   // blocks of the current job done
  std::atomic<std::uint32_t> generation_{0}; // wakes the workers (spin, then atomic wait)
  std::atomic<bool> stop_{false};
};

} // namespace vkcloth::detail
