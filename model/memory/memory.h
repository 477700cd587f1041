// The memory model shared by the depth unit and the N-buffer unit: a channel with a bandwidth and
// a latency, and set-associative caches in front of it. Plain C++ with time in cycles; SystemC
// wrappers turn the cycles into waits. Bytes moved are counted per client (depth, nbuffer, ...).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace nbsim::memory {

struct ChannelConfig {
  double bandwidth_bytes_per_cycle = 32.0;  // sustained; tunable (32 B/cycle at 1 GHz = 32 GB/s)
  int latency_cycles = 200;                 // from request to first data; tunable
};

// A channel that serves requests in order: a request of n bytes occupies it for
// n / bandwidth cycles after the earlier requests, and completes `latency` cycles after that.
class Channel {
 public:
  explicit Channel(ChannelConfig c);
  // Reserves the channel for a transfer issued at cycle `now`; returns the cycle it completes.
  std::uint64_t transfer(std::uint64_t now, std::uint64_t bytes, int client);
  int add_client(const std::string& name);  // returns the client id used by transfer()
  std::uint64_t bytes(int client) const { return bytes_.at(static_cast<std::size_t>(client)); }
  const std::vector<std::string>& clients() const noexcept { return names_; }
  std::uint64_t busy_cycles() const noexcept { return static_cast<std::uint64_t>(busy_); }
  const ChannelConfig& config() const noexcept { return c_; }

 private:
  ChannelConfig c_;
  double free_at_ = 0.0;  // cycle at which the channel can start the next transfer
  double busy_ = 0.0;
  std::vector<std::string> names_;
  std::vector<std::uint64_t> bytes_;
};

struct CacheConfig {
  int size_bytes = 64 * 1024;  // tunable; 0 disables the cache (every access misses)
  int line_bytes = 256;        // e.g. an 8x8 tile of 32-bit depth; tunable
  int ways = 4;                // associativity; tunable
};

// A set-associative cache with LRU replacement and write-back, write-allocate lines. It tracks
// tags only (the functional data lives in the cores); it reports hits, misses and write-backs.
class Cache {
 public:
  explicit Cache(CacheConfig c);
  struct Result {
    bool hit = false;
    bool writeback = false;  // the line it evicted was dirty
  };
  Result access(std::uint64_t address, bool write);
  // Writes back every dirty line; returns how many.
  std::uint64_t flush();
  void invalidate();
  std::uint64_t hits() const noexcept { return hits_; }
  std::uint64_t misses() const noexcept { return misses_; }
  std::uint64_t writebacks() const noexcept { return writebacks_; }
  const CacheConfig& config() const noexcept { return c_; }

 private:
  struct Line {
    std::uint64_t tag = 0;
    std::uint64_t used = 0;  // LRU stamp; 0 = invalid
    bool dirty = false;
  };
  CacheConfig c_;
  std::uint64_t sets_ = 0;
  bool pow2_ = false;  // line size and set count powers of two: shift and mask
  int line_shift_ = 0;
  std::uint64_t set_mask_ = 0;
  std::vector<Line> lines_;
  std::uint64_t clock_ = 0;
  std::uint64_t hits_ = 0, misses_ = 0, writebacks_ = 0;
  // The line of the last access, valid until invalidate(): accessing it again is a hit that changes
  // no LRU order (it is already the most recent of its set), so access() takes it without the search.
  static constexpr std::size_t kNoLine = ~std::size_t{0};
  std::size_t last_ = kNoLine;  // an index into lines_, so that a copied cache stays right
};

