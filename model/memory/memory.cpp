// Memory channel and cache models; see memory.h.
#include "model/memory/memory.h"

#include <algorithm>
#include <cmath>

#include "model/common/error.h"

namespace nbsim::memory {

Channel::Channel(ChannelConfig c) : c_(c) {
  NBSIM_CHECK(c.bandwidth_bytes_per_cycle > 0 && c.latency_cycles >= 0, "memory channel config not validated");
}

int Channel::add_client(const std::string& name) {
  names_.push_back(name);
  bytes_.push_back(0);
  return static_cast<int>(names_.size() - 1);
}

std::uint64_t Channel::transfer(std::uint64_t now, std::uint64_t bytes, int client) {
  NBSIM_CHECK(client >= 0 && static_cast<std::size_t>(client) < bytes_.size(), "unknown memory client");
  bytes_[static_cast<std::size_t>(client)] += bytes;
  const double start = std::max(static_cast<double>(now), free_at_);
  const double occupy = static_cast<double>(bytes) / c_.bandwidth_bytes_per_cycle;
  free_at_ = start + occupy;
  busy_ += occupy;
  return static_cast<std::uint64_t>(std::ceil(free_at_)) + static_cast<std::uint64_t>(c_.latency_cycles);
}

Cache::Cache(CacheConfig c) : c_(c) {
  NBSIM_CHECK(c.size_bytes >= 0 && c.line_bytes > 0 && c.ways > 0, "cache config not validated");
  sets_ = static_cast<std::uint64_t>(c.size_bytes) / static_cast<std::uint64_t>(c.line_bytes * c.ways);
  lines_.assign(sets_ * static_cast<std::uint64_t>(c.ways), Line{});
  // Powers of two (the usual sizes) index with a shift and a mask instead of two divisions.
  const auto line = static_cast<std::uint64_t>(c.line_bytes);
  if ((line & (line - 1)) == 0 && sets_ > 0 && (sets_ & (sets_ - 1)) == 0) {
    line_shift_ = 0;
    while ((std::uint64_t{1} << line_shift_) < line) ++line_shift_;
    set_mask_ = sets_ - 1;
    pow2_ = true;
  }
}

Cache::Result Cache::access(std::uint64_t address, bool write) {
  Result r;
  if (sets_ == 0) {  // no cache: every access goes to memory
    ++misses_;
    return r;
  }
  const std::uint64_t line = pow2_ ? address >> line_shift_ : address / static_cast<std::uint64_t>(c_.line_bytes);
  if (last_ != kNoLine && lines_[last_].tag == line && lines_[last_].used) {
    lines_[last_].dirty = lines_[last_].dirty || write;
    ++hits_;
    r.hit = true;
    return r;
  }
  const std::uint64_t set = pow2_ ? line & set_mask_ : line % sets_;
  Line* ways = &lines_[set * static_cast<std::uint64_t>(c_.ways)];
  ++clock_;
  Line* victim = ways;
  for (int w = 0; w < c_.ways; ++w) {
    Line& l = ways[w];
    if (l.used && l.tag == line) {
      l.used = clock_;
      l.dirty = l.dirty || write;
      ++hits_;
      r.hit = true;
      last_ = static_cast<std::size_t>(&l - lines_.data());
      return r;
    }
    if (l.used < victim->used) victim = &l;  // invalid lines (used == 0) go first
  }
  ++misses_;
  if (victim->used && victim->dirty) {
    r.writeback = true;
    ++writebacks_;
  }
  *victim = {line, clock_, write};
  last_ = static_cast<std::size_t>(victim - lines_.data());
  return r;
}

std::uint64_t Cache::flush() {
  std::uint64_t n = 0;
  for (Line& l : lines_)
    if (l.used && l.dirty) ++n, l.dirty = false;
  writebacks_ += n;
  return n;
}

void Cache::invalidate() {
  std::fill(lines_.begin(), lines_.end(), Line{});
  last_ = kNoLine;
}

LineCache::LineCache(CacheConfig c) : c_(c) {
  NBSIM_CHECK(c.size_bytes >= 0 && c.line_bytes > 1 && c.ways > 0, "line cache config not validated");
  sets_ = static_cast<std::uint64_t>(c.size_bytes) / static_cast<std::uint64_t>(c.line_bytes * c.ways);
  ways_ = c.ways;
  tags_.assign(sets_ * static_cast<std::uint64_t>(c.ways), kInvalid);
  if (sets_ > 0 && (sets_ & (sets_ - 1)) == 0) {
    set_mask_ = sets_ - 1;
    pow2_ = true;
  }
}

void LineCache::invalidate() { std::fill(tags_.begin(), tags_.end(), kInvalid); }

}  // namespace nbsim::memory
