#include "posedb/parallel_chunks.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace mocap::posedb {

void for_each_chunk(std::size_t chunks, int threads, const std::function<void(std::size_t)>& work,
                    const std::function<void(std::size_t)>& after_own_chunk) {
  std::atomic<std::size_t> next{0};
  std::atomic<std::size_t> done{0};
  std::atomic<bool> failed{false};
  std::exception_ptr first_error;
  std::mutex error_mutex;

  auto run = [&](bool reports) {
    for (std::size_t chunk = next++; chunk < chunks && !failed; chunk = next++) {
      try {
        work(chunk);
      } catch (...) {
        const std::lock_guard lock(error_mutex);
        if (!first_error) first_error = std::current_exception();
        failed = true;
        return;
      }
      const std::size_t finished = ++done;
      if (reports && after_own_chunk) after_own_chunk(finished);
    }
  };

  const std::size_t helpers =
      std::min<std::size_t>(static_cast<std::size_t>(std::max(threads, 1)) - 1, chunks);
  {
    std::vector<std::jthread> pool;
    pool.reserve(helpers);
    for (std::size_t t = 0; t < helpers; ++t) pool.emplace_back(run, false);
    run(true);
  }  // joins the helpers
  if (first_error) std::rethrow_exception(first_error);
}

}  // namespace mocap::posedb
