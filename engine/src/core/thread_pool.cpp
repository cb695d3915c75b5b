// SPDX-License-Identifier: MIT
#include "thread_pool.hpp"

#ifdef __linux__
#include <sched.h>
#endif

#include <algorithm>
#include <chrono>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define VKCLOTH_PAUSE() _mm_pause()
#else
#define VKCLOTH_PAUSE() std::this_thread::yield()
#endif

namespace vkcloth::detail {

unsigned ThreadPool::available_cores() {
#ifdef __linux__
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) == 0 && CPU_COUNT(&set) > 0)
    return static_cast<unsigned>(CPU_COUNT(&set));
#endif
  return std::max(1u, std::thread::hardware_concurrency());
}

namespace {
// How long a worker spins for the next job before it sleeps: back-to-back steps (the usual case)
// then cost no futex wake-up; an idle solver costs at most this much CPU per job.
constexpr auto spin_for = std::chrono::microseconds(50);
} // namespace

ThreadPool::ThreadPool(unsigned threads) {
  for (unsigned i = 1; i < threads; ++i)
    workers_.emplace_back([this] { worker(); });
}

ThreadPool::~ThreadPool() {
  stop_.store(true);
  generation_.fetch_add(1);
  generation_.notify_all();
  for (std::thread& t : workers_)
    t.join();
}

void ThreadPool::parallel_for(std::size_t n, const Fn& fn) {
  const unsigned t = size();
  if (t == 1 || n < 2 * t) {
    fn(0, n);
    return;
  }
  run(n, t, fn);
}

void ThreadPool::parallel_blocks(std::size_t n, std::size_t block, const Fn& fn) {
  const std::size_t blocks = std::min<std::size_t>(n / std::max<std::size_t>(block, 1), UINT32_MAX);
  if (size() == 1 || blocks < 2) {
    fn(0, n);
    return;
  }
  run(n, std::uint32_t(blocks), fn);
}

void ThreadPool::run(std::size_t n, std::uint32_t blocks, const Fn& fn) {
  // Only the caller writes the job, and only while no block of the previous one is unfinished.
  const std::uint32_t g = generation_.load(std::memory_order_relaxed) + 1;
  fn_.store(&fn, std::memory_order_relaxed);
  n_.store(n, std::memory_order_relaxed);
  blocks_.store(blocks, std::memory_order_relaxed);
  finished_.store(0, std::memory_order_relaxed);
  claim_.store(std::uint64_t(g) << 32, std::memory_order_release);
  generation_.store(g, std::memory_order_release);
  generation_.notify_all();
  claim_loop(g);
  // Every block is claimed now; wait for the ones other threads are still running.
  for (unsigned spins = 0; finished_.load(std::memory_order_acquire) != blocks; ++spins) {
    if (spins < 4096)
      VKCLOTH_PAUSE();
    else
      std::this_thread::yield(); // a worker was preempted mid-block: let it run
  }
}

void ThreadPool::claim_loop(std::uint32_t g) {
  std::uint64_t v = claim_.load(std::memory_order_acquire);
  for (;;) {
    if (std::uint32_t(v >> 32) != g)
      return; // a later job: this one is over
    const std::uint32_t i = std::uint32_t(v);
    const Fn* fn = fn_.load(std::memory_order_relaxed);
    const std::size_t n = n_.load(std::memory_order_relaxed);
    const std::uint32_t blocks = blocks_.load(std::memory_order_relaxed);
    if (i >= blocks)
      return;
    // Succeeds only while the counter still reads (g, i): the job read above is g's, since the
    // caller replaces it only after all of g's blocks were claimed and finished.
    if (!claim_.compare_exchange_weak(v, v + 1, std::memory_order_acq_rel, std::memory_order_acquire))
      continue;
    (*fn)(n * i / blocks, n * (std::size_t(i) + 1) / blocks);
    finished_.fetch_add(1, std::memory_order_release);
    v = claim_.load(std::memory_order_acquire);
  }
}

void ThreadPool::worker() {
  // Generation 0 is the constructor's: a job (or the destructor) published before this thread
  // got to run is still seen as new.
  std::uint32_t seen = 0;
  for (;;) {
    std::uint32_t g = generation_.load(std::memory_order_acquire);
    if (g == seen) {
      const auto until = std::chrono::steady_clock::now() + spin_for;
      for (unsigned k = 1; g == seen; ++k) {
        VKCLOTH_PAUSE();
        g = generation_.load(std::memory_order_acquire);
        if (g == seen && (k & 63) == 0 && std::chrono::steady_clock::now() > until) {
          generation_.wait(seen, std::memory_order_acquire);
          g = generation_.load(std::memory_order_acquire);
        }
      }
    }
    if (stop_.load())
      return;
    seen = g;
    claim_loop(g);
  }
}

} // namespace vkcloth::detail
