// The one description of every trace record: `fields(io, record)` visits the record's fields in
// file order with their names, types, limits and meanings. The same visit encodes, decodes,
// validates, dumps and writes FORMAT.md's record tables (codec.cpp, describe.cpp), the way
// apitrace generates its (de)coders from one spec. A field added in version N sits inside
// `io.since(N, ...)`; a field dropped in version N inside `io.until(N - 1, ...)`.
//
// The Io concept (every visitor implements all of these; `name` and `meaning` are string literals):
//   version()                                the layout being visited (the file's, or the newest)
//   since(v, fn) / until(v, fn)              fn() when version() >= v / <= v
//   u8 / u32 / u64 / i32 / f32 / f64 / boolean(name, T& value, meaning)
//   ranged(name, T& value, lo, hi, symbol, meaning)     an integer within [lo, hi]; symbol ("W") or ""
//   enumeration(name, E& value, meaning)     one byte, values of EnumInfo<E>
//   floats(name, std::array<float, N>& value, meaning)
//   string(name, std::string& value, max_bytes, meaning)
//   words(name, std::vector<T>& value, symbol, meaning)         u32 count, 4-byte elements
//   image(name, std::vector<T>& value, count, count_text, meaning)  no count: `count` elements
//   items(name, std::vector<E>& value, symbol, Element, fn, meaning)
//                                            u32 count, then fn(io, element) for each element
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>

#include "model/common/depth.h"
#include "model/scene/technique_roles.h"
#include "traces/format/records.h"

