// The typed header: one table of the keys it knows, each with its parser; see header.h.
#include "traces/format/header.h"

#include <fmt/format.h>

#include <array>
#include <charconv>
#include <cmath>
#include <functional>

#include "model/common/error.h"
#include "model/common/names.h"
#include "traces/format/schema.h"

namespace nbsim::trace {

namespace {

// GL's names, indexed by the enums' fixed values.
constexpr std::array<std::string_view, 8> kGlDepthFuncs = {"NEVER",   "LESS",     "EQUAL",  "LEQUAL",
                                                           "GREATER", "NOTEQUAL", "GEQUAL", "ALWAYS"};
constexpr std::array<std::string_view, 2> kGlClipControls = {"NEGATIVE_ONE_TO_ONE", "ZERO_TO_ONE"};
constexpr std::array<std::string_view, 6> kGlDepthFormats = {"DEPTH_COMPONENT16", "DEPTH_COMPONENT24", "DEPTH_COMPONENT32",
                                                             "DEPTH_COMPONENT32F", "DEPTH24_STENCIL8", "DEPTH32F_STENCIL8"};

[[noreturn]] void refuse(std::string_view key, std::string_view value, std::string_view expected) {
  throw InputError(fmt::format("header property '{}' is '{}': expected {}", key, value, expected));
}

// The whole string is one number of type T (no sign for unsigned, no spaces, no trailing text).
template <class T>
std::optional<T> number(std::string_view s) {
  T v{};
  if (s.empty() || s.front() == '+' || s.front() == ' ') return std::nullopt;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
  if constexpr (std::is_floating_point_v<T>)
    if (!std::isfinite(v)) return std::nullopt;
  return v;
}

std::uint64_t count(std::string_view key, std::string_view v) {
  if (v.starts_with('-')) refuse(key, v, "a whole number, at least 0");
  if (const auto n = number<std::uint64_t>(v)) return *n;
  refuse(key, v, "a whole number, at least 0");
}

double real(std::string_view key, std::string_view v, double lo, double hi, bool open_lo, std::string_view expected) {
  const auto x = number<double>(v);
  if (!x || *x < lo || *x > hi || (open_lo && *x == lo)) refuse(key, v, expected);
  return *x;
}

Viewport viewport(std::string_view key, std::string_view v) {
  const std::string expected = fmt::format("WIDTHxHEIGHT, each 1 .. {}", kMaxImageSide);
  const std::size_t x = v.find('x');
  if (x == std::string_view::npos) refuse(key, v, expected);
  const auto w = number<std::int32_t>(v.substr(0, x)), h = number<std::int32_t>(v.substr(x + 1));
  if (!w || !h || *w < 1 || *h < 1 || *w > kMaxImageSide || *h > kMaxImageSide) refuse(key, v, expected);
  return {*w, *h};
}

template <class E, std::size_t N>
E named(std::string_view key, std::string_view v, const std::array<std::string_view, N>& names) {
  if (const auto e = parse_enum_name<E>(names, v)) return *e;
  refuse(key, v, fmt::format("one of {}", fmt::join(names, ", ")));
}

// One row per typed key: its name and how it sets the header.
struct Key {
  std::string_view name;
  std::function<void(Header&, std::string_view)> parse;
};

const std::array<Key, 17>& keys() {
  static const std::array<Key, 17> table = {{
      {"viewport", [](Header& h, std::string_view v) { h.viewport = viewport("viewport", v); }},
      {"depth_format",
       [](Header& h, std::string_view v) {
         named<std::uint8_t>("depth_format", v, kGlDepthFormats);
         h.depth_format = std::string(v);
       }},
      {"depth_func", [](Header& h, std::string_view v) { h.depth_func = named<DepthFunc>("depth_func", v, kGlDepthFuncs); }},
      {"clip_control",
       [](Header& h, std::string_view v) { h.clip_control = named<ClipControl>("clip_control", v, kGlClipControls); }},
      {"depth_clear",
       [](Header& h, std::string_view v) {
         h.depth_clear = static_cast<float>(real("depth_clear", v, 0.0, 1.0, false, "a depth in 0 .. 1"));
       }},
      {"technique", [](Header& h, std::string_view v) { h.technique = std::string(v); }},
      {"test_mode",
       [](Header& h, std::string_view v) {
         h.test_mode = scene::parse_test_mode(v);
         if (!h.test_mode) refuse("test_mode", v, "one of oq, oq_hier, nb, nb_hier, none");
       }},
      {"scene", [](Header& h, std::string_view v) { h.scene = std::string(v); }},
      {"path", [](Header& h, std::string_view v) { h.path = std::string(v); }},
      {"seed", [](Header& h, std::string_view v) { h.seed = count("seed", v); }},
      {"objects", [](Header& h, std::string_view v) { h.objects = count("objects", v); }},
      {"frames", [](Header& h, std::string_view v) { h.frames = count("frames", v); }},
      {"levels_every", [](Header& h, std::string_view v) { h.levels_every = count("levels_every", v); }},
      {"fov_y_deg",
       [](Header& h, std::string_view v) {
         h.fov_y_deg = real("fov_y_deg", v, 0.0, 180.0, true, "an angle in degrees, above 0 and below 180");
         if (h.fov_y_deg == 180.0) refuse("fov_y_deg", v, "an angle in degrees, above 0 and below 180");
       }},
      {"near", [](Header& h, std::string_view v) { h.near_m = real("near", v, 0.0, 1e300, true, "a distance above 0"); }},
      {"far", [](Header& h, std::string_view v) { h.far_m = real("far", v, 0.0, 1e300, true, "a distance above 0"); }},
      {"nearest_margin",
       [](Header& h, std::string_view v) {
         h.nearest_margin = real("nearest_margin", v, 0.0, 1.0, false, "a depth margin in 0 .. 1");
       }},
  }};
  return table;
}

}  // namespace

FarOp Header::far_op() const noexcept {
  return depth_func == DepthFunc::Greater || depth_func == DepthFunc::Gequal ? FarOp::Min : FarOp::Max;
}

const std::string* Header::property(std::string_view key) const noexcept {
  for (const auto& [k, v] : properties)
    if (k == key) return &v;
  return nullptr;
}

Header parse_header(const Properties& properties) {
  Header h;
  h.properties = properties;
  for (const auto& [k, v] : properties)
    for (const Key& key : keys())
      if (key.name == k) key.parse(h, v);
  if (h.far_m != 0.0 && h.near_m != 0.0 && h.far_m <= h.near_m)
    refuse("far", *h.property("far"), fmt::format("a distance above near ({})", *h.property("near")));
  return h;
}

std::string_view gl_name(DepthFunc func) noexcept { return enum_name(kGlDepthFuncs, func); }
std::string_view gl_name(ClipControl clip) noexcept { return enum_name(kGlClipControls, clip); }

}  // namespace nbsim::trace
