#include "engine/core/ordered_pool.h"

#include <algorithm>

namespace strata {

OrderedPool::OrderedPool(unsigned workers, size_t capacity)
    : capacity_(std::max<size_t>(capacity, 1)) {
  for (unsigned i = 0; i < workers; ++i) threads_.emplace_back([this] { work(); });
}

OrderedPool::~OrderedPool() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    queue_.clear();
  }
  job_ready_.notify_all();
  for (std::thread& thread : threads_) thread.join();
}

void OrderedPool::submit(std::function<void()> job) {
  if (threads_.empty()) {
    job();
    return;
  }
  std::unique_lock lock(mutex_);
  job_done_.wait(lock, [this] {
    collect();
    return failure_ || outcomes_.size() < capacity_;
  });
  if (failure_) std::rethrow_exception(failure_);
  queue_.push_back({collected_ + outcomes_.size(), std::move(job)});
  outcomes_.emplace_back();
  lock.unlock();
  job_ready_.notify_one();
}

void OrderedPool::finish() {
  std::unique_lock lock(mutex_);
  job_done_.wait(lock, [this] {
    collect();
    return outcomes_.empty();
  });
  if (failure_) std::rethrow_exception(failure_);
}

void OrderedPool::work() {
  std::unique_lock lock(mutex_);
  for (;;) {
    job_ready_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
    if (queue_.empty()) return;
    Job job = std::move(queue_.front());
    queue_.pop_front();
    std::exception_ptr error;
    // (failure_ is set only once every job before the failing one is done: what is still queued
    // comes after it and is dropped)
    if (!failure_) {
      lock.unlock();
      try {
        job.work();
      } catch (...) {
        error = std::current_exception();
      }
      job.work = nullptr;  // (the job's data freed outside the lock)
      lock.lock();
    }
    outcomes_[job.index - collected_] = {true, error};
    job_done_.notify_all();
  }
}

// Takes the outcomes of the finished jobs at the front, in submission order (mutex_ held).
void OrderedPool::collect() {
  while (!outcomes_.empty() && outcomes_.front().done) {
    if (outcomes_.front().error && !failure_) failure_ = outcomes_.front().error;
    outcomes_.pop_front();
    ++collected_;
  }
}

}  // namespace strata
