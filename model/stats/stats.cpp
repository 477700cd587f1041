// Statistics groups and registry; see stats.h.
#include "model/stats/stats.h"

#include <numeric>

#include "model/common/error.h"

namespace nbsim::stats {

VectorCounter::VectorCounter(std::string name, std::string unit, std::string description, std::vector<std::string> labels)
    : name_(std::move(name)), unit_(std::move(unit)), description_(std::move(description)), labels_(std::move(labels)),
      values_(labels_.size(), 0) {}

void VectorCounter::add(std::size_t bucket, std::uint64_t n) {
  NBSIM_CHECK(bucket < values_.size(), "statistic " + name_ + ": bucket out of range");
  values_[bucket] += n;
}

std::uint64_t VectorCounter::total() const noexcept { return std::accumulate(values_.begin(), values_.end(), std::uint64_t{0}); }

void VectorCounter::reset() noexcept { std::fill(values_.begin(), values_.end(), 0); }

void Group::claim(const std::string& name) {
  NBSIM_CHECK(!name.empty() && name.find('.') == std::string::npos, "statistic name '" + name + "' must be one word");
  NBSIM_CHECK(!kinds_.count(name), "statistic " + name_ + "." + name + " declared twice");
  order_.push_back(name);
}

Counter& Group::counter(const std::string& name, const std::string& unit, const std::string& description) {
  claim(name);
  kinds_[name] = 'c';
  return counters_.emplace_back(name, unit, description);
}

Counter& Group::maximum(const std::string& name, const std::string& unit, const std::string& description) {
  claim(name);
  kinds_[name] = 'm';
  return counters_.emplace_back(name, unit, description);
}

VectorCounter& Group::vector(const std::string& name, const std::string& unit, const std::string& description,
                             std::vector<std::string> labels) {
  claim(name);
  kinds_[name] = 'v';
  return vectors_.emplace_back(name, unit, description, std::move(labels));
}

void Group::formula(const std::string& name, const std::string& unit, const std::string& description, std::function<double()> f) {
  claim(name);
  kinds_[name] = 'f';
  formulas_.push_back({name, unit, description, std::move(f)});
}

void Group::reset() {
  for (auto& c : counters_) c.reset();
  for (auto& v : vectors_) v.reset();
}

namespace {

template <class Seq>
const auto& by_name(const Seq& seq, const std::string& name) {
  for (const auto& x : seq)
    if (x.name == name) return x;
  NBSIM_CHECK(false, "statistic " + name + " not found");
  return seq.front();
}

}  // namespace

nlohmann::ordered_json Group::values() const {
  nlohmann::ordered_json j = nlohmann::ordered_json::object();
  std::size_t ci = 0, vi = 0;
  for (const auto& name : order_) {
    switch (kinds_.at(name)) {
      case 'c':
      case 'm': j[name] = counters_[ci++].value(); break;
      case 'v': {
        const VectorCounter& v = vectors_[vi++];
        nlohmann::ordered_json b = nlohmann::ordered_json::object();
        for (std::size_t k = 0; k < v.size(); ++k) b[v.labels()[k]] = v.value(k);
        j[name] = b;
        break;
      }
      default: j[name] = by_name(formulas_, name).value(); break;
    }
  }
  return j;
}

nlohmann::ordered_json Group::describe() const {
  nlohmann::ordered_json j = nlohmann::ordered_json::array();
  std::size_t ci = 0, vi = 0;
  for (const auto& name : order_) {
    std::string unit, desc, kind;
    switch (kinds_.at(name)) {
      case 'c':
      case 'm':
        unit = counters_[ci].unit(), desc = counters_[ci].description();
        kind = kinds_.at(name) == 'c' ? "counter" : "maximum";
        ++ci;
        break;
      case 'v': unit = vectors_[vi].unit(), desc = vectors_[vi].description(), kind = "vector", ++vi; break;
      default: {
        const Formula& f = by_name(formulas_, name);
        unit = f.unit, desc = f.description, kind = "formula";
      }
    }
    j.push_back({{"name", name_ + "." + name}, {"kind", kind}, {"unit", unit}, {"description", desc}});
  }
  return j;
}

void Group::flatten(std::vector<std::pair<std::string, double>>& out) const {
  std::size_t ci = 0, vi = 0;
  for (const auto& name : order_) {
    const std::string full = name_ + "." + name;
    switch (kinds_.at(name)) {
      case 'c':
      case 'm': out.emplace_back(full, static_cast<double>(counters_[ci++].value())); break;
      case 'v': {
        const VectorCounter& v = vectors_[vi++];
        for (std::size_t k = 0; k < v.size(); ++k) out.emplace_back(full + "." + v.labels()[k], static_cast<double>(v.value(k)));
        break;
      }
      default: out.emplace_back(full, by_name(formulas_, name).value()); break;
    }
  }
}

Group& Registry::group(const std::string& full_name) {
  for (auto& g : groups_)
    if (g.name() == full_name) return g;
  return groups_.emplace_back(full_name);
}

const Group* Registry::find(const std::string& full_name) const {
  for (const auto& g : groups_)
    if (g.name() == full_name) return &g;
  return nullptr;
}

void Registry::reset() {
  for (auto& g : groups_) g.reset();
}

nlohmann::ordered_json Registry::values() const {
  nlohmann::ordered_json j = nlohmann::ordered_json::object();
  for (const auto& g : groups_) j[g.name()] = g.values();
  return j;
}

nlohmann::ordered_json Registry::describe() const {
  nlohmann::ordered_json j = nlohmann::ordered_json::array();
  for (const auto& g : groups_)
    for (auto& d : g.describe()) j.push_back(d);
  return j;
}

std::vector<std::pair<std::string, double>> Registry::flatten() const {
  std::vector<std::pair<std::string, double>> out;
  for (const auto& g : groups_) g.flatten(out);
  return out;
}

}  // namespace nbsim::stats
