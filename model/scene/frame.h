// The frame a technique works on: the scene's objects and BVH, one frame's camera, its draws with
// GL's post-transform geometry and counters, depth images, N-buffer levels and ground truth. The
// GL renderer (traces/capture) fills these in, the trace format (traces/format) stores them, and
// the model (model/, pipeline/sim) replays them: they are the model's input types, so they live
// here and the model never includes traces/. Every enum that reaches a file has a fixed
// underlying type and fixed values, and one name table (frame.cpp).
// Conventions: model/common/depth.h (window depth in [0, 1], y up, pixel centres at +0.5).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "model/common/depth.h"

namespace nbsim::scene {

// Axis-aligned bounds of one scene object or BVH node, world space.
struct Aabb {
  std::array<float, 3> lo{};
  std::array<float, 3> hi{};
};

// The scene's objects and BVH (so a replay can re-test bounds without the renderer).
struct SceneObjects {
  std::vector<Aabb> objects;           // index = object id
  std::vector<std::uint32_t> triangles;  // triangle count per object
  // BVH nodes: bounds, children (-1 when a leaf) and, for leaves, a range into leaf_objects.
  std::vector<Aabb> node_bounds;
  std::vector<std::int32_t> node_left, node_right;
  std::vector<std::uint32_t> node_first, node_count;
  std::vector<std::uint32_t> leaf_objects;
};

// Fixed values (they are in files). GL's depth funcs in GL's order.
enum class DepthFunc : std::uint8_t { Never = 0, Less = 1, Equal = 2, Lequal = 3, Greater = 4, NotEqual = 5, Gequal = 6, Always = 7 };
enum class CullFace : std::uint8_t { None = 0, Back = 1, Front = 2, FrontAndBack = 3 };
enum class ClipControl : std::uint8_t { NegativeOneToOne = 0, ZeroToOne = 1 };

// What a draw is for, in the frame's technique. The core roles below are fixed; a technique
// declares its own (values from kFirstTechniqueRole on) in its folder (model/<name>/roles.h), and
// model/scene/technique_roles.h lists them all: the DRAW record's role is any of both.
enum class DrawRole : std::uint8_t {
  Occluder = 0,       // objects visible last frame, drawn first to fill the depth buffer
  BoundsQuery = 1,    // an object's bounding box rasterized inside an occlusion query
  NodeQuery = 2,      // a BVH node's bounding box inside an occlusion query (hierarchical mode)
  NBufferBuild = 3,   // a full-screen pass of the GLSL N-buffer construction (one per level)
  NBufferQuery = 4,   // bounds tested against the N-buffer (4 lookups each) in a shader
  Visible = 5,        // an object the technique found visible, drawn for the final image
  IdBuffer = 6,       // the ground-truth ID-buffer pass (every object in the frustum, nothing culled)
  Scene = 7,          // a scene object drawn to fill the depth buffer, nothing culled
};
inline constexpr std::uint8_t kFirstTechniqueRole = 8;

// A technique's draw role and its name (in traces, dumps and messages).
struct RoleName {
  DrawRole role;
  std::string_view name;
};

// The culling technique a frame ran: the Table 2 modes (docs/architecture.md, "Definitions").
enum class TestMode : std::uint8_t { OcclusionQuery = 0, OcclusionQueryHier = 1, NBuffer = 2, NBufferHier = 3, None = 4 };

// What a draw rasterizes: triangles (three clip-space vertices each) or point sprites (one vertex
// each, every fragment at the vertex's depth, a square of the vertex's point size in pixels).
enum class Topology : std::uint8_t { Triangles = 0, Points = 1 };

// GL's stencil operations in GL's order (glStencilOp).
enum class StencilOp : std::uint8_t { Keep = 0, Zero = 1, Replace = 2, Incr = 3, IncrWrap = 4, Decr = 5, DecrWrap = 6, Invert = 7 };

// One face's stencil state; GL's stencil funcs are the depth funcs. Defaults are GL's.
struct StencilFace {
  DepthFunc func = DepthFunc::Always;
  std::int32_t ref = 0;
  std::uint32_t value_mask = 0xFFFFFFFFu;  // ANDed with ref and the stored value before the test
  std::uint32_t write_mask = 0xFFFFFFFFu;
  StencilOp fail = StencilOp::Keep;        // stencil test fails
  StencilOp depth_fail = StencilOp::Keep;  // stencil test passes, depth test fails
  StencilOp pass = StencilOp::Keep;        // both pass
};

struct StencilState {
  bool test = false;  // GL_STENCIL_TEST
  StencilFace front, back;
};

struct DepthState {
  DepthFunc func = DepthFunc::Less;
  bool write = true;
  bool test = true;
  CullFace cull = CullFace::Back;
  bool front_ccw = true;
  ClipControl clip = ClipControl::NegativeOneToOne;
  bool depth_clamp = false;
  bool operator==(const DepthState&) const = default;
};

// GL's own counters for one draw (what each counts on llvmpipe: docs/architecture.md, "Platform
// facts").
struct GlCounters {
  std::uint64_t fragments = 0;         // rasterized fragments: atomic counter, no early fragment tests
  std::uint64_t samples_passed = 0;    // GL_SAMPLES_PASSED
  std::uint64_t clip_prims_in = 0;     // GL_CLIPPING_INPUT_PRIMITIVES
  std::uint64_t clip_prims_out = 0;    // GL_CLIPPING_OUTPUT_PRIMITIVES
};

// A bounds test as the renderer computed it: the screen rectangle (pixels, y up, clipped to the
// viewport) and the nearest window depth of the bounds. rect w == 0 when the bounds are off-screen.
struct BoundsTest {
  std::int32_t x = 0, y = 0, w = 0, h = 0;
  float nearest_depth = 0.0f;
  bool crosses_near = false;  // bounds cross the near plane: never culled
  bool visible = true;        // the renderer's decision for this test
};

struct DrawRecord {
  std::uint32_t index = 0;   // draw index within the frame
  DrawRole role = DrawRole::Visible;
  std::int32_t object = -1;  // object id, or -1
  std::int32_t node = -1;    // BVH node id, or -1
  std::uint8_t level = 0;    // N-buffer level written (NBufferBuild)
  DepthState state;
  // Post-transform geometry as GL computed it (transform feedback): clip-space x, y, z, w per
  // vertex, three vertices a triangle (one a point). Empty for full-screen passes.
  std::vector<std::array<float, 4>> clip_positions;
  bool has_bounds = false;
  BoundsTest bounds;
  GlCounters gl;
  Topology topology = Topology::Triangles;
  std::vector<float> point_sizes;  // Points: gl_PointSize per vertex, pixels; Triangles: empty
  StencilState stencil;
  bool discards = false;      // the fragment shader may discard fragments
  bool writes_depth = false;  // the fragment shader writes gl_FragDepth (no early depth test)
};

// A camera: view and projection (column-major, as GL takes them) and its position, world space.
// A frame's second camera is a light's (shadow volumes with litmaps).
struct Camera {
  std::array<float, 16> view{};
  std::array<float, 16> proj{};
  std::array<float, 3> eye{};
};

struct FrameBegin {
  std::uint32_t frame = 0;
  TestMode mode = TestMode::None;
  std::array<float, 16> view{};  // column-major, as GL takes them
  std::array<float, 16> proj{};
  std::array<float, 3> eye{};
};

// The two depth images of occlusion culling; their names ("after_occluders", "final") are depth
// image names like any technique's.
enum class DepthWhich : std::uint8_t { AfterOccluders = 0, Final = 1 };

// A named depth image of the frame (occlusion culling: "after_occluders" and "final"; other
// techniques add theirs, e.g. litmaps "litmap_min" and "litmap_max").
struct DepthSnapshot {
  std::string name = "final";
  std::int32_t width = 0, height = 0;
  std::vector<float> texels;  // y up, row-major
};

// A named stencil image of the frame (shadow volumes' mask, for instance).
struct StencilSnapshot {
  std::string name;
  std::int32_t width = 0, height = 0;
  std::vector<std::uint8_t> texels;  // y up, row-major
};

// N-buffer levels GL built from one of the frame's depth images.
struct NBufferLevels {
  std::string source = "after_occluders";  // the depth image's name (occlusion culling builds from the occluder pass)
  std::uint8_t op = 0;  // FarOp
  std::int32_t width = 0, height = 0, levels = 0;
  std::vector<float> texels;  // levels planes of width * height, y up, row-major
};

// A technique's own record (a chunk type the technique registered in traces/format): its type
// (fourcc) and payload as stored and, when the reader knew the type's field description, the
// decoded fields in order.
struct TechniqueField {
  std::string name;
  std::variant<std::uint64_t, std::int64_t, double, std::string, std::vector<float>, std::vector<std::uint32_t>,
               std::vector<std::int32_t>>
      value;
};
struct TechniqueRecord {
  std::uint32_t type = 0;
  // The chunk's bytes, kept only for a type this build does not know (not decoded): a decoded
  // record's bytes are its fields' encoding (traces/format technique_chunks.h encode()).
  std::vector<std::uint8_t> payload;
  bool decoded = false;  // `fields` holds the payload's fields (the type was registered)
  std::vector<TechniqueField> fields;
};

struct GroundTruth {
  // Visible pixels of every object in the finished frame's ID buffer (index = object id).
  std::vector<std::uint32_t> visible_pixels;
  std::uint64_t covered_pixels = 0;  // pixels covered by any object
  // Optional: the ID buffer itself (object id per pixel, -1 where no object; y up, row-major),
  // for `nbsim trace dump --truth OUT.png`. Empty with id_width == id_height == 0 when not recorded.
  std::int32_t id_width = 0, id_height = 0;
  std::vector<std::int32_t> ids;
};

struct FrameEnd {
  std::uint32_t frame = 0;
  std::uint32_t draws = 0;
  double gl_ms = 0.0;  // host time GL took for the frame's technique passes (timer query)
};

// One frame, FRAM .. FEND in a trace, decoded.
struct Frame {
  std::uint64_t ordinal = 0;  // 0 for the trace's first frame
  std::uint64_t offset = 0;   // byte offset of its FRAM chunk (0 when it did not come from a file)
  FrameBegin begin;
  std::vector<DrawRecord> draws;  // draws[i].index == i
  std::vector<DepthSnapshot> depths;  // names unique, in file order
  std::vector<NBufferLevels> levels;  // at most one per (source, op), in file order
  std::vector<StencilSnapshot> stencils;  // names unique, in file order
  std::optional<Camera> light;            // a second camera, when the technique has a light
  std::vector<TechniqueRecord> technique_records;  // in file order
  std::optional<GroundTruth> truth;
  FrameEnd end;

