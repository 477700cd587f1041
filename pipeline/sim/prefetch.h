// One item read ahead on a thread of its own: while the simulation replays frame k, the next frame
// is read and decoded (decompression and parsing are a tenth of a replay's time, and the replay
// itself runs on SystemC's one thread, so the host's other core would otherwise idle).
//
// next() hands the items over in the source's order, so a replay is the same with or without the
// read-ahead. The source runs on the prefetch thread only; at most one item waits beside the one the
// caller holds. An exception the source throws is rethrown by next() (and by every call after it),
// on the caller's thread. After the source's end (nullopt) next() keeps returning nullopt. The
// destructor stops the thread, also while the caller has not read everything (an error elsewhere).
#pragma once

#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>

namespace nbsim::sim {

template <class T>
class Prefetch {
 public:
  using Source = std::function<std::optional<T>()>;

  explicit Prefetch(Source source) : source_(std::move(source)), thread_([this] { run(); }) {}
  Prefetch(const Prefetch&) = delete;
  Prefetch& operator=(const Prefetch&) = delete;
  ~Prefetch() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    changed_.notify_all();
    thread_.join();
  }

  std::optional<T> next() {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return full_; });
    if (error_) std::rethrow_exception(error_);
    if (!slot_) return std::nullopt;  // the end: full_ stays set, so every later call lands here
    std::optional<T> item = std::move(slot_);
    slot_.reset();
    full_ = false;
    changed_.notify_all();
    return item;
  }

 private:
  void run() {
    for (;;) {
      {  // the next item is read only once the caller took the last one: one item ahead, no more
        std::unique_lock<std::mutex> lock(mutex_);
        changed_.wait(lock, [this] { return !full_ || stop_; });
        if (stop_) return;
      }
      std::optional<T> item;
      std::exception_ptr error;
      try {
        item = source_();
      } catch (...) {
        error = std::current_exception();
      }
      const bool last = !item || error;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        slot_ = std::move(item);
        error_ = error;
        full_ = true;
      }
      changed_.notify_all();
      if (last) return;
    }
  }

  Source source_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::optional<T> slot_;
  std::exception_ptr error_;
  bool full_ = false;  // slot_ (or error_, or the end) waits for the caller
  bool stop_ = false;
  std::thread thread_;  // last: started once every member above is constructed
};

}  // namespace nbsim::sim
