// The relief replay's worker pool; see workers.h.
#include "model/relief/workers.h"

#include <algorithm>
#include <charconv>
#include <cstdlib>
#include <string_view>

namespace nbsim::relief {

int relief_threads() {
  if (const char* env = std::getenv("NBSIM_RELIEF_THREADS")) {
    const std::string_view s(env);
    int n = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), n);
    if (ec == std::errc() && end == s.data() + s.size() && n >= 1 && n <= 64) return n;
  }
  return std::clamp(static_cast<int>(std::thread::hardware_concurrency()), 1, 8);
}

namespace {
thread_local int t_slot = 0;
}  // namespace

int WorkerPool::slot() noexcept { return t_slot; }

WorkerPool::WorkerPool(int threads) {
  for (int k = 1; k < threads; ++k)
    helpers_.emplace_back([this, k](const std::stop_token& stop) {
      t_slot = k;
      helper(stop);
    });
}

// The jthreads ask their helpers to stop (waking them) and join them.
WorkerPool::~WorkerPool() = default;

void WorkerPool::helper(const std::stop_token& stop) {
  std::uint64_t seen = 0;
  for (;;) {
    {
      std::unique_lock lock(mutex_);
      if (!wake_.wait(lock, stop, [&] { return generation_ != seen; })) return;  // asked to stop
      seen = generation_;
      ++active_;
    }
    drain();
    {
      std::lock_guard lock(mutex_);
      --active_;
    }
    idle_.notify_all();
  }
}

void WorkerPool::drain() {
  for (;;) {
    const std::size_t k = next_.fetch_add(1, std::memory_order_relaxed);
    if (k >= count_) return;
    std::exception_ptr error;
    try {
      (*work_)(k);
    } catch (...) {
      error = std::current_exception();
    }
    finish(k, error);
  }
}

void WorkerPool::finish(std::size_t k, std::exception_ptr error) {
  if (error) {
    std::lock_guard lock(mutex_);
    if (!error_) error_ = error;
  }
  // Release: what work(k) wrote is seen by the thread that sees the flag (then(k)'s).
  done_[k].store(error ? 2u : 1u, std::memory_order_release);
  done_[k].notify_one();
}

void WorkerPool::run(std::size_t count, const std::function<void(std::size_t)>& work, const std::function<void(std::size_t)>& then,
                     const std::function<void()>& first) {
  {
    // A helper still inside the previous job (it found nothing left to claim) reads its fields:
    // they change only once every helper has left it.
    std::unique_lock lock(mutex_);
    idle_.wait(lock, [&] { return active_ == 0; });
    if (done_size_ < count) {
      done_ = std::make_unique<std::atomic<std::uint32_t>[]>(count);
      done_size_ = count;
    }
    for (std::size_t k = 0; k < count; ++k) done_[k].store(0, std::memory_order_relaxed);
    count_ = count;
    work_ = &work;
    next_.store(0, std::memory_order_relaxed);
    error_ = nullptr;
    ++generation_;
  }
  if (!helpers_.empty()) wake_.notify_all();
  bool failed = false;
  std::exception_ptr first_error;
  if (first) {
    try {
      first();
    } catch (...) {
      first_error = std::current_exception();
      failed = true;
    }
  }
  for (std::size_t k = 0; k < count; ++k) {
    for (;;) {
      const std::uint32_t state = done_[k].load(std::memory_order_acquire);
      if (state != 0) {
        failed = failed || state == 2;
        break;
      }
      // Not finished yet: take on unstarted work rather than wait, else wait for k's.
      const std::size_t j = next_.fetch_add(1, std::memory_order_relaxed);
      if (j < count) {
        std::exception_ptr error;
        try {
          work(j);
        } catch (...) {
          error = std::current_exception();
        }
        finish(j, error);
      } else {
        done_[k].wait(0, std::memory_order_acquire);
      }
    }
    if (!failed) then(k);
  }
  if (failed) {
    std::exception_ptr error = first_error;
    if (!error) {
      std::lock_guard lock(mutex_);
      error = error_;
    }
    std::rethrow_exception(error);
  }
}

}  // namespace nbsim::relief
