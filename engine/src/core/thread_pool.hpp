// A small fork-join pool for the CPU solver: parallel_for splits [0, n) into one contiguous chunk
// per thread. Work items are independent per particle, so results do not depend on the thread count.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace vkcloth::detail {

class ThreadPool {
public:
  /// `threads` = total threads including the caller's (1 = run everything inline).
  explicit ThreadPool(unsigned threads);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  unsigned size() const { return static_cast<unsigned>(workers_.size()) + 1; }

  /// Calls fn(begin, end) over [0, n) split across the threads; returns when all are done.
  void parallel_for(std::size_t n, const std::function<void(std::size_t, std::size_t)>& fn);

private:
  void worker(unsigned index);

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  const std::function<void(std::size_t, std::size_t)>* job_ = nullptr;
  std::size_t n_ = 0;
  std::uint64_t generation_ = 0;
  unsigned pending_ = 0;
  bool stop_ = false;
};

} // namespace vkcloth::detail
