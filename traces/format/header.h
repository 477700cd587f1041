// The typed trace header: the HEAD chunk's key/value properties parsed and checked once, when a
// trace is opened (TraceReader), so that replay, `nbsim trace` and tests read numbers and enums
// instead of parsing strings. Keys the table in header.cpp does not know stay as they are in
// `properties`. That table also writes FORMAT.md's list of keys (header_keys_table).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "model/nbuffer/covering.h"
#include "traces/format/records.h"

namespace nbsim::trace {

struct Viewport {
  std::int32_t width = 0, height = 0;  // 1 .. 16384 each
};

struct Header {
  Properties properties;  // every property, in file order, as written

  // The typed ones. An absent key keeps the default (which is what a capture without it meant).
  std::optional<Viewport> viewport;             // "viewport": "512x512"
  std::string depth_format;                     // "depth_format": a GL depth format name, "" when absent
  DepthFunc depth_func = DepthFunc::Less;       // "depth_func": GL name, "LESS", "GREATER", ...
  ClipControl clip_control = ClipControl::NegativeOneToOne;  // "clip_control": "NEGATIVE_ONE_TO_ONE" or "ZERO_TO_ONE"
  float depth_clear = 1.0f;                     // "depth_clear": 0 .. 1
  std::string technique;                        // "technique": a capture technique's name
  std::string scene;                            // "scene": "city"
  std::string path;                             // "path": the camera path, "walk"
  std::optional<std::uint64_t> seed;            // "seed"
  std::optional<std::uint64_t> objects;         // "objects"
  std::optional<std::uint64_t> frames;          // "frames": frames the capture was asked for
  std::optional<std::uint64_t> levels_every;    // "levels_every"
  double fov_y_deg = 0.0;                       // "fov_y_deg": (0, 180), 0 when absent
  double near_m = 0.0;                          // "near": > 0, 0 when absent
  double far_m = 0.0;                           // "far": > near, 0 when absent
  double nearest_margin = 0.0;                  // "nearest_margin": >= 0
  std::optional<CoveringSpec> covering;         // "nbuffer_covering": "paper/top" (absent: corners/bottom)

  // "Farthest" under this header's depth func: FarOp::Min under GREATER/GEQUAL (reversed Z).
  FarOp far_op() const noexcept;
  // The most bytes a frame's chunks may decode to (schema.h kFrameBaseBytes, FORMAT.md "Limits"),
  // and the rule in words for messages ("64 MiB + 128 bytes a pixel of the 512x512 viewport").
  std::uint64_t frame_byte_limit() const noexcept;
  std::string frame_byte_limit_rule() const;
  // The value of any property as written, or nullptr.
  const std::string* property(std::string_view key) const noexcept;
  // A property a reader needs, typed: its value as written (text), a whole number or a finite
  // number. parse_header has checked a key the trace's technique declares against its range, so
  // these only refuse an absent key ("the <technique> trace's header has no '<key>' property")
  // or, for a key no technique declares, a value that is not of the type (InputError).
  const std::string& text(std::string_view key) const;
  std::uint64_t whole(std::string_view key) const;
  double real(std::string_view key) const;

 private:
  const std::string& required(std::string_view key) const;
};

// Parses and checks the typed keys, and the keys the header's technique declares
// (technique_chunks.h, HeaderKeySpec). Throws InputError naming the property, its value and what it
// must be ("header property 'viewport' is '128x96x': expected WIDTHxHEIGHT, each 1 .. 16384");
// TraceReader adds the file and chunk.
Header parse_header(const Properties& properties);

// The Markdown table of the keys the header knows (FORMAT.md "HEAD"): key, values, example, meaning.
std::string header_keys_table();

// The GL names of the header's depth funcs and clip controls ("LESS", "ZERO_TO_ONE").
std::string gl_name(DepthFunc func);
std::string gl_name(ClipControl clip);

}  // namespace nbsim::trace
