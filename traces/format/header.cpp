// The typed header: one table of the keys it knows, each with its parser; see header.h.
#include "traces/format/header.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cctype>
#include <cmath>
#include <string>
#include <vector>

#include "model/common/error.h"
#include "model/common/names.h"
#include "traces/format/schema.h"
#include "traces/format/technique_chunks.h"

namespace nbsim::trace {

namespace {

constexpr std::array<std::string_view, 6> kGlDepthFormats = {"DEPTH_COMPONENT16", "DEPTH_COMPONENT24", "DEPTH_COMPONENT32",
                                                             "DEPTH_COMPONENT32F", "DEPTH24_STENCIL8", "DEPTH32F_STENCIL8"};

[[noreturn]] void refuse(std::string_view key, std::string_view value, std::string_view expected) {
  throw InputError(fmt::format("header property '{}' is '{}': expected {}", key, value, expected));
}

// GL's spelling of a model enum's name: its one name table (model/scene/frame.cpp) in upper case.
template <class E>
std::string gl_spelling(E e) {
  std::string s(scene::to_string(e));
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

// The value whose GL spelling is exactly `v` ("LESS"; "less" is refused).
template <class E>
E gl_named(std::string_view key, std::string_view v, std::string_view expected) {
  for (int i = 0; scene::to_string(static_cast<E>(i)) != "?"; ++i)
    if (gl_spelling(static_cast<E>(i)) == v) return static_cast<E>(i);
  refuse(key, v, expected);
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

std::uint64_t count(std::string_view key, std::string_view v, std::string_view expected) {
  if (v.starts_with('-')) refuse(key, v, expected);
  if (const auto n = number<std::uint64_t>(v)) return *n;
  refuse(key, v, expected);
}

double real(std::string_view key, std::string_view v, std::string_view expected, double lo, double hi, bool open_lo) {
  const auto x = number<double>(v);
  if (!x || *x < lo || *x > hi || (open_lo && *x == lo)) refuse(key, v, expected);
  return *x;
}

Viewport viewport(std::string_view key, std::string_view v, std::string_view expected) {
  const std::size_t x = v.find('x');
  if (x == std::string_view::npos) refuse(key, v, expected);
  const auto w = number<std::int32_t>(v.substr(0, x)), h = number<std::int32_t>(v.substr(x + 1));
  if (!w || !h || *w < 1 || *h < 1 || *w > kMaxImageSide || *h > kMaxImageSide) refuse(key, v, expected);
  return {*w, *h};
}

template <class E, std::size_t N>
E named(std::string_view key, std::string_view v, std::string_view expected, const std::array<std::string_view, N>& names) {
  if (const auto e = parse_enum_name<E>(names, v)) return *e;
  refuse(key, v, expected);
}

// One row per known key: its name, the values it takes (also what a refusal says is expected),
// an example, what it means and how it sets the typed header (nothing for free text).
struct Key {
  std::string_view name;
  std::string_view values;
  std::string_view example;
  std::string_view meaning;
  void (*parse)(Header&, std::string_view key, std::string_view value, std::string_view values);
};

const std::vector<Key>& keys() {
  static const std::vector<Key> table = {
      {"gl_renderer", "text", "llvmpipe (LLVM 15.0.6, 256 bits)", "GL_RENDERER", nullptr},
      {"gl_version", "text", "4.5 (Core Profile) Mesa 22.3.6", "GL_VERSION", nullptr},
      {"gl_vendor", "text", "Mesa", "GL_VENDOR", nullptr},
      {"mesa_version", "text", "22.3.6", "Mesa's version, from GL_VERSION", nullptr},
      {"viewport", "WIDTHxHEIGHT, each 1 .. 16384", "512x512", "the frame's size in pixels; replay needs it",
       [](Header& h, std::string_view k, std::string_view v, std::string_view e) { h.viewport = viewport(k, v, e); }},
      {"depth_format", "one of DEPTH_COMPONENT16, DEPTH_COMPONENT24, DEPTH_COMPONENT32, DEPTH_COMPONENT32F, DEPTH24_STENCIL8, DEPTH32F_STENCIL8",
       "DEPTH_COMPONENT32F", "the depth buffer's GL format",
       [](Header& h, std::string_view k, std::string_view v, std::string_view e) {
         if (!parse_enum_name<std::uint8_t>(kGlDepthFormats, v)) refuse(k, v, e);
         h.depth_format = std::string(v);
       }},
      {"depth_func", "one of NEVER, LESS, EQUAL, LEQUAL, GREATER, NOTEQUAL, GEQUAL, ALWAYS", "LESS",
       "the frame's depth func: LESS, or GREATER with reversed Z (default LESS)",
       [](Header& h, std::string_view k, std::string_view v, std::string_view e) { h.depth_func = gl_named<DepthFunc>(k, v, e); }},
      {"clip_control", "one of NEGATIVE_ONE_TO_ONE, ZERO_TO_ONE", "NEGATIVE_ONE_TO_ONE",
       "glClipControl's depth mode (default NEGATIVE_ONE_TO_ONE)",
       [](Header& h, std::string_view k, std::string_view v, std::string_view e) {
         h.clip_control = gl_named<ClipControl>(k, v, e);
       }},
      {"depth_clear", "a depth in 0 .. 1", "1", "the depth buffer's clear value (default 1)",
       [](Header& h, std::string_view k, std::string_view v, std::string_view e) {
         h.depth_clear = static_cast<float>(real(k, v, e, 0.0, 1.0, false));
       }},
      {"technique", "text", "{technique}", "the technique the capture ran",
       [](Header& h, std::string_view, std::string_view v, std::string_view) { h.technique = std::string(v); }},
      {"scene", "text", "city", "the scene",
       [](Header& h, std::string_view, std::string_view v, std::string_view) { h.scene = std::string(v); }},
      {"seed", "a whole number, at least 0", "1", "the scene's and path's random seed",
       [](Header& h, std::string_view k, std::string_view v, std::string_view e) { h.seed = count(k, v, e); }},
      {"objects", "a whole number, at least 0", "5000", "the scene's object count",
       [](Header& h, std::string_view k, std::string_view v, std::string_view e) { h.objects = count(k, v, e); }},
      {"path", "text", "walk", "the camera path",
       [](Header& h, std::string_view, std::string_view v, std::string_view) { h.path = std::string(v); }},
      {"frames", "a whole number, at least 0", "60", "the frames the capture was asked for",
       [](Header& h, std::string_view k, std::string_view v, std::string_view e) { h.frames = count(k, v, e); }},
      {"fov_y_deg", "an angle in degrees, above 0 and below 180", "60", "the camera's vertical field of view",
       [](Header& h, std::string_view k, std::string_view v, std::string_view e) {
         h.fov_y_deg = real(k, v, e, 0.0, 180.0, true);
         if (h.fov_y_deg == 180.0) refuse(k, v, e);
       }},
      {"near", "a distance above 0", "0.5", "the near plane, m",
       [](Header& h, std::string_view k, std::string_view v, std::string_view e) { h.near_m = real(k, v, e, 0.0, 1e300, true); }},
      {"far", "a distance above near", "4000", "the far plane, m",
       [](Header& h, std::string_view k, std::string_view v, std::string_view e) { h.far_m = real(k, v, e, 0.0, 1e300, true); }},
      {"nearest_margin", "a depth margin in 0 .. 1", "1e-06", "margin subtracted from a bounds test's nearest depth",
       [](Header& h, std::string_view k, std::string_view v, std::string_view e) {
         h.nearest_margin = real(k, v, e, 0.0, 1.0, false);
       }},
      {"levels_every", "a whole number, at least 0", "1", "the N-buffer levels are recorded every k-th frame (0: never)",
       [](Header& h, std::string_view k, std::string_view v, std::string_view e) { h.levels_every = count(k, v, e); }},
      {"nbuffer_covering", "paper, corners or one, '/', top or bottom", "paper/top",
       "how the capture's N-buffer queries cover a rectangle (model/nbuffer/covering.h; absent: corners/bottom, nbsim's covering "
       "before the paper's)",
       [](Header& h, std::string_view k, std::string_view v, std::string_view e) {
         h.covering = parse_covering_name(v);
         if (!h.covering) refuse(k, v, e);
       }},
      {"nbsim_version", "text", "0.1.0", "the capturing nbsim's version", nullptr},
      {"command_line", "text", "nbsim capture {technique} --scene city --frames 60 -o walk.nbtrace", "the capture's command line", nullptr},
  };
  return table;
}

// Checks one technique key's value against its declaration (InputError naming it otherwise).
void check_technique_key(const HeaderKeySpec& key, std::string_view v) {
  bool ok = true;
  switch (key.kind) {
    case HeaderKeySpec::Kind::Text: break;
    case HeaderKeySpec::Kind::Whole: {
      const auto n = v.starts_with('-') ? std::nullopt : number<std::uint64_t>(v);
      ok = n && *n >= key.min && *n <= key.max;
      break;
    }
    case HeaderKeySpec::Kind::Real: {
      const auto x = number<double>(v);
      ok = x && *x >= key.lo && *x <= key.hi && !(key.above_lo && *x == key.lo);
      break;
    }
    case HeaderKeySpec::Kind::OneOf:
      ok = std::find(key.choices.begin(), key.choices.end(), v) != key.choices.end();
      break;
    case HeaderKeySpec::Kind::Custom: ok = key.custom(v); break;
  }
  if (!ok) refuse(key.name, v, key.values);
}

const HeaderKeySpec* find_technique_key(std::string_view technique, std::string_view name) {
  for (const HeaderKeySpec& k : technique_header_keys())
    if (k.technique == technique && k.name == name) return &k;
  return nullptr;
}

}  // namespace

FarOp Header::far_op() const noexcept {
  return depth_func == DepthFunc::Greater || depth_func == DepthFunc::Gequal ? FarOp::Min : FarOp::Max;
}

std::uint64_t Header::frame_byte_limit() const noexcept {
  const std::uint64_t pixels = viewport ? static_cast<std::uint64_t>(viewport->width) * static_cast<std::uint64_t>(viewport->height)
                                        : kFramePixelsWithoutViewport;
  return kFrameBaseBytes + kFrameBytesPerPixel * pixels;
}

std::string Header::frame_byte_limit_rule() const {
  const std::string of = viewport ? fmt::format("the {}x{} viewport", viewport->width, viewport->height)
                                  : std::string("a 1024x1024 viewport (the header has none)");
  return fmt::format("{} MiB + {} bytes a pixel of {}", kFrameBaseBytes >> 20, kFrameBytesPerPixel, of);
}

const std::string* Header::property(std::string_view key) const noexcept {
  for (const auto& [k, v] : properties)
    if (k == key) return &v;
  return nullptr;
}

const std::string& Header::required(std::string_view key) const {
  if (const std::string* v = property(key)) return *v;
  throw InputError(fmt::format("the {} trace's header has no '{}' property", technique.empty() ? "(no technique)" : technique, key));
}

std::uint64_t Header::whole(std::string_view key) const {
  const std::string& v = required(key);
  const auto n = v.starts_with('-') ? std::nullopt : number<std::uint64_t>(v);
  if (!n) refuse(key, v, "a whole number");
  return *n;
}

double Header::real(std::string_view key) const {
  const std::string& v = required(key);
  const auto x = number<double>(v);
  if (!x) refuse(key, v, "a finite number");
  return *x;
}

const std::string& Header::text(std::string_view key) const { return required(key); }

Header parse_header(const Properties& properties) {
  Header h;
  h.properties = properties;
  for (const auto& [k, v] : properties)
    for (const Key& key : keys())
      if (key.name == k && key.parse) key.parse(h, k, v, key.values);
  for (const auto& [k, v] : properties)  // the keys the trace's technique declares
    if (const HeaderKeySpec* key = find_technique_key(h.technique, k)) check_technique_key(*key, v);
  if (h.far_m != 0.0 && h.near_m != 0.0 && h.far_m <= h.near_m)
    refuse("far", *h.property("far"), fmt::format("a distance above near ({})", *h.property("near")));
  return h;
}

std::string header_keys_table() {
  // "{technique}" in a core key's example: the first technique that declares keys.
  const std::string technique = technique_header_keys().empty() ? "NAME" : technique_header_keys().front().technique;
  const auto example = [&](std::string_view e) {
    std::string s(e);
    if (const auto at = s.find("{technique}"); at != std::string::npos) s.replace(at, 11, technique);
    return s;
  };
  std::string t = "| Key | Values | Example | Meaning |\n|-----|--------|---------|---------|\n";
  for (const Key& k : keys()) t += fmt::format("| `{}` | {} | `{}` | {} |\n", k.name, k.values, example(k.example), k.meaning);
  t += "\nThe keys each technique declares, checked only in a trace of that technique (a trace of another "
       "technique, or one without a technique, keeps them as free text):\n\n"
       "| Technique | Key | Values | Example | Meaning |\n|-----------|-----|--------|---------|---------|\n";
  for (const HeaderKeySpec& k : technique_header_keys())
    t += fmt::format("| {} | `{}` | {} | `{}` | {} |\n", k.technique, k.name, k.values, k.example, k.meaning);
  return t;
}

std::string gl_name(DepthFunc func) { return gl_spelling(func); }
std::string gl_name(ClipControl clip) { return gl_spelling(clip); }

}  // namespace nbsim::trace
