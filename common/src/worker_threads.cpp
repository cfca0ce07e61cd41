#include "livo/worker_threads.hpp"

#include <algorithm>
#include <stdexcept>

namespace livo {

WorkerThreads::WorkerThreads(int threads) {
  if (threads < 1) throw std::invalid_argument("WorkerThreads: at least one thread (the caller)");
  for (int slot = 1; slot < threads; ++slot) helpers_.emplace_back([this, slot] { helperLoop(slot); });
}

WorkerThreads::~WorkerThreads() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  start_.notify_all();
  for (auto& t : helpers_) t.join();
}

void WorkerThreads::forEachShare(size_t n, const std::function<void(size_t, size_t)>& fn, size_t min_share) {
  const size_t max_shares = n / std::max<size_t>(1, min_share);
  const int shares =
      static_cast<int>(std::min<size_t>(static_cast<size_t>(threads()), std::max<size_t>(1, max_shares)));
  if (shares == 1) {
    fn(0, n);
    return;
  }
  std::lock_guard<std::mutex> call(call_mutex_);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    job_ = &fn;
    n_ = n;
    shares_ = shares;
    pending_ = shares - 1;
    error_ = nullptr;
    ++generation_;
  }
  start_.notify_all();
  std::exception_ptr mine;
  try {
    fn(0, n / static_cast<size_t>(shares));
  } catch (...) {
    mine = std::current_exception();
  }
  std::unique_lock<std::mutex> lock(mutex_);
  done_.wait(lock, [this] { return pending_ == 0; });
  job_ = nullptr;
  if (mine) std::rethrow_exception(mine);
  if (error_) std::rethrow_exception(error_);
}

void WorkerThreads::helperLoop(int slot) {
  uint64_t seen = 0;
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    start_.wait(lock, [&] { return stop_ || generation_ != seen; });
    if (stop_) return;
    seen = generation_;
    if (slot >= shares_) continue;  // this job needs fewer threads
    const auto* job = job_;
    const size_t n = n_, shares = static_cast<size_t>(shares_), s = static_cast<size_t>(slot);
    lock.unlock();
    std::exception_ptr error;
    try {
      (*job)(n * s / shares, n * (s + 1) / shares);
    } catch (...) {
      error = std::current_exception();
    }
    lock.lock();
    if (error && !error_) error_ = error;
    if (--pending_ == 0) done_.notify_one();
  }
}

}  // namespace livo