namespace nbsim::trace {

// Fixed by the format (FORMAT.md "Limits"), so that a damaged or hostile file never causes a
// huge allocation. 256 MiB holds the N-buffer levels of a 2048x2048 frame (11 planes of 16 MiB).
inline constexpr std::uint64_t kMaxChunkBytes = std::uint64_t{256} << 20;  // stored and raw
inline constexpr std::size_t kMaxKeyBytes = 64;
inline constexpr std::size_t kMaxValueBytes = 64 * 1024;
inline constexpr std::size_t kMaxProperties = 1024;
inline constexpr std::int32_t kMaxImageSide = 16384;
inline constexpr std::int32_t kMaxLevels = 32;

// Per frame (FORMAT.md "Limits"), so that a frame reader's memory stays bounded: a frame's chunks
// (FRAM excluded, FEND included) decode to at most kFrameBaseBytes plus kFrameBytesPerPixel bytes
// a pixel of the header's viewport (Header::frame_byte_limit; a 1024x1024 viewport when the
// header has none), and hold at most kMaxDrawsPerFrame draws. Derived from the largest real
// frames: a 2048x2048 frame with a bounds-test pass holds two depth images (8 bytes a pixel), 11 N-buffer
// planes (44), an ID buffer (4) and a few MiB of draws, about 60 bytes a pixel; the city's frames
// have about 15,000 draws of 1 KiB or less. Twice that leaves room for a stencil image or a
// second level set.
inline constexpr std::uint64_t kFrameBaseBytes = std::uint64_t{64} << 20;
inline constexpr std::uint64_t kFrameBytesPerPixel = 128;
inline constexpr std::uint64_t kFramePixelsWithoutViewport = 1024 * 1024;
inline constexpr std::uint32_t kMaxDrawsPerFrame = std::uint32_t{1} << 20;

// The element type of a counted vector visited by items(): its name in the tables, its size in
// bytes (the least size when it varies) and whether every element has that size.
struct Element {
  const char* type;
  std::size_t bytes;
  bool fixed = true;
};

// The enums stored as one byte: their type name (in the tables) and largest value; value names
// come from the model's one name table per enum (to_string).
template <class E> struct EnumInfo;
template <> struct EnumInfo<TestMode> { static constexpr const char* name = "TestMode"; static constexpr unsigned max = 4; };
template <> struct EnumInfo<DrawRole> { static constexpr const char* name = "DrawRole"; static constexpr unsigned max = scene::kMaxDrawRole; };
template <> struct EnumInfo<DepthFunc> { static constexpr const char* name = "DepthFunc"; static constexpr unsigned max = 7; };
template <> struct EnumInfo<CullFace> { static constexpr const char* name = "CullFace"; static constexpr unsigned max = 3; };
template <> struct EnumInfo<ClipControl> { static constexpr const char* name = "ClipControl"; static constexpr unsigned max = 1; };
template <> struct EnumInfo<DepthWhich> { static constexpr const char* name = "DepthWhich"; static constexpr unsigned max = 1; };
template <> struct EnumInfo<FarOp> { static constexpr const char* name = "FarOp"; static constexpr unsigned max = 1; };
template <> struct EnumInfo<Topology> { static constexpr const char* name = "Topology"; static constexpr unsigned max = 1; };
template <> struct EnumInfo<StencilOp> { static constexpr const char* name = "StencilOp"; static constexpr unsigned max = 7; };

// Names of depth and stencil images and of N-buffer sources: 1 to 64 characters, like property keys.
inline constexpr std::size_t kMaxNameBytes = 64;

template <class E>
std::string_view enum_value_name(E e) {
  using nbsim::to_string;
  using scene::to_string;
  return to_string(e);
}

// ---- the records --------------------------------------------------------------------------------

template <class Io>
void fields(Io& io, Properties& p) {
  io.items("properties", p, "P", Element{"(string key, string value)", 8, false},
           [](Io& e, std::pair<std::string, std::string>& kv) {
             e.string("key", kv.first, kMaxKeyBytes, "1 to 64 characters of A-Z a-z 0-9 _ . -, unique");
             e.string("value", kv.second, kMaxValueBytes, "at most 64 KiB of UTF-8");
           },
           "key/value pairs in order, at most 1024");
}

template <class Io>
void aabb_fields(Io& io, Aabb& b) {
  io.floats("lo", b.lo, "");
  io.floats("hi", b.hi, "");
}

template <class Io>
void fields(Io& io, SceneObjects& s) {
  io.items("objects", s.objects, "N", Element{"aabb", 24}, aabb_fields<Io>, "index = object id");
  io.words("triangles", s.triangles, "N", "triangle count per object; same count as `objects`");
  io.items("node_bounds", s.node_bounds, "M", Element{"aabb", 24}, aabb_fields<Io>, "BVH nodes");
  io.words("node_left", s.node_left, "M", "child node or -1; same count as `node_bounds`");
  io.words("node_right", s.node_right, "M", "child node or -1; a node has two children or none (a leaf)");
  io.words("node_first", s.node_first, "M", "first entry in `leaf_objects`");
  io.words("node_count", s.node_count, "M", "entries in `leaf_objects`; `node_first + node_count` at most their count");
  io.words("leaf_objects", s.leaf_objects, "K", "object ids, each below the object count");
}

template <class Io>
void fields(Io& io, FrameBegin& f) {
  io.u32("frame", f.frame, "frame number (strictly increasing through the file)");
  io.enumeration("mode", f.mode, "");
  io.floats("view", f.view, "view matrix, column-major as GL takes it");
  io.floats("proj", f.proj, "projection matrix, column-major");
  io.floats("eye", f.eye, "camera position, world space");
}

template <class Io>
void position_fields(Io& io, std::array<float, 4>& p) {
  io.floats("xyzw", p, "");
}

template <class Io>
void stencil_face_fields(Io& io, StencilFace& f, const char* func, const char* ref, const char* value_mask,
                         const char* write_mask, const char* fail, const char* depth_fail, const char* pass) {
  io.enumeration(func, f.func, "the stencil test's comparison");
  io.i32(ref, f.ref, "reference value");
  io.u32(value_mask, f.value_mask, "ANDed with the reference and the stored value");
  io.u32(write_mask, f.write_mask, "stencil bits written");
  io.enumeration(fail, f.fail, "when the stencil test fails");
  io.enumeration(depth_fail, f.depth_fail, "when the stencil test passes and the depth test fails");
  io.enumeration(pass, f.pass, "when both pass");
}

template <class Io>
void fields(Io& io, DrawRecord& d) {
  io.u32("index", d.index, "draw index within the frame: 0, 1, 2, ...");
  io.enumeration("role", d.role, "");
  io.ranged("object", d.object, std::int32_t{-1}, std::int32_t{0x7FFFFFFF}, "", "object id or -1");
  io.ranged("node", d.node, std::int32_t{-1}, std::int32_t{0x7FFFFFFF}, "", "BVH node id or -1");
  io.ranged("level", d.level, std::uint8_t{0}, static_cast<std::uint8_t>(kMaxLevels - 1), "",
            "N-buffer level written (nbuffer_build)");
  io.enumeration("state.func", d.state.func, "");
  io.boolean("state.write", d.state.write, "depth write mask");
  io.boolean("state.test", d.state.test, "depth test enabled");
  io.enumeration("state.cull", d.state.cull, "");
  io.boolean("state.front_ccw", d.state.front_ccw, "front faces are counter-clockwise");
  io.enumeration("state.clip", d.state.clip, "");
  io.boolean("state.depth_clamp", d.state.depth_clamp, "GL_DEPTH_CLAMP");
  io.items("clip_positions", d.clip_positions, "V", Element{"f32[4]", 16}, position_fields<Io>,
           "clip-space x, y, z, w per vertex, three a triangle (transform feedback)");
  io.boolean("has_bounds", d.has_bounds, "the bounds fields below are meaningful (else all zero)");
  io.i32("bounds.x", d.bounds.x, "screen rectangle, pixels, y up, clipped to the viewport");
  io.i32("bounds.y", d.bounds.y, "");
  io.ranged("bounds.w", d.bounds.w, std::int32_t{0}, std::int32_t{0x7FFFFFFF}, "", "0 when the bounds are off-screen");
  io.ranged("bounds.h", d.bounds.h, std::int32_t{0}, std::int32_t{0x7FFFFFFF}, "", "");
  io.f32("bounds.nearest_depth", d.bounds.nearest_depth, "nearest window depth of the bounds");
  io.boolean("bounds.crosses_near", d.bounds.crosses_near, "bounds cross the near plane (never culled)");
  io.boolean("bounds.visible", d.bounds.visible, "the renderer's decision for this test");
  io.u64("gl.fragments", d.gl.fragments, "rasterized fragments (fragment-shader atomic counter, no early fragment tests)");
  io.u64("gl.samples_passed", d.gl.samples_passed, "GL_SAMPLES_PASSED");
  io.u64("gl.clip_prims_in", d.gl.clip_prims_in, "GL_CLIPPING_INPUT_PRIMITIVES");
  io.u64("gl.clip_prims_out", d.gl.clip_prims_out, "GL_CLIPPING_OUTPUT_PRIMITIVES");
  io.since(2, [&] {
    io.enumeration("topology", d.topology, "three vertices a triangle, or one a point sprite");
    io.words("point_sizes", d.point_sizes, "S",
             "gl_PointSize per vertex, pixels: S = V for points, 0 for triangles");
    io.boolean("stencil.test", d.stencil.test, "GL_STENCIL_TEST");
    stencil_face_fields(io, d.stencil.front, "stencil.front.func", "stencil.front.ref", "stencil.front.value_mask",
                        "stencil.front.write_mask", "stencil.front.fail", "stencil.front.depth_fail", "stencil.front.pass");
    stencil_face_fields(io, d.stencil.back, "stencil.back.func", "stencil.back.ref", "stencil.back.value_mask",
                        "stencil.back.write_mask", "stencil.back.fail", "stencil.back.depth_fail", "stencil.back.pass");
    io.boolean("discards", d.discards, "the fragment shader may discard");
    io.boolean("writes_depth", d.writes_depth, "the fragment shader writes gl_FragDepth");
  });
}

template <class Io>
void fields(Io& io, DrawBatch& b) {
  io.items("draws", b.draws, "D", Element{"DRAW record", 80, false}, [](Io& e, DrawRecord& d) { fields(e, d); },
           "consecutive draws of the frame, each laid out as a DRAW payload");
}

inline std::uint64_t texel_count(std::int32_t w, std::int32_t h, std::int32_t planes = 1) {
  if (w < 0 || h < 0 || planes < 0) return 0;
  return static_cast<std::uint64_t>(w) * static_cast<std::uint64_t>(h) * static_cast<std::uint64_t>(planes);
}

template <class Io>
void fields(Io& io, DepthSnapshot& d) {
  io.until(1, [&] {  // version 1 knew two images by number; they are names since
    DepthWhich which = d.name == "after_occluders" ? DepthWhich::AfterOccluders : DepthWhich::Final;
    io.enumeration("which", which, "");
    d.name = std::string(enum_value_name(which));
  });
  io.since(2, [&] { io.string("name", d.name, kMaxNameBytes, "the image's name, unique in the frame: after_occluders, final, ..."); });
  io.ranged("width", d.width, std::int32_t{1}, kMaxImageSide, "W", "");
  io.ranged("height", d.height, std::int32_t{1}, kMaxImageSide, "H", "");
  io.image("texels", d.texels, texel_count(d.width, d.height), "W·H", "window depth, y up, row-major (index y·W + x)");
}

template <class Io>
void fields(Io& io, NBufferLevels& l) {
  io.since(2, [&] {
    io.string("source", l.source, kMaxNameBytes, "name of the depth image the levels were built from (version 1: after_occluders)");
  });
  FarOp op = static_cast<FarOp>(l.op);
  io.enumeration("op", op, "max under LESS/LEQUAL, min under reversed Z");
  l.op = static_cast<std::uint8_t>(op);
  io.ranged("width", l.width, std::int32_t{1}, kMaxImageSide, "W", "");
  io.ranged("height", l.height, std::int32_t{1}, kMaxImageSide, "H", "");
  io.ranged("levels", l.levels, std::int32_t{1}, kMaxLevels, "L", "");
  io.image("texels", l.texels, texel_count(l.width, l.height, l.levels), "L·W·H",
           "L planes of W·H, level 0 first; each y up, row-major");
}

template <class Io>
void fields(Io& io, StencilSnapshot& s) {
  io.string("name", s.name, kMaxNameBytes, "the image's name, unique in the frame");
  io.ranged("width", s.width, std::int32_t{1}, kMaxImageSide, "W", "");
  io.ranged("height", s.height, std::int32_t{1}, kMaxImageSide, "H", "");
  io.image("texels", s.texels, texel_count(s.width, s.height), "W·H", "stencil value, y up, row-major");
}

template <class Io>
void fields(Io& io, Camera& c) {
  io.floats("view", c.view, "the light's view matrix, column-major");
  io.floats("proj", c.proj, "the light's projection matrix, column-major");
  io.floats("eye", c.eye, "the light's position, world space");
}

template <class Io>
void fields(Io& io, GroundTruth& t) {
  io.words("visible_pixels", t.visible_pixels, "N",
           "pixels of the finished frame's ID buffer showing each object (index = object id)");
  io.u64("covered_pixels", t.covered_pixels, "pixels covered by any object");
  io.ranged("id_width", t.id_width, std::int32_t{0}, kMaxImageSide, "W", "0 when the ID buffer image is not recorded");
  io.ranged("id_height", t.id_height, std::int32_t{0}, kMaxImageSide, "H", "0 together with W");
  io.image("ids", t.ids, texel_count(t.id_width, t.id_height), "W·H", "object id per pixel, -1 where no object; y up, row-major");
}

template <class Io>
void fields(Io& io, FrameEnd& f) {
  io.u32("frame", f.frame, "equals the frame's FRAM.frame");
  io.u32("draws", f.draws, "number of draws in the frame");
  io.f64("gl_ms", f.gl_ms, "host time GL took for the frame's technique passes (timer query), ms");
}

template <class Io>
void fields(Io& io, EndMarker& e) {
  io.u64("chunks", e.chunks, "number of chunks before END, HEAD included");
  io.u32("frames", e.frames, "number of frames");
}

}  // namespace nbsim::trace
