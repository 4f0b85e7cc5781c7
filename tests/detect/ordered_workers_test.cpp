// OrderedWorkers: jobs on several threads, results in submission order whatever order they finish
// in, at most one job per worker in flight, a job's exception rethrown at its turn.

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>

#include "detect/ordered_workers.hpp"

namespace mocap::detect {
namespace {

using namespace std::chrono_literals;

TEST(OrderedWorkers, ResultsComeBackInSubmissionOrder) {
  OrderedWorkers<int> pool(3);
  std::vector<int> got;
  for (int i = 0; i < 12; ++i) {
    // Later jobs are quicker: they finish before earlier ones.
    pool.submit([i](int) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2 * ((12 - i) % 4)));
      return i;
    });
    while (auto r = pool.next(false)) got.push_back(*r);
  }
  while (auto r = pool.next(true)) got.push_back(*r);
  ASSERT_EQ(got.size(), 12u);
  for (int i = 0; i < 12; ++i) EXPECT_EQ(got[static_cast<std::size_t>(i)], i);
  EXPECT_EQ(pool.pending(), 0u);
}

TEST(OrderedWorkers, NeverRunsMoreJobsThanWorkersAndEachWorkerHasItsIndex) {
  OrderedWorkers<int> pool(2);
  std::atomic<int> running{0}, most{0};
  for (int i = 0; i < 8; ++i) {
    pool.submit([&](int worker) {
      const int now = ++running;
      most = std::max(most.load(), now);
      std::this_thread::sleep_for(3ms);
      --running;
      return worker;
    });
    EXPECT_LE(pool.pending(), 8u);
  }
  while (auto r = pool.next(true)) {
    EXPECT_GE(*r, 0);
    EXPECT_LT(*r, 2);
  }
  EXPECT_LE(most.load(), 2);
}

TEST(OrderedWorkers, AJobsExceptionIsRethrownInItsTurnAndLaterResultsFollow) {
  OrderedWorkers<int> pool(2);
  pool.submit([](int) { return 1; });
  pool.submit([](int) -> int { throw std::runtime_error("broken frame"); });
  pool.submit([](int) { return 3; });
  EXPECT_EQ(pool.next(true), 1);
  EXPECT_THROW(pool.next(true), std::runtime_error);
  EXPECT_EQ(pool.next(true), 3);
  EXPECT_EQ(pool.next(true), std::nullopt);
}

}  // namespace
}  // namespace mocap::detect
