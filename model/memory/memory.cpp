// Memory channel and cache models; see memory.h.
#include "model/memory/memory.h"

#include <algorithm>
#include <cmath>

#include "model/common/error.h"

#if defined(__x86_64__)
#include <immintrin.h>
#endif

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
#if defined(__x86_64__) && !defined(NBSIM_BASELINE_ONLY)
  vector_sets_ = __builtin_cpu_supports("avx2");
#endif
}

#if defined(__x86_64__) && !defined(NBSIM_BASELINE_ONLY)
namespace {
// For each hit mask (bit k: way k holds the line), the ways that keep their line: way k (k >= 1)
// when the line is at a way before it; the others take the line of the way before them.
struct KeepMasks {
  alignas(32) std::int64_t lanes[16][4];
  constexpr KeepMasks() : lanes{} {
    for (int m = 0; m < 16; ++m)
      for (int k = 1; k < 4; ++k) lanes[m][k] = (m & ((1 << k) - 1)) != 0 ? -1 : 0;
  }
};
constexpr KeepMasks kKeep;
}  // namespace

[[gnu::target("avx2")]] std::uint64_t LineCache::read_all_4_lanes(std::span<const std::uint64_t> lines) noexcept {
  std::uint64_t hits = 0;
  std::uint64_t* const tags = tags_.data();
  for (const std::uint64_t line : lines) {
    auto* set = reinterpret_cast<__m256i*>(tags + (pow2_ ? line & set_mask_ : line % sets_) * 4);
    const __m256i old = _mm256_loadu_si256(set);
    const __m256i wanted = _mm256_set1_epi64x(static_cast<long long>(line));
    const int at = _mm256_movemask_pd(_mm256_castsi256_pd(_mm256_cmpeq_epi64(old, wanted)));
    // [line, old 0, old 1, old 2] with the ways after the hit keeping theirs.
    const __m256i back = _mm256_permute4x64_epi64(old, 0x90);
    const __m256i keep = _mm256_load_si256(reinterpret_cast<const __m256i*>(kKeep.lanes[at]));
    _mm256_storeu_si256(set, _mm256_blend_epi32(_mm256_blendv_epi8(back, old, keep), wanted, 0x03));
    hits += at != 0 ? 1 : 0;
  }
  hits_ += hits;
  misses_ += lines.size() - hits;
  return hits;
}
#else
std::uint64_t LineCache::read_all_4_lanes(std::span<const std::uint64_t> lines) noexcept { return read_all_ways<4>(lines); }
#endif

void LineCache::invalidate() { std::fill(tags_.begin(), tags_.end(), kInvalid); }

}  // namespace nbsim::memory
