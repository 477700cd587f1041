// A small pool of worker threads for the relief replay: the walks and exact references of a draw's
// fragments run in parallel in chunks, while the calling thread hands each chunk's results on in
// chunk order (the texel cache must see the lookups in pixel order), so that every count is the
// same whatever the number of threads.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace nbsim::relief {

// The relief replay's thread count: the environment variable NBSIM_RELIEF_THREADS when it is a
// number from 1 to 64 (1: everything on the calling thread, e.g. to check that the counts do not
// depend on it), else the machine's hardware threads, at most 8 (a draw has few enough fragments
// that more would mostly wait for the in-order hand-on). Read at every call.
int relief_threads();

class WorkerPool {
 public:
  // `threads` >= 1: the calling thread and threads - 1 helper threads (started here).
  explicit WorkerPool(int threads);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  int threads() const noexcept { return static_cast<int>(helpers_.size()) + 1; }
  // The calling thread's place in its pool, for state a work keeps per thread: 0 for the thread that
  // calls run() (and any thread outside a pool), 1 to threads() - 1 for the helpers.
  static int slot() noexcept;

  // Runs work(k) for every k in [0, count) on the helpers and the calling thread, and then(k) on
  // the calling thread in order k = 0, 1, ..., count - 1, each once work(k) has finished (the
  // calling thread takes on unstarted work while it waits). work(k) must touch nothing that
  // another work(j) or then(j) touches but what it owns for k. An exception from work(k) is
  // rethrown here, after every started work has finished (then(j) not called from k on).
  // `first` (may be empty) runs on the calling thread once the helpers have started, before any
  // then(k): work the calling thread does beside the job's (it must touch nothing a work touches);
  // an exception from it is rethrown likewise, no then(k) called.
  void run(std::size_t count, const std::function<void(std::size_t)>& work, const std::function<void(std::size_t)>& then,
           const std::function<void()>& first = {});

 private:
  void helper(const std::stop_token& stop);
  // Claims and runs unstarted work until none is left.
  void drain();
  void finish(std::size_t k, std::exception_ptr error);

  std::mutex mutex_;
  std::condition_variable_any wake_;  // a new job or stop, for the helpers
  std::condition_variable idle_;      // a helper left the job, for run()
  std::uint64_t generation_ = 0;      // the job's number (helpers take part in each once)
  int active_ = 0;                    // helpers inside the current job
  std::exception_ptr error_;          // the first work's exception
  // The current job (set by run() while no helper is active).
  std::size_t count_ = 0;
  const std::function<void(std::size_t)>* work_ = nullptr;
  std::atomic<std::size_t> next_{0};  // the next unclaimed k
  std::unique_ptr<std::atomic<std::uint32_t>[]> done_;  // per k: 1 once work(k) has finished
  std::size_t done_size_ = 0;
  std::vector<std::jthread> helpers_;
};

}  // namespace nbsim::relief
