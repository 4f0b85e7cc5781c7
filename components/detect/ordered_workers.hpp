#pragma once
// Jobs on a few worker threads, results handed back in the order the jobs were submitted: two
// single-thread copies of a network on alternate frames use both cores better than one network on
// two threads (docs/models.md). Worker i always runs with copy i of whatever the job needs (the
// job gets its index). At most one job per worker is in flight: submit() waits for a free worker,
// so nothing queues up behind busy workers (a live source's newest frame is taken only when a
// worker can start on it).
//
// Used from one thread (the owner's: submit, next, pending); the workers only run jobs.

#include <algorithm>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

namespace mocap::detect {

template <class Result>
class OrderedWorkers {
 public:
  using Job = std::function<Result(int worker)>;

  explicit OrderedWorkers(int workers) {
    for (int i = 0; i < std::max(workers, 1); ++i) threads_.emplace_back([this, i] { work(i); });
  }
  ~OrderedWorkers() {
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
    }
    wake_workers_.notify_all();
    for (std::thread& t : threads_) t.join();
  }
  OrderedWorkers(const OrderedWorkers&) = delete;
  OrderedWorkers& operator=(const OrderedWorkers&) = delete;

  int workers() const { return static_cast<int>(threads_.size()); }

  // Waits until a worker is free, then hands it `job`.
  void submit(Job job) {
    auto slot = std::make_shared<Slot>();
    std::unique_lock lock(mutex_);
    job_done_.wait(lock, [&] { return running_ + queued_.size() < threads_.size(); });
    queued_.push_back({std::move(job), slot});
    order_.push_back(std::move(slot));
    lock.unlock();
    wake_workers_.notify_one();
  }

  // Submitted jobs whose results were not taken yet.
  std::size_t pending() const { return order_.size(); }

  // Waits until the oldest job is done, leaving its result to next() (returns at once when nothing
  // is pending).
  void wait_oldest() {
    if (order_.empty()) return;
    std::unique_lock lock(mutex_);
    const std::shared_ptr<Slot> slot = order_.front();
    job_done_.wait(lock, [&] { return slot->done; });
  }

  // The oldest job's result once it is done: waits for it when `wait`, else returns nothing when
  // it is still running (or nothing is pending). Rethrows what the job threw.
  std::optional<Result> next(bool wait) {
    if (order_.empty()) return std::nullopt;
    std::unique_lock lock(mutex_);
    const std::shared_ptr<Slot> slot = order_.front();
    if (wait)
      job_done_.wait(lock, [&] { return slot->done; });
    else if (!slot->done)
      return std::nullopt;
    order_.pop_front();
    if (slot->error) std::rethrow_exception(slot->error);
    return std::move(slot->result);
  }

 private:
  struct Slot {
    bool done = false;
    std::optional<Result> result;
    std::exception_ptr error;
  };
  struct Queued {
    Job job;
    std::shared_ptr<Slot> slot;
  };

  void work(int index) {
    std::unique_lock lock(mutex_);
    while (true) {
      wake_workers_.wait(lock, [&] { return stopping_ || !queued_.empty(); });
      if (stopping_) return;
      Queued q = std::move(queued_.front());
      queued_.pop_front();
      ++running_;
      lock.unlock();
      std::optional<Result> result;
      std::exception_ptr error;
      try {
        result.emplace(q.job(index));
      } catch (...) {
        error = std::current_exception();
      }
      lock.lock();
      q.slot->result = std::move(result);
      q.slot->error = error;
      q.slot->done = true;
      --running_;
      job_done_.notify_all();
    }
  }

  std::vector<std::thread> threads_;
  std::mutex mutex_;
  std::condition_variable wake_workers_, job_done_;
  std::deque<Queued> queued_;                // submitted, no worker yet
  std::deque<std::shared_ptr<Slot>> order_;  // submitted, result not taken, oldest first
  std::size_t running_ = 0;
  bool stopping_ = false;
};

}  // namespace mocap::detect
