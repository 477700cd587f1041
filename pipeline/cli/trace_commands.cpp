// `nbsim trace info|verify|dump`: look inside a depth trace (traces/FORMAT.md) captured by the GL
// renderer: its header and per-frame summary, a full integrity check, and one frame's images.
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <optional>

#include "model/common/error.h"
#include "pipeline/cli/command.h"
#include "io/image_io.h"
#include "io/json_spill.h"
#include "traces/format/codec.h"
#include "traces/format/describe.h"
#include "traces/format/reader.h"
#include "traces/format/writer.h"
#include "io/output_folder.h"

namespace nbsim::cli {

namespace {

namespace fs = std::filesystem;
namespace tr = nbsim::trace;
using ojson = nlohmann::ordered_json;

// What `info` says about one frame.
struct FrameSummary {
  std::uint32_t frame = 0;
  tr::TestMode mode = tr::TestMode::None;
  std::uint64_t offset = 0;
  std::size_t draws = 0;
  std::uint64_t fragments = 0, samples_passed = 0;
  std::optional<std::uint64_t> objects_visible, covered_pixels;
  double gl_ms = 0.0;
  std::vector<std::string> depths;  // "after_occluders", "final"
  std::vector<std::string> stencils;  // names (version 2)
  bool light = false;
  std::vector<std::string> technique_records;  // chunk types
  std::vector<std::string> level_text;  // "max x9", ...
  std::vector<ojson> level_json;
};

FrameSummary summarize(const tr::Frame& f) {
  FrameSummary s;
  s.frame = f.begin.frame;
  s.mode = f.begin.mode;
  s.offset = f.offset;
  s.draws = f.draws.size();
  for (const tr::DrawRecord& d : f.draws) {
    s.fragments += d.gl.fragments;
    s.samples_passed += d.gl.samples_passed;
  }
  if (f.truth) {
    s.objects_visible = static_cast<std::uint64_t>(
        std::count_if(f.truth->visible_pixels.begin(), f.truth->visible_pixels.end(), [](std::uint32_t n) { return n > 0; }));
    s.covered_pixels = f.truth->covered_pixels;
  }
  s.gl_ms = f.end.gl_ms;
  for (const tr::DepthSnapshot& d : f.depths) s.depths.emplace_back(d.name);
  for (const tr::StencilSnapshot& st : f.stencils) s.stencils.emplace_back(st.name);
  s.light = f.light.has_value();
  for (const tr::TechniqueRecord& t : f.technique_records) s.technique_records.push_back(tr::chunk_type_name(t.type));
  for (const tr::NBufferLevels& l : f.levels) {
    const std::string_view op = to_string(static_cast<FarOp>(l.op));
    s.level_text.push_back(fmt::format("{} x{}", op, l.levels));
    s.level_json.push_back({{"op", op}, {"levels", l.levels}, {"size", fmt::format("{}x{}", l.width, l.height)}});
  }
  return s;
}

std::string mib(std::uint64_t bytes) { return fmt::format("{:.2f} MiB", static_cast<double>(bytes) / (1 << 20)); }

// The per-frame part of `info`'s text output, kept in a temporary file until the totals that
// precede it are known (the whole trace has been read), so that memory stays bounded.
class SpilledText {
 public:
  SpilledText() : file_(std::tmpfile()) {
    if (!file_) throw InputError(fmt::format("cannot create a temporary file for the frame summaries: {}", std::strerror(errno)));
  }
  ~SpilledText() { std::fclose(file_); }
  SpilledText(const SpilledText&) = delete;
  SpilledText& operator=(const SpilledText&) = delete;
  std::FILE* file() noexcept { return file_; }
  void copy_to(std::FILE* out) {
    if (std::fflush(file_) != 0 || std::fseek(file_, 0, SEEK_SET) != 0)
      throw InputError(fmt::format("cannot read back the frame summaries: {}", std::strerror(errno)));
    char buf[1 << 16];
    std::size_t n = 0;
    while ((n = std::fread(buf, 1, sizeof buf, file_)) > 0) std::fwrite(buf, 1, n, out);
    if (std::ferror(file_)) throw InputError("cannot read back the frame summaries");
  }

