#pragma once
// A minimal parallel loop for the long passes of k-means: chunks are handed out one at a time
// through an atomic counter, so a thread slowed down by another user of the machine does not hold
// up the others.

#include <cstddef>
#include <functional>

namespace mocap::posedb {

// Calls work(chunk) for every chunk in [0, chunks) on `threads` threads, the calling thread
// included. after_own_chunk(done), if set, runs on the calling thread only, after each chunk it
// processed, with the number of chunks finished by all threads so far: a progress callback then
// never runs concurrently with itself. The first exception thrown by `work` is rethrown here
// after all threads have stopped.
void for_each_chunk(std::size_t chunks, int threads, const std::function<void(std::size_t)>& work,
                    const std::function<void(std::size_t)>& after_own_chunk = {});

}  // namespace mocap::posedb
