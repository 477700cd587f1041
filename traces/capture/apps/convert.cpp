// From the interposer's recording to an nbsim trace; see convert.h.
#include "traces/capture/apps/convert.h"

#include <fmt/format.h>

#include <optional>
#include <regex>
#include <system_error>
#include <vector>

#include "model/apps/roles.h"
#include "model/common/error.h"
#include "traces/capture/apps/recording.h"
#include "traces/format/apps/apps_chunk.h"
#include "traces/format/writer.h"

namespace nbsim::apitrace {

namespace {

constexpr std::uint32_t kGlNever = 0x0200;  // GL's comparison functions run GL_NEVER .. GL_ALWAYS

scene::DepthFunc depth_func(std::uint32_t gl) {
  return gl >= kGlNever && gl <= kGlNever + 7 ? static_cast<scene::DepthFunc>(gl - kGlNever) : scene::DepthFunc::Always;
}

scene::StencilOp stencil_op(std::uint32_t gl) {
  switch (gl) {
    case 0x0000: return scene::StencilOp::Zero;
    case 0x1E01: return scene::StencilOp::Replace;
    case 0x1E02: return scene::StencilOp::Incr;
    case 0x8507: return scene::StencilOp::IncrWrap;
    case 0x1E03: return scene::StencilOp::Decr;
    case 0x8508: return scene::StencilOp::DecrWrap;
    case 0x150A: return scene::StencilOp::Invert;
    default: return scene::StencilOp::Keep;
  }
}

scene::StencilFace stencil_face(const StencilFaceRaw& s) {
  scene::StencilFace f;
  f.func = depth_func(s.func);
  f.ref = s.ref;
  f.value_mask = s.value_mask;
  f.write_mask = s.write_mask;
  f.fail = stencil_op(s.fail);
  f.depth_fail = stencil_op(s.depth_fail);
  f.pass = stencil_op(s.pass);
  return f;
}

scene::DrawRecord draw_record(const RawDraw& raw) {
  const DrawHead& h = raw.head;
  scene::DrawRecord d;
  d.index = h.index;
  d.role = apps::kAppDrawRole;
  d.state.func = depth_func(h.depth_func);
  d.state.test = (h.flags & kDepthTest) != 0;
  d.state.write = (h.flags & kDepthMask) != 0;
  d.state.cull = !(h.flags & kCullFace)   ? scene::CullFace::None
                 : h.cull_mode == 0x0404 ? scene::CullFace::Front
                 : h.cull_mode == 0x0408 ? scene::CullFace::FrontAndBack
                                         : scene::CullFace::Back;
  d.state.front_ccw = (h.flags & kFrontCcw) != 0;
  d.state.clip = (h.flags & kClipZeroToOne) ? scene::ClipControl::ZeroToOne : scene::ClipControl::NegativeOneToOne;
  d.state.depth_clamp = (h.flags & kDepthClamp) != 0;
  d.stencil.test = (h.flags & kStencilTest) != 0;
  d.stencil.front = stencil_face(h.stencil[0]);
  d.stencil.back = stencil_face(h.stencil[1]);
  d.gl.samples_passed = h.samples_passed;
  d.discards = (h.flags & (kDiscards | kAlphaTest)) != 0;
  d.writes_depth = (h.flags & kWritesDepth) != 0;
  d.topology = scene::Topology::Triangles;
  if (h.skipped == 0 && h.primitive == 0x0004) d.clip_positions = raw.positions;  // triangles only; points and lines are flagged
  return d;
}

template <class T>
std::vector<T>& vec(scene::TechniqueRecord& r, std::size_t at) {
  return std::get<std::vector<T>>(r.fields[at].value);
}

// A record of `spec`'s fields with empty values of their kinds.
scene::TechniqueRecord empty_record(const trace::ChunkSpec& spec) {
  scene::TechniqueRecord r;
  r.type = spec.type;
  r.decoded = true;
  for (const trace::FieldSpec& f : spec.fields) {
    scene::TechniqueField field;
    field.name = f.name;
    switch (f.kind) {
      case trace::FieldKind::U32:
      case trace::FieldKind::U64: field.value = std::uint64_t{0}; break;
      case trace::FieldKind::I32: field.value = std::int64_t{0}; break;
      case trace::FieldKind::F32:
      case trace::FieldKind::F64: field.value = 0.0; break;
      case trace::FieldKind::String: field.value = std::string(); break;
      case trace::FieldKind::VecF32: field.value = std::vector<float>(); break;
      case trace::FieldKind::VecU32: field.value = std::vector<std::uint32_t>(); break;
      case trace::FieldKind::VecI32: field.value = std::vector<std::int32_t>(); break;
    }
    r.fields.push_back(std::move(field));
  }
  return r;
}

scene::TechniqueRecord draws_record(const RawFrame& f) {
  static const trace::ChunkSpec spec = trace::app_draws_chunk_spec();
  scene::TechniqueRecord r = empty_record(spec);
  r.fields[0].value = std::uint64_t{f.draws.size()};
  for (const RawDraw& raw : f.draws) {
    const DrawHead& h = raw.head;
    std::size_t at = 1;
    for (const std::uint32_t v : {h.mode, h.call, h.skipped, h.skipped == 0 ? h.primitive : 0u, h.flags, h.framebuffer,
                                  static_cast<std::uint32_t>(h.target_width), static_cast<std::uint32_t>(h.target_height), h.depth_bits,
                                  h.depth_float, h.polygon_mode})
      vec<std::uint32_t>(r, at++).push_back(v);
    for (const std::int32_t v : {h.viewport[0], h.viewport[1], h.viewport[2], h.viewport[3], h.scissor[0], h.scissor[1], h.scissor[2], h.scissor[3]})
      vec<std::int32_t>(r, at++).push_back(v);
    for (const float v : {static_cast<float>(h.depth_range[0]), static_cast<float>(h.depth_range[1]), h.offset_factor, h.offset_units})
      vec<float>(r, at++).push_back(v);
  }
  return r;
}

scene::TechniqueRecord clears_record(const RawFrame& f) {
  static const trace::ChunkSpec spec = trace::app_clears_chunk_spec();
  scene::TechniqueRecord r = empty_record(spec);
  r.fields[0].value = std::uint64_t{f.clears.size()};
  for (const ClearHead& c : f.clears) {
    std::size_t at = 1;
    for (const std::uint32_t v : {c.index, c.framebuffer, c.buffers, c.flags, c.stencil_write_mask}) vec<std::uint32_t>(r, at++).push_back(v);
    for (const std::int32_t v : {c.scissor[0], c.scissor[1], c.scissor[2], c.scissor[3], c.stencil}) vec<std::int32_t>(r, at++).push_back(v);
    vec<float>(r, at++).push_back(static_cast<float>(std::clamp(c.depth, 0.0, 1.0)));
  }
  return r;
}

scene::TechniqueRecord depth_change_record(const RawDraw& d) {
  static const trace::ChunkSpec spec = trace::app_depth_change_chunk_spec();
  scene::TechniqueRecord r = empty_record(spec);
  r.fields[0].value = std::uint64_t{d.head.index};
  r.fields[1].value = std::uint64_t{d.delta.framebuffer};
  r.fields[2].value = std::uint64_t{static_cast<std::uint32_t>(d.delta.width)};
  r.fields[3].value = std::uint64_t{static_cast<std::uint32_t>(d.delta.height)};
  r.fields[4].value = d.delta_pixels;
  r.fields[5].value = d.delta_depths;
  return r;
}

scene::TechniqueRecord frame_record(const RawFrame& f) {
  static const trace::ChunkSpec spec = trace::app_frame_chunk_spec();
  scene::TechniqueRecord r = empty_record(spec);
  r.fields[0].value = std::uint64_t{f.end.framebuffer};
  r.fields[1].value = std::uint64_t{static_cast<std::uint32_t>(f.end.width)};
  r.fields[2].value = std::uint64_t{static_cast<std::uint32_t>(f.end.height)};
  std::string unhandled;
  for (const RawUnhandled& u : f.unhandled) unhandled += fmt::format("{}{} x {}", unhandled.empty() ? "" : "; ", u.name, u.count);
  r.fields[3].value = unhandled;
  return r;
}

// "GL_RENDERER=...", "GL_VERSION=...", "GL_VENDOR=..." notes, by key.
std::string note(const std::vector<std::string>& notes, std::string_view key) {
  for (const std::string& n : notes)
    if (n.size() > key.size() && n.compare(0, key.size(), key) == 0 && n[key.size()] == '=') return n.substr(key.size() + 1);
  return "unknown";
}

}  // namespace

std::string depth_format_name(std::uint32_t bits, bool is_float) {
  if (bits == 32 && is_float) return "DEPTH_COMPONENT32F";
  if (bits == 24) return "DEPTH_COMPONENT24";
  if (bits == 16) return "DEPTH_COMPONENT16";
  if (bits == 32) return "DEPTH_COMPONENT32";
  return "none";
}

scene::Frame to_frame(RawFrame&& f) {
  scene::Frame out;
  out.begin.frame = f.frame;
  out.begin.mode = scene::TestMode::None;
  for (const RawDraw& raw : f.draws) out.draws.push_back(draw_record(raw));
  out.technique_records.push_back(draws_record(f));
  out.technique_records.push_back(clears_record(f));
  out.technique_records.push_back(frame_record(f));
  for (const RawDraw& raw : f.draws)
    if (raw.has_delta) out.technique_records.push_back(depth_change_record(raw));
  if (f.end.has_depth) {
    scene::DepthSnapshot depth;
    depth.name = "final";
    depth.width = f.end.width;
    depth.height = f.end.height;
    depth.texels = std::move(f.depth);
    out.depths.push_back(std::move(depth));
  }
  out.end.frame = f.frame;
  out.end.draws = static_cast<std::uint32_t>(f.draws.size());
  return out;
}

ConvertSummary convert_recording(const std::filesystem::path& recording, const std::filesystem::path& out, const ConvertOptions& options,
                                 const std::function<void(std::uint32_t frames)>& progress) {
  RawReader reader(recording);
  std::optional<RawFrame> first = reader.next();
  if (!first) throw InputError(fmt::format("the recording '{}' holds no frame: the trace has fewer frames than the range asked for", recording.string()));
  ConvertSummary sum;
  sum.renderer = note(reader.notes(), "GL_RENDERER");
  const std::string version = note(reader.notes(), "GL_VERSION");
  if (version.rfind("OpenGL ES", 0) == 0)
    throw InputError(fmt::format("the trace runs an OpenGL ES context ({}): ES has no samples-passed query, so GL's counters cannot be "
                                 "recorded; record the program with a desktop GL context",
                                 version));
  std::smatch m;
  const std::string mesa = std::regex_search(version, m, std::regex("Mesa ([0-9][^ ]*)")) ? m[1].str() : "unknown";
  // The depth format of the frame's main target, from a draw into it.
  std::uint32_t bits = 0;
  bool is_float = false;
  for (const RawDraw& d : first->draws)
    if (d.head.framebuffer == first->end.framebuffer) bits = d.head.depth_bits, is_float = d.head.depth_float != 0;
  const FileHead& fh = reader.head();
  trace::Properties props = {
      {"gl_renderer", sum.renderer},
      {"gl_version", version},
      {"gl_vendor", note(reader.notes(), "GL_VENDOR")},
      {"mesa_version", mesa},
      {"viewport", fmt::format("{}x{}", std::max(first->end.width, 1), std::max(first->end.height, 1))},
      {"depth_func", "LESS"},
      {"clip_control", "NEGATIVE_ONE_TO_ONE"},
      {"depth_clear", "1"},
      {"technique", "apps"},
      {"scene", "none"},
      {"path", "none"},
      {"apitrace", options.apitrace},
      {"app_frames", fh.last_frame == 0xFFFFFFFFu ? fmt::format("{}:end", fh.first_frame) : fmt::format("{}:{}", fh.first_frame, fh.last_frame)},
      {"nbsim_version", NBSIM_VERSION},
      {"command_line", options.command_line},
  };
  // The header's depth_format sets the generic depth unit's buffer: only a format it stores (the
  // apps program keeps each target in its own format, from the AppDraws record).
  if (const std::string f = depth_format_name(bits, is_float); f == "DEPTH_COMPONENT24" || f == "DEPTH_COMPONENT32F")
    props.insert(props.begin() + 5, {"depth_format", f});
  const std::filesystem::path partial(out.string() + ".partial");
  try {
    trace::TraceWriter writer(partial, props);
    std::optional<RawFrame> f = std::move(first);
    while (f) {
      for (const RawDraw& raw : f->draws) {
        ++sum.draws;
        sum.skipped[std::min<std::size_t>(raw.head.skipped, 6)] += 1;
        sum.captured += raw.head.skipped == 0 ? 1 : 0;
        sum.vertices += raw.positions.size();
        sum.depth_changes += raw.has_delta ? 1 : 0;
      }
      sum.clears += f->clears.size();
      for (const RawUnhandled& u : f->unhandled) sum.unhandled[u.name] += u.count;
      const scene::Frame frame = to_frame(std::move(*f));
      writer.begin_frame(frame.begin);
      for (const scene::DrawRecord& d : frame.draws) writer.write(d);
      for (const scene::TechniqueRecord& r : frame.technique_records) writer.write(r);
      for (const scene::DepthSnapshot& d : frame.depths) writer.write(d);
      writer.end_frame(frame.end);
      ++sum.frames;
      if (progress) progress(sum.frames);
      f = reader.next();
    }
    writer.close();
    sum.bytes = writer.bytes_written();
  } catch (...) {
    std::error_code ec;
    std::filesystem::remove(partial, ec);
    throw;
  }
  std::error_code ec;
  std::filesystem::rename(partial, out, ec);
  if (ec) throw InputError(fmt::format("cannot write the trace '{}': {}", out.string(), ec.message()));
  return sum;
}

}  // namespace nbsim::apitrace
