// Statistics are the product (docs/architecture.md, "Code conventions"): counters are always on,
// declared once with a name, a unit and a description, grouped per unit under the module
// hierarchy's full name ("gpu.nbuffer"), and ratios are derived when the statistics are dumped.
// Plain C++: SystemC wrappers own the groups.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace nbsim::stats {

// A monotonically counted quantity (events, bytes, cycles), or, declared with Group::maximum, the
// largest value seen (raise_to).
class Counter {
 public:
  Counter(std::string name, std::string unit, std::string description)
      : name_(std::move(name)), unit_(std::move(unit)), description_(std::move(description)) {}
  Counter& operator+=(std::uint64_t n) noexcept { value_ += n; return *this; }
  Counter& operator++() noexcept { ++value_; return *this; }
  void raise_to(std::uint64_t n) noexcept { value_ = n > value_ ? n : value_; }
  std::uint64_t value() const noexcept { return value_; }
  void reset() noexcept { value_ = 0; }
  const std::string& name() const noexcept { return name_; }
  const std::string& unit() const noexcept { return unit_; }
  const std::string& description() const noexcept { return description_; }

 private:
  std::string name_, unit_, description_;
  std::uint64_t value_ = 0;
};

// A counter with one bucket per label (per level, per tile class, per draw role).
class VectorCounter {
 public:
  VectorCounter(std::string name, std::string unit, std::string description, std::vector<std::string> labels);
  void add(std::size_t bucket, std::uint64_t n = 1);
  std::uint64_t value(std::size_t bucket) const { return values_.at(bucket); }
  std::uint64_t total() const noexcept;
  std::size_t size() const noexcept { return values_.size(); }
  void reset() noexcept;
  const std::string& name() const noexcept { return name_; }
  const std::string& unit() const noexcept { return unit_; }
  const std::string& description() const noexcept { return description_; }
  const std::vector<std::string>& labels() const noexcept { return labels_; }

 private:
  std::string name_, unit_, description_;
  std::vector<std::string> labels_;
  std::vector<std::uint64_t> values_;
};

// A value derived from counters when dumped (a ratio, a rate); NaN-free: division by zero gives 0.
struct Formula {
  std::string name, unit, description;
  std::function<double()> value;
};

// The statistics of one unit. Names are unique within a group; declaring a name twice is a bug.
class Group {
 public:
  explicit Group(std::string full_name) : name_(std::move(full_name)) {}
  Group(const Group&) = delete;
  Group& operator=(const Group&) = delete;

  Counter& counter(const std::string& name, const std::string& unit, const std::string& description);
  // The largest of the values given to raise_to() (e.g. the most lookups one query took).
  Counter& maximum(const std::string& name, const std::string& unit, const std::string& description);
  VectorCounter& vector(const std::string& name, const std::string& unit, const std::string& description,
                        std::vector<std::string> labels);
  void formula(const std::string& name, const std::string& unit, const std::string& description, std::function<double()> f);

  const std::string& name() const noexcept { return name_; }
  void reset();
  // {"counter": value, ..., "vector": {"label": value, ...}, "formula": value}
  nlohmann::ordered_json values() const;
  // [{"name": "gpu.nbuffer.lookups", "unit": ..., "description": ...}, ...]
  nlohmann::ordered_json describe() const;
  // Flat (full name, value) pairs, vectors as name.label, for CSV rows.
  void flatten(std::vector<std::pair<std::string, double>>& out) const;

 private:
  void claim(const std::string& name);
  std::string name_;
  std::deque<Counter> counters_;  // deque: references stay valid as counters are added
  std::deque<VectorCounter> vectors_;
  std::vector<Formula> formulas_;
  std::vector<std::string> order_;  // declaration order, for stable output
  std::map<std::string, char> kinds_;
};

// All groups of a run, in registration order.
class Registry {
 public:
  Group& group(const std::string& full_name);  // creates it on first use
  const Group* find(const std::string& full_name) const;
  void reset();
  nlohmann::ordered_json values() const;    // {"gpu.nbuffer": {...}, ...}
  nlohmann::ordered_json describe() const;  // every statistic with its unit and description
  std::vector<std::pair<std::string, double>> flatten() const;

 private:
  std::deque<Group> groups_;
};

// a / b, or 0 when b is 0.
inline double ratio(double a, double b) noexcept { return b == 0.0 ? 0.0 : a / b; }

}  // namespace nbsim::stats