 private:
  std::FILE* file_ = nullptr;
};

ojson frame_json(const FrameSummary& s) {
  ojson o;
  o["frame"] = s.frame;
  o["mode"] = tr::to_string(s.mode);
  o["draws"] = s.draws;
  o["fragments"] = s.fragments;
  o["samples_passed"] = s.samples_passed;
  o["objects_visible"] = s.objects_visible ? ojson(*s.objects_visible) : ojson(nullptr);
  o["covered_pixels"] = s.covered_pixels ? ojson(*s.covered_pixels) : ojson(nullptr);
  o["gl_ms"] = s.gl_ms;
  o["depth"] = s.depths;
  o["levels"] = s.level_json;
  // Version 2's records only when the frame has them (summaries of frames without them stay as they were).
  if (!s.stencils.empty()) o["stencil"] = s.stencils;
  if (s.light) o["light"] = true;
  if (!s.technique_records.empty()) o["technique_records"] = s.technique_records;
  o["offset"] = s.offset;
  return o;
}

void print_frame_line(std::FILE* out, const FrameSummary& s) {
  const std::string visible = s.objects_visible ? fmt::format("{}", *s.objects_visible) : std::string("?");
  fmt::print(out, "  frame {} ({}): {} draws, {} GL fragments, {} samples passed, {} objects visible (ground truth)", s.frame,
             tr::to_string(s.mode), s.draws, s.fragments, s.samples_passed, visible);
  if (!s.depths.empty()) fmt::print(out, "; depth: {}", fmt::join(s.depths, ", "));
  if (!s.level_text.empty()) fmt::print(out, "; N-buffer: {}", fmt::join(s.level_text, ", "));
  if (!s.stencils.empty()) fmt::print(out, "; stencil: {}", fmt::join(s.stencils, ", "));
  if (s.light) fmt::print(out, "; light camera");
  if (!s.technique_records.empty()) fmt::print(out, "; technique records: {}", fmt::join(s.technique_records, ", "));
  fmt::print(out, "\n");
}

// Streams: each frame's summary goes to a temporary file as the frame is read (the header lines
// need the whole trace's chunk counts first), so memory is one frame however long the trace.
int run_info(const std::string& file, bool json) {
  tr::FrameReader frames{fs::path(file)};
  std::optional<io::SpilledJsonArray> frame_objects;
  std::optional<SpilledText> frame_lines;
  if (json) frame_objects.emplace();
  else frame_lines.emplace();
  std::uint64_t fragments = 0, samples = 0, draws = 0, count = 0;
  while (const auto f = frames.next()) {
    const FrameSummary s = summarize(*f);
    fragments += s.fragments;
    samples += s.samples_passed;
    draws += s.draws;
    ++count;
    if (json) frame_objects->push_back(frame_json(s));
    else print_frame_line(frame_lines->file(), s);
  }
  const tr::TraceReader& t = frames.trace();
  const tr::TraceStats& st = t.stats();

  if (json) {
    ojson j;
    j["file"] = file;
    j["format_version"] = t.version();
    j["bytes"] = t.file_bytes();
    j["chunks"] = st.chunks;
    j["compressed_chunks"] = st.compressed_chunks;
    j["payload_bytes"] = st.raw_bytes;
    j["stored_payload_bytes"] = st.stored_bytes;
    ojson props = ojson::object();
    for (const auto& [k, v] : t.properties()) props[k] = v;
    j["properties"] = props;
    if (const tr::SceneObjects* sc = t.scene())
      j["scene"] = {{"objects", sc->objects.size()}, {"bvh_nodes", sc->node_bounds.size()}};
    else
      j["scene"] = nullptr;
    j["frames"] = io::SpilledJsonArray::placeholder();
    j["totals"] = {{"frames", count}, {"draws", draws}, {"fragments", fragments}, {"samples_passed", samples}};
    std::fflush(stdout);
    frame_objects->write_document(stdout, j);
    return 0;
  }

  fmt::print("trace {}: format version {}, {} bytes, {} chunks ({} compressed; payload {} stored as {})\n", file,
             t.version(), t.file_bytes(), st.chunks, st.compressed_chunks, mib(st.raw_bytes), mib(st.stored_bytes));
  fmt::print("properties:\n");
  for (const auto& [k, v] : t.properties()) fmt::print("  {}: {}\n", k, v);
  if (const tr::SceneObjects* sc = t.scene())
    fmt::print("scene: {} objects, {} BVH nodes\n", sc->objects.size(), sc->node_bounds.size());
  else
    fmt::print("scene: none recorded\n");
  fmt::print("frames: {}\n", count);
  std::fflush(stdout);
  frame_lines->copy_to(stdout);
  fmt::print("total: {} draws, {} GL fragments, {} samples passed\n", draws, fragments, samples);
  return 0;
}

int run_verify(const std::string& file) {
  tr::FrameReader frames{fs::path(file)};
  while (frames.next()) {
  }
  const tr::TraceReader& t = frames.trace();
  const tr::TraceStats& st = t.stats();
  fmt::print("{}: sound: format version {}, {} bytes, {} chunks, {} frames, {} draws, payload {} stored as {}\n", file,
             t.version(), t.file_bytes(), st.chunks, st.frames, st.draws, mib(st.raw_bytes), mib(st.stored_bytes));
  return 0;
}

struct RepeatOptions {
  std::string file;
  std::uint64_t frames = 0;
  std::string out;
};

// Writes one frame, renumbered, record by record (the writer batches the draws and checks the
// format's rules again). Frame records come back in the FrameReader's grouping, which the format
// allows in any order inside FRAM .. FEND.
void write_frame(tr::TraceWriter& w, const tr::Frame& f, std::uint32_t number) {
  tr::FrameBegin begin = f.begin;
  begin.frame = number;
  w.begin_frame(begin);
  for (const tr::DrawRecord& d : f.draws) w.write(d);
  for (const tr::DepthSnapshot& d : f.depths) w.write(d);
  for (const tr::NBufferLevels& l : f.levels) w.write(l);
  for (const tr::StencilSnapshot& s : f.stencils) w.write(s);
  if (f.light) w.write_light(*f.light);
  for (const tr::TechniqueRecord& t : f.technique_records) w.write(t);
  if (f.truth) w.write(*f.truth);
  tr::FrameEnd end = f.end;
  end.frame = number;
  w.end_frame(end);
}

// `nbsim trace repeat`: a long trace from a short one, for memory and speed measurements. The input
// is read once a pass, one frame at a time (FrameReader), so memory stays at one frame whatever N.
// Pass p renumbers frame n of the input as p * (last + 1) + n: the first pass keeps the input's
// numbers, and every later one keeps its gaps and order.
int run_repeat(const RepeatOptions& o) {
  if (o.frames < 1) throw InputError(fmt::format("--frames {}: the new trace needs at least 1 frame", o.frames));
  {
    std::error_code ec;
    if (fs::exists(o.out, ec) && fs::equivalent(o.file, o.out, ec))
      throw InputError(fmt::format("--out '{}' is the input trace: write the long trace to another file", o.out));
  }
  // One pass over the input checks all of it (as `trace verify` does) before anything is written,
  // and gives its frame count and last frame number.
  std::uint64_t input_frames = 0;
  std::uint32_t last = 0;
  tr::Properties properties;
  {
    tr::FrameReader frames{fs::path(o.file)};
    while (const auto f = frames.next()) {
      ++input_frames;
      last = f->begin.frame;
    }
    properties = frames.trace().properties();
  }
  if (input_frames == 0) throw InputError(fmt::format("trace '{}' has no frames to repeat", o.file));
  const std::uint64_t period = std::uint64_t{last} + 1;
  const std::uint64_t passes = (o.frames + input_frames - 1) / input_frames;
  if ((passes - 1) * period + last > std::numeric_limits<std::uint32_t>::max())
    throw InputError(fmt::format("--frames {}: the repeated frame numbers of '{}' (frames up to {}, repeated every {}) would "
                                 "pass the format's largest frame number {}",
                                 o.frames, o.file, last, period, std::numeric_limits<std::uint32_t>::max()));
  // The header says what the file is: the frame count it now holds and where its frames came from.
  bool has_frames = false;
  for (auto& [k, v] : properties)
    if (k == "frames") v = std::to_string(o.frames), has_frames = true;
  if (!has_frames) properties.emplace_back("frames", std::to_string(o.frames));
  std::erase_if(properties, [](const auto& kv) { return kv.first == "repeated_from"; });
  properties.emplace_back("repeated_from", fmt::format("{} ({} frames)", fs::path(o.file).filename().string(), input_frames));

  // As a capture does: the frames go to OUT.partial, renamed to OUT once the trace is whole, so a
  // failure (a full disk) leaves no half-written trace and an existing OUT as it was.
  const fs::path partial = fs::path(o.out + ".partial");
  std::uint64_t written = 0, bytes = 0;
  try {
    tr::TraceWriter w(partial, properties);
    for (std::uint64_t pass = 0; written < o.frames; ++pass) {
      tr::FrameReader frames{fs::path(o.file)};
      if (pass == 0 && frames.trace().scene()) w.write(*frames.trace().scene());
      while (written < o.frames) {
        const auto f = frames.next();
        if (!f) break;
        write_frame(w, *f, static_cast<std::uint32_t>(pass * period + f->begin.frame));
        ++written;
      }
    }
    w.close();
    bytes = w.bytes_written();
    std::error_code ec;
    fs::rename(partial, o.out, ec);
    if (ec) throw InputError(fmt::format("cannot write trace '{}': {}", o.out, ec.message()));
  } catch (...) {
    std::error_code ec;
    fs::remove(partial, ec);
    throw;
  }
  fmt::print("wrote {}: {} frames ({} passes over the {} frames of {}), {} bytes\n", o.out, written, passes, input_frames,
             o.file, bytes);
  return 0;
}

std::string lower_extension(const fs::path& p) {
  std::string e = p.extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return e;
}

// A colour per object id (a fixed integer hash, bright enough to tell from the black background).
std::array<std::uint8_t, 3> id_colour(std::int32_t id) {
  if (id < 0) return {0, 0, 0};
  std::uint32_t h = static_cast<std::uint32_t>(id) * 0x9E3779B1u;
  h ^= h >> 15;
  h *= 0x85EBCA77u;
  h ^= h >> 13;
  return {static_cast<std::uint8_t>(64 + (h & 0xBF)), static_cast<std::uint8_t>(64 + ((h >> 8) & 0xBF)),
          static_cast<std::uint8_t>(64 + ((h >> 16) & 0xBF))};
}

struct DumpOptions {
  std::string file;
  std::uint32_t frame = 0;
  std::string depth;
  std::string which = "final";
  std::string levels;
  std::string truth;
  bool records = false;
};

int run_dump(const DumpOptions& o) {
  if (o.depth.empty() && o.levels.empty() && o.truth.empty() && !o.records)
    throw InputError("nothing to dump: pass --records, --depth OUT.exr, --levels DIR or --truth OUT.csv|OUT.png");
  const std::string truth_ext = lower_extension(o.truth);
  if (!o.truth.empty() && truth_ext != ".csv" && truth_ext != ".png")
    throw InputError(fmt::format("--truth '{}': expected a .csv (visible pixels per object) or .png (ID buffer) file", o.truth));

  tr::FrameReader frames{fs::path(o.file)};
  std::optional<tr::Frame> frame;
  std::uint64_t count = 0;
  std::uint32_t first = 0, last = 0;
  while ((frame = frames.next())) {
    if (count++ == 0) first = frame->begin.frame;
    last = frame->begin.frame;
    if (frame->begin.frame >= o.frame) break;  // frame numbers increase: it is here or nowhere
  }
  if (!frame || frame->begin.frame != o.frame) {
    if (count == 0) throw InputError(fmt::format("trace '{}' has no frames", o.file));
    if (frame)
      throw InputError(fmt::format("trace '{}' has no frame {} (the next frame is {})", o.file, o.frame, last));
    throw InputError(fmt::format("trace '{}' has no frame {} (its {} frames are numbered {} to {})", o.file, o.frame,
                                 count, first, last));
  }
  const tr::Frame& f = *frame;
  if (o.records) fmt::print("{}", tr::dump_frame(f));

  // Check that everything asked for is there before writing anything.
  const std::string which = o.which == "occluders" ? std::string(tr::to_string(tr::DepthWhich::AfterOccluders)) : o.which;
  const tr::DepthSnapshot* depth = o.depth.empty() ? nullptr : f.depth(which);
  if (!o.depth.empty() && !depth) {
    std::vector<std::string> have;
    for (const tr::DepthSnapshot& d : f.depths) have.emplace_back(d.name);
    throw InputError(fmt::format("frame {} of '{}' has no '{}' depth snapshot (it has: {})", o.frame, o.file,
                                 which, have.empty() ? std::string("none") : fmt::format("{}", fmt::join(have, ", "))));
  }
  if (!o.levels.empty() && f.levels.empty())
    throw InputError(fmt::format("frame {} of '{}' records no N-buffer levels (the capture may store them every k-th frame only)",
                                 o.frame, o.file));
  if (!o.truth.empty() && !f.truth)
    throw InputError(fmt::format("frame {} of '{}' records no ground truth", o.frame, o.file));
  if (truth_ext == ".png" && f.truth->ids.empty())
    throw InputError(fmt::format("frame {} of '{}' records no ID-buffer image, only visible pixels per object: "
                                 "use --truth OUT.csv", o.frame, o.file));

  if (depth) {
    DepthImage img;
    img.width = depth->width;
    img.height = depth->height;
    img.texels = depth->texels;
    io::write_depth(img, o.depth);
    fmt::print("wrote {} ({}x{}, '{}' depth of frame {})\n", o.depth, img.width, img.height, which, o.frame);
  }
  if (!o.levels.empty()) {
    const fs::path dir(o.levels);
    io::create_output_folder(dir, "output directory");
    for (const tr::NBufferLevels& l : f.levels) {
      const std::string prefix = f.levels.size() == 1 ? "level" : fmt::format("{}_level", to_string(static_cast<FarOp>(l.op)));
      const std::size_t plane = static_cast<std::size_t>(l.width) * static_cast<std::size_t>(l.height);
      for (std::int32_t i = 0; i < l.levels; ++i) {
        DepthImage img;
        img.width = l.width;
        img.height = l.height;
        const auto from = l.texels.begin() + static_cast<std::ptrdiff_t>(plane * static_cast<std::size_t>(i));
        img.texels.assign(from, from + static_cast<std::ptrdiff_t>(plane));
        io::write_depth(img, dir / fmt::format("{}_{:02d}.exr", prefix, i));
      }
      fmt::print("wrote {} {} levels of {}x{} ({}_NN.exr) to {}\n", l.levels, to_string(static_cast<FarOp>(l.op)), l.width,
                  l.height, prefix, dir.string());
    }
  }
  if (truth_ext == ".csv") {
    std::ofstream out(o.truth);
    if (!out) throw InputError(fmt::format("cannot write '{}'", o.truth));
    out << "object,visible_pixels\n";
    for (std::size_t i = 0; i < f.truth->visible_pixels.size(); ++i) out << i << ',' << f.truth->visible_pixels[i] << '\n';
    if (!out.flush()) throw InputError(fmt::format("cannot write '{}'", o.truth));
    const auto visible = std::count_if(f.truth->visible_pixels.begin(), f.truth->visible_pixels.end(),
                                       [](std::uint32_t n) { return n > 0; });
    fmt::print("wrote {} ({} objects, {} visible, {} covered pixels in frame {})\n", o.truth, f.truth->visible_pixels.size(),
               visible, f.truth->covered_pixels, o.frame);
  } else if (truth_ext == ".png") {
    const tr::GroundTruth& t = *f.truth;
    std::vector<std::uint8_t> rgb(t.ids.size() * 3);
    for (std::size_t i = 0; i < t.ids.size(); ++i) {
      const auto c = id_colour(t.ids[i]);
      std::copy(c.begin(), c.end(), rgb.begin() + static_cast<std::ptrdiff_t>(3 * i));
    }
    io::write_rgb8(t.id_width, t.id_height, rgb, o.truth);
    fmt::print("wrote {} ({}x{} ID buffer of frame {}, one colour per object, black where none)\n", o.truth, t.id_width,
               t.id_height, o.frame);
  }
  return 0;
}

int run_format(std::uint32_t version, const std::string& update) {
  if (version < 1 || version > tr::kFormatVersion)
    throw InputError(fmt::format("--format-version {}: this nbsim knows format versions 1 to {}", version, tr::kFormatVersion));
  if (update.empty()) {
    fmt::print("{}", tr::record_tables(version));
    return 0;
  }
  std::ifstream in(update, std::ios::binary);
  if (!in) throw InputError(fmt::format("cannot read '{}'", update));
  const std::string doc((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string fresh = tr::refresh_format_doc(doc);
  if (fresh == doc) {
    fmt::print("{}: its {} record tables are current\n", update, tr::format_doc_regions(doc).size());
    return 0;
  }
  std::ofstream out(update, std::ios::binary | std::ios::trunc);
  if (!(out << fresh) || !out.flush()) throw InputError(fmt::format("cannot write '{}'", update));
  fmt::print("{}: refreshed its {} record tables\n", update, tr::format_doc_regions(doc).size());
  return 0;
}

}  // namespace

void add_trace_commands(CLI::App& app, Action& action) {
  auto* tc = app.add_subcommand("trace", "Depth traces captured by the GL renderer: summary, integrity check, frame images");
  tc->require_subcommand(1);
  tc->footer("Trace files are specified in traces/FORMAT.md. A damaged or unreadable trace exits with status 2 and a\n"
             "message naming the chunk (index and type) and its byte offset.");

  {
    auto* cmd = tc->add_subcommand("info", "Header properties and a per-frame summary (draws, GL fragments, samples passed, visible objects)");
    auto file = std::make_shared<std::string>();
    auto json = std::make_shared<bool>(false);
    cmd->add_option("FILE", *file, "Trace file")->required();
    cmd->add_flag("--json", *json, "Print one JSON object instead of text");
    cmd->footer("'objects visible' counts the objects with at least one pixel in the frame's ID buffer (ground truth).\n"
                "The whole trace is read and checked, as by 'nbsim trace verify'.");
    cmd->callback([&action, file, json] { action = [=] { return run_info(*file, *json); }; });
  }
  {
    auto* cmd = tc->add_subcommand("verify", "Check every chunk (CRC-32, lengths, order, records); exit 0 when sound, 2 when not");
    auto file = std::make_shared<std::string>();
    cmd->add_option("FILE", *file, "Trace file")->required();
    cmd->footer("Prints one summary line when the trace is sound. Otherwise prints the first problem, naming the chunk\n"
                "(index and type) and its byte offset, and exits with status 2.");
    cmd->callback([&action, file] { action = [=] { return run_verify(*file); }; });
  }
  {
    auto* cmd = tc->add_subcommand("repeat", "Write a long trace that repeats a trace's frames until it has N frames");
    auto o = std::make_shared<RepeatOptions>();
    cmd->add_option("FILE", o->file, "Trace file to repeat")->required();
    cmd->add_option("--frames", o->frames, "Frames the new trace holds (at least 1)")->required();
    cmd->add_option("-o,--out", o->out, "The new trace file (replaced when it exists; written as OUT.partial until whole)")->required();
    cmd->footer("The input is checked whole first (as by 'nbsim trace verify'), then read again once per pass, one frame\n"
                "at a time, so memory stays at one frame however many frames are written. Pass p numbers input frame n as\n"
                "p * (last frame number + 1) + n. The header keeps the input's properties, with 'frames' set to N and\n"
                "'repeated_from' naming the input. For memory and speed measurements of long traces (docs/exploration.md).");
    cmd->callback([&action, o] { action = [=] { return run_repeat(*o); }; });
  }
  {
    auto* cmd = tc->add_subcommand("format", "Print the record tables of the trace format (Markdown), from the records' one description");
    auto version = std::make_shared<std::uint32_t>(tr::kFormatVersion);
    auto update = std::make_shared<std::string>();
    cmd->add_option("--format-version", *version, "Layout of this format version")->capture_default_str();
    cmd->add_option("--update", *update, "Refresh the generated tables of this document (traces/FORMAT.md) in place");
    cmd->footer("The tables are what the codec reads and writes: traces/format/schema.h describes each record once.\n"
                "FORMAT.md holds them between '<!-- generated: nbsim trace format TYPE VERSION -->' markers.");
    cmd->callback([&action, version, update] { action = [=] { return run_format(*version, *update); }; });
  }
  {
    auto* cmd = tc->add_subcommand("dump", "Write one frame's depth snapshot, N-buffer levels (EXR) and ground truth (CSV or PNG)");
    auto o = std::make_shared<DumpOptions>();
    cmd->add_option("FILE", o->file, "Trace file")->required();
    cmd->add_option("--frame", o->frame, "Frame number (as recorded in the trace)")->required();
    cmd->add_option("--depth", o->depth, "Write the depth snapshot as a single-channel float image (EXR), y up");
    cmd->add_option("--which", o->which,
                    "Which depth image, by name: final (end of frame), occluders or after_occluders (after the occluder "
                    "pass), or any image a technique recorded")
        ->capture_default_str();
    cmd->add_option("--levels", o->levels, "Write the N-buffer levels the GLSL shader built as DIR/level_NN.exr");
    cmd->add_option("--truth", o->truth, "Write the ground truth: OUT.csv (visible pixels per object) or OUT.png (ID buffer)");
    cmd->add_flag("--records", o->records, "Print every record of the frame, field by field (long vectors abbreviated)");
    cmd->footer("At least one of --records, --depth, --levels, --truth. Nothing is written when the frame lacks any of them.\n"
                "With both max and min N-buffers in the frame, the level files are named max_level_NN.exr and min_level_NN.exr.");
    cmd->callback([&action, o] { action = [=] { return run_dump(*o); }; });
  }
}

}  // namespace nbsim::cli