// The same LRU set-associative cache for a client that only reads and knows its lines: the same
// hits and misses as Cache given the same sequence (line = address / line_bytes; reads only, so no
// dirty lines or write-backs), faster. An LRU set holds the `ways` most recently used distinct lines
// mapped to it, whatever way each sits in; here each set keeps them in recency order (most recent
// first), so a hit on the most recent line costs one compare and nothing needs an LRU stamp.
class LineCache {
 public:
  explicit LineCache(CacheConfig c);
  // Reads `line`; true on a hit.
  bool read(std::uint64_t line) noexcept {
    if (sets_ == 0) {  // no cache: every access goes to memory
      ++misses_;
      return false;
    }
    std::uint64_t* ways = &tags_[(pow2_ ? line & set_mask_ : line % sets_) * static_cast<std::uint64_t>(ways_)];
    bool hit = false;
    switch (ways_) {  // the usual associativities unrolled (the same branch every time)
      case 1: hit = read_set<1>(ways, line); break;
      case 2: hit = read_set<2>(ways, line); break;
      case 4: hit = read_set<4>(ways, line); break;
      case 8: hit = read_set<8>(ways, line); break;
      default: hit = read_set_any(ways, line); break;
    }
    ++(hit ? hits_ : misses_);
    return hit;
  }
  // Reads every line of `lines` in order (as read() one by one); returns how many hit.
  std::uint64_t read_all(std::span<const std::uint64_t> lines) noexcept {
    switch (ways_) {  // chosen once for the whole sequence
      case 1: return read_all_ways<1>(lines);
      case 2: return read_all_ways<2>(lines);
      case 4: return vector_sets_ && sets_ > 0 ? read_all_4_lanes(lines) : read_all_ways<4>(lines);
      case 8: return read_all_ways<8>(lines);
      default: {
        std::uint64_t hits = 0;
        for (const std::uint64_t line : lines) hits += read(line) ? 1 : 0;
        return hits;
      }
    }
  }
  void invalidate();
  std::uint64_t hits() const noexcept { return hits_; }
  std::uint64_t misses() const noexcept { return misses_; }
  const CacheConfig& config() const noexcept { return c_; }

 private:
  // read_all_ways<4> with each set's four ways in one AVX2 register (the CPU has AVX2): the
  // compare, the shift of the ways before the hit and the new line's insertion as three vector
  // operations instead of a chain of scalar ones.
  std::uint64_t read_all_4_lanes(std::span<const std::uint64_t> lines) noexcept;
  template <int W>
  std::uint64_t read_all_ways(std::span<const std::uint64_t> lines) noexcept {
    if (sets_ == 0) {
      misses_ += lines.size();
      return 0;
    }
    std::uint64_t hits = 0;
    for (const std::uint64_t line : lines)
      hits += read_set<W>(&tags_[(pow2_ ? line & set_mask_ : line % sets_) * W], line) ? 1 : 0;
    hits_ += hits;
    misses_ += lines.size() - hits;
    return hits;
  }
  // One set of W ways, most recently used first: `line` goes first and the lines before its place
  // (or all but the last, evicted, on a miss) move back one, without a branch on where it was.
  template <int W>
  static bool read_set(std::uint64_t* ways, std::uint64_t line) noexcept {
    std::uint64_t old[W];
    for (int k = 0; k < W; ++k) old[k] = ways[k];
    bool seen = false;  // `line` is among the ways before k
    ways[0] = line;
    for (int k = 1; k < W; ++k) {
      seen = seen || old[k - 1] == line;
      ways[k] = seen ? old[k] : old[k - 1];
    }
    return seen || old[W - 1] == line;
  }
  bool read_set_any(std::uint64_t* ways, std::uint64_t line) const noexcept {
    int k = 0;
    while (k < ways_ && ways[k] != line) ++k;
    const bool hit = k < ways_;
    for (k = hit ? k : ways_ - 1; k > 0; --k) ways[k] = ways[k - 1];
    ways[0] = line;
    return hit;
  }

  // No address has this line (line_bytes >= 2): it marks an invalid way, which sorts last.
  static constexpr std::uint64_t kInvalid = ~std::uint64_t{0};
  CacheConfig c_;
  std::uint64_t sets_ = 0;
  int ways_ = 0;
  bool pow2_ = false;
  std::uint64_t set_mask_ = 0;
  bool vector_sets_ = false;  // read_all_4_lanes runs here
  std::vector<std::uint64_t> tags_;  // sets * ways, each set most recently used first
  std::uint64_t hits_ = 0, misses_ = 0;
};

}  // namespace nbsim::memory
