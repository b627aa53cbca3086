// Jobs on worker threads whose failures come back in the order the jobs were given: the error
// reported is the first failing job's by submission order, even when a later job failed sooner,
// so a run with workers says what the same run one job after another would have said. Memory
// stays bounded: submit() waits while `capacity` jobs are queued or running.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace strata {

class OrderedPool {
 public:
  // No workers: submit() runs each job itself, on the caller's thread. One worker: the jobs run
  // one after another in submission order (an encoder's frames).
  OrderedPool(unsigned workers, size_t capacity);
  // Jobs not started are dropped, running ones finish; nothing is thrown.
  ~OrderedPool();
  OrderedPool(const OrderedPool&) = delete;
  OrderedPool& operator=(const OrderedPool&) = delete;

  // Queues `job`, after waiting for room. Rethrows the first failure among the jobs before it;
  // after a failure, the jobs queued behind the failing one are dropped.
  void submit(std::function<void()> job);
  // Waits for every job, then rethrows the first failure, if any.
  void finish();

  unsigned workers() const { return unsigned(threads_.size()); }

 private:
  struct Outcome {
    bool done = false;
    std::exception_ptr error;
  };
  struct Job {
    size_t index = 0;
    std::function<void()> work;
  };

  void work();
  void collect();

  size_t capacity_;
  std::mutex mutex_;
  std::condition_variable job_ready_, job_done_;
  std::deque<Job> queue_;
  std::deque<Outcome> outcomes_;  // of the jobs from collected_ on, in submission order
  size_t collected_ = 0;          // the jobs before it are done and their outcome taken
  std::exception_ptr failure_;    // the first failure in submission order
  bool stopping_ = false;
  std::vector<std::thread> threads_;  // (last: started once the rest is set up)
};

}  // namespace strata
