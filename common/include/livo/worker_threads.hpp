// A small fixed team of threads that shares out index ranges: the calling thread takes the first
// share, each helper thread one of the others. Meant for per-point work whose results go to
// per-point slots (the neighbour searches of a registration), so that the outcome is the same,
// bit for bit, whatever the number of threads.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace livo {

class WorkerThreads {
 public:
  /// `threads` in all, the caller included: 1 starts no helper thread.
  explicit WorkerThreads(int threads);
  ~WorkerThreads();
  WorkerThreads(const WorkerThreads&) = delete;
  WorkerThreads& operator=(const WorkerThreads&) = delete;

  int threads() const { return static_cast<int>(helpers_.size()) + 1; }

  /// Calls fn(begin, end) on contiguous shares of [0, n), at once on up to threads() threads, and
  /// returns when all are done (an exception thrown by fn is rethrown here). Each share holds at
  /// least min_share indices (fewer threads for small n; n < 2 * min_share runs in the caller).
  /// Calls from different threads take turns.
  void forEachShare(size_t n, const std::function<void(size_t, size_t)>& fn, size_t min_share = 1);

 private:
  void helperLoop(int slot);

  std::vector<std::thread> helpers_;
  std::mutex call_mutex_;  // one forEachShare at a time
  std::mutex mutex_;       // guards the job below
  std::condition_variable start_, done_;
  const std::function<void(size_t, size_t)>* job_ = nullptr;
  size_t n_ = 0;
  int shares_ = 0;
  int pending_ = 0;
  uint64_t generation_ = 0;
  bool stop_ = false;
  std::exception_ptr error_;
};

}  // namespace livo
