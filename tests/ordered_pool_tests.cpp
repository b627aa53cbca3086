// The worker pool behind `strata video`'s frame writer: every job runs, one worker keeps the
// order, failures come back in submission order, and memory and shutdown stay bounded.
#include <doctest/doctest.h>

#include <atomic>
#include <chrono>
#include <future>
#include <stdexcept>
#include <thread>
#include <vector>

#include "engine/core/ordered_pool.h"

namespace strata {
namespace {

using namespace std::chrono_literals;

}  // namespace

TEST_SUITE("cpu") {
  TEST_CASE("ordered_pool_runs_every_job_before_finish_returns") {
    std::atomic<int> done{0};
    OrderedPool pool(3, 6);
    for (int i = 0; i < 50; ++i) pool.submit([&] { ++done; });
    pool.finish();
    CHECK(done == 50);
  }

  TEST_CASE("ordered_pool_with_one_worker_runs_jobs_in_submission_order") {
    std::vector<int> order;  // (one worker: no two jobs at once)
    OrderedPool pool(1, 2);
    for (int i = 0; i < 20; ++i) pool.submit([&order, i] { order.push_back(i); });
    pool.finish();
    REQUIRE(order.size() == 20);
    for (int i = 0; i < 20; ++i) CHECK(order[size_t(i)] == i);
  }

  TEST_CASE("ordered_pool_without_workers_runs_each_job_in_submit_and_throws_there") {
    OrderedPool pool(0, 1);
    std::thread::id ran_on;
    pool.submit([&] { ran_on = std::this_thread::get_id(); });
    CHECK(ran_on == std::this_thread::get_id());
    CHECK_THROWS_WITH(pool.submit([] { throw std::runtime_error("frame 1"); }), "frame 1");
  }

  TEST_CASE("ordered_pool_reports_the_first_failure_by_submission_order_not_by_time") {
    OrderedPool pool(2, 4);
    pool.submit([] {
      std::this_thread::sleep_for(100ms);
      throw std::runtime_error("job 0");
    });
    pool.submit([] { throw std::runtime_error("job 1"); });  // fails first
    CHECK_THROWS_WITH(pool.finish(), "job 0");
    // Once failed, the pool takes no more work and says why.
    CHECK_THROWS_WITH(pool.submit([] {}), "job 0");
  }

  TEST_CASE("ordered_pool_submit_waits_while_capacity_jobs_are_unfinished") {
    std::promise<void> release;
    std::shared_future<void> released = release.get_future().share();
    OrderedPool pool(2, 2);
    for (int i = 0; i < 2; ++i) pool.submit([released] { released.wait(); });
    auto third = std::async(std::launch::async, [&] { pool.submit([] {}); });
    CHECK(third.wait_for(100ms) == std::future_status::timeout);
    release.set_value();
    CHECK(third.wait_for(10s) == std::future_status::ready);
    third.get();
    pool.finish();
  }

  TEST_CASE("ordered_pool_destroyed_with_queued_jobs_drops_them_without_waiting") {
    std::atomic<int> ran{0};
    const auto start = std::chrono::steady_clock::now();
    {
      OrderedPool pool(1, 8);
      for (int i = 0; i < 8; ++i) {
        pool.submit([&] {
          ++ran;
          std::this_thread::sleep_for(50ms);
        });
      }
    }
    CHECK(ran <= 1);  // (the job running, if the worker had taken one)
    CHECK(std::chrono::steady_clock::now() - start < 300ms);
  }
}

}  // namespace strata