  const DepthSnapshot* depth(DepthWhich which) const noexcept;
  const DepthSnapshot* depth(std::string_view name) const noexcept;
  const StencilSnapshot* stencil(std::string_view name) const noexcept;
  // The first level set with this op (occlusion culling has at most one per op).
  const NBufferLevels* nbuffer(FarOp op) const noexcept;
  const NBufferLevels* nbuffer(std::string_view source, FarOp op) const noexcept;
};

// Names (run outputs, `nbsim trace info`, timelines), one table per enum in frame.cpp; "?" for a
// value outside the table.
std::string_view to_string(DrawRole role) noexcept;
std::string_view to_string(TestMode mode) noexcept;
std::string_view to_string(DepthWhich which) noexcept;
std::string_view to_string(DepthFunc func) noexcept;
std::string_view to_string(CullFace cull) noexcept;
std::string_view to_string(ClipControl clip) noexcept;
std::string_view to_string(Topology topology) noexcept;
std::string_view to_string(StencilOp op) noexcept;
// The capture's --mode names of TestMode, indexed by its value (also the model's cull.mode names).
inline constexpr std::array<std::string_view, 5> kTestModeNames = {"oq", "oq_hier", "nb", "nb_hier", "none"};
std::optional<TestMode> parse_test_mode(std::string_view s) noexcept;

}  // namespace nbsim::scene
