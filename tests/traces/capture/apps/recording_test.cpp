// The interposer's recording (traces/apitrace/raw.h) as RawReader reads it and convert_recording
// turns it into a trace: recordings written here record by record, every damage refused with the
// byte offset and what is wrong, and a whole one converted into the trace the model reads.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "model/apps/roles.h"
#include "model/common/error.h"
#include "tests/common/scratch.h"
#include "traces/capture/apps/convert.h"
#include "traces/capture/apps/recording.h"
#include "traces/format/apps/apps_chunk.h"
#include "traces/format/reader.h"

namespace nbsim::apitrace {
namespace {

using Bytes = std::vector<std::uint8_t>;

// Appends bytes (resize and copy: GCC 12 warns wrongly about vector::insert of bytes).
void append(Bytes& b, const void* data, std::size_t n) {
  const std::size_t at = b.size();
  b.resize(at + n);
  if (n) std::memcpy(b.data() + at, data, n);
}

template <class T>
void put(Bytes& b, const T& v) {
  append(b, &v, sizeof v);
}

void record(Bytes& b, RawType type, const Bytes& payload) {
  put(b, RecordHead{static_cast<std::uint32_t>(type), static_cast<std::uint32_t>(payload.size())});
  append(b, payload.data(), payload.size());
}

Bytes head(std::uint32_t first = 0, std::uint32_t last = 0xFFFFFFFFu) {
  Bytes b;
  FileHead h{};
  std::memcpy(h.magic, kRawMagic, sizeof h.magic);
  h.version = kRawVersion;
  h.first_frame = first, h.last_frame = last;
  put(b, h);
  return b;
}

DrawHead draw_head(std::uint32_t frame, std::uint32_t index, std::uint32_t vertices) {
  DrawHead d{};
  d.frame = frame, d.index = index, d.mode = 4, d.primitive = 4, d.vertices = vertices;
  d.flags = kDepthTest | kDepthMask | kFrontCcw | kCullFace;
  d.framebuffer = 0, d.target_width = 4, d.target_height = 2;
  d.viewport[2] = 4, d.viewport[3] = 2;
  d.depth_range[1] = 1.0;
  d.depth_func = 0x0201, d.cull_mode = 0x0405, d.polygon_mode = 0x1B02;
  d.depth_bits = 24;
  d.samples_passed = 3;
  return d;
}

Bytes draw(std::uint32_t frame, std::uint32_t index, std::uint32_t vertices = 3) {
  Bytes p;
  put(p, draw_head(frame, index, vertices));
  for (std::uint32_t v = 0; v < vertices; ++v)
    for (const float c : {0.0f, 0.5f, 0.25f, 1.0f}) put(p, c);
  return p;
}

Bytes frame_end(std::uint32_t frame, std::uint32_t draws, bool depth = true) {
  Bytes p;
  put(p, FrameHead{frame, draws, 0, 4, 2, depth ? 1u : 0u});
  if (depth)
    for (int i = 0; i < 8; ++i) put(p, 0.5f);
  return p;
}

Bytes note(const std::string& s) { return Bytes(s.begin(), s.end()); }

// A whole recording: notes, frames 5 and 6, each a clear, two draws (the second with a depth change),
// and frame 6 an unhandled feature.
Bytes whole() {
  Bytes b = head(5, 6);
  record(b, RawType::Note, note("GL_RENDERER=llvmpipe (test)"));
  record(b, RawType::Note, note("GL_VERSION=4.5 (Compatibility Profile) Mesa 22.3.6"));
  for (std::uint32_t f = 5; f <= 6; ++f) {
    Bytes c;
    ClearHead ch{};
    ch.frame = f, ch.buffers = kClearDepth, ch.flags = kDepthMask, ch.depth = 1.0, ch.scissor[2] = 4, ch.scissor[3] = 2;
    put(c, ch);
    record(b, RawType::Clear, c);
    record(b, RawType::Draw, draw(f, 0));
    record(b, RawType::Draw, draw(f, 1));
    Bytes d;
    put(d, DeltaHead{f, 1, 0, 4, 2, 2});
    for (const std::uint32_t px : {1u, 6u}) put(d, px);
    for (const float z : {0.25f, 0.75f}) put(d, z);
    record(b, RawType::Delta, d);
    if (f == 6) {
      Bytes u;
      const std::string name = "glBegin (immediate mode)";
      put(u, UnhandledHead{f, 1, 3, static_cast<std::uint32_t>(name.size())});
      append(u, name.data(), name.size());
      record(b, RawType::Unhandled, u);
    }
    record(b, RawType::Frame, frame_end(f, 2));
  }
  record(b, RawType::End, {});
  return b;
}

std::filesystem::path write(const Bytes& b, const std::string& name) {
  const auto p = nbsim::testing::scratch_path("nbsim_apps_recording", name);
  std::FILE* f = std::fopen(p.string().c_str(), "wb");
  std::fwrite(b.data(), 1, b.size(), f);
  std::fclose(f);
  return p;
}

// Reads every frame; the InputError's message, or "" when all read.
std::string read_error(const Bytes& b) {
  try {
    RawReader r(write(b, "damaged.raw"));
    while (r.next()) {
    }
    return "";
  } catch (const InputError& e) {
    return e.what();
  }
}

TEST(AppsRecordingTest, AWholeRecordingReadsBack) {
  RawReader r(write(whole(), "whole.raw"));
  auto f = r.next();
  ASSERT_TRUE(f);
  EXPECT_EQ(f->frame, 5u);
  ASSERT_EQ(f->draws.size(), 2u);
  EXPECT_EQ(f->draws[0].positions.size(), 3u);
  EXPECT_FALSE(f->draws[0].has_delta);
  ASSERT_TRUE(f->draws[1].has_delta);
  EXPECT_EQ(f->draws[1].delta_pixels, (std::vector<std::uint32_t>{1, 6}));
  EXPECT_EQ(f->clears.size(), 1u);
  EXPECT_EQ(f->depth.size(), 8u);
  f = r.next();
  ASSERT_TRUE(f);
  ASSERT_EQ(f->unhandled.size(), 1u);
  EXPECT_EQ(f->unhandled[0].name, "glBegin (immediate mode)");
  EXPECT_EQ(f->unhandled[0].count, 3u);
  EXPECT_FALSE(r.next());
  EXPECT_EQ(r.notes().size(), 2u);
}

TEST(AppsRecordingTest, DamageIsRefusedWithWhatIsWrong) {
  const Bytes good = whole();
  struct Case {
    const char* what;
    Bytes bytes;
    const char* message;
  };
  std::vector<Case> cases;
  {
    Bytes b = good;
    b[0] = 'X';
    cases.push_back({"magic", b, "not an nbsim interposer recording"});
  }
  {
    Bytes b = good;
    b[8] = 9;
    cases.push_back({"version", b, "recording version 9"});
  }
  cases.push_back({"no end marker", Bytes(good.begin(), good.end() - 8), "ends before its end marker"});
  cases.push_back({"cut in a record", Bytes(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(good.size() / 2)), "the file ends inside"});
  {
    Bytes b = head(5, 6);
    record(b, RawType::Draw, draw(5, 1));
    cases.push_back({"draw out of order", b, "draw 1 where draw 0 comes next"});
  }
  {
    Bytes b = head(5, 6);
    Bytes d = draw(5, 0);
    d.pop_back();
    record(b, RawType::Draw, d);
    cases.push_back({"draw size", b, "bytes for 3 vertices"});
  }
  {
    Bytes b = head(5, 6);
    record(b, RawType::Draw, draw(5, 0, 2));
    cases.push_back({"two vertices of triangles", b, "2 vertices of primitive 0x4"});
  }
  {
    Bytes b = head(5, 6);
    record(b, RawType::Draw, draw(9, 0));
    cases.push_back({"frame outside the range", b, "outside the recorded frames 5:6"});
  }
  {
    Bytes b = head(5, 6);
    record(b, RawType::Draw, draw(5, 0));
    Bytes d;
    put(d, DeltaHead{5, 0, 0, 4, 2, 1});
    put(d, 8u);
    put(d, 0.5f);
    record(b, RawType::Delta, d);
    cases.push_back({"change outside the target", b, "pixel 8 out of order or outside the target"});
  }
  {
    Bytes b = head(5, 6);
    Bytes d;
    put(d, DeltaHead{5, 0, 0, 4, 2, 0});
    record(b, RawType::Delta, d);
    cases.push_back({"change of no draw", b, "does not follow it"});
  }
  {
    Bytes b = head(5, 6);
    record(b, RawType::Draw, draw(5, 0));
    record(b, RawType::Frame, frame_end(5, 3));
    cases.push_back({"draw count", b, "frame 5 ends after 3 draws, but 1 were recorded"});
  }
  {
    Bytes b = head(5, 6);
    record(b, static_cast<RawType>(42), {});
    cases.push_back({"record type", b, "unknown record type 42"});
  }
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    const std::string e = read_error(c.bytes);
    EXPECT_NE(e.find(c.message), std::string::npos) << e;
    EXPECT_NE(e.find("byte "), std::string::npos) << e;
  }
  EXPECT_EQ(read_error(good), "");
}

// A refused head closes the file (found by fuzz_apitrace_recording: the constructor threw with the
// file open, and after a thousand refusals every open failed).
TEST(AppsRecordingTest, ARefusedRecordingLeavesNoFileOpen) {
  Bytes b = whole();
  b[0] = 'X';
  const auto file = write(b, "bad_head.raw");
  const auto open_files = [] {
    return std::distance(std::filesystem::directory_iterator("/proc/self/fd"), std::filesystem::directory_iterator{});
  };
  const auto before = open_files();
  for (int i = 0; i < 100; ++i) EXPECT_THROW(RawReader r(file), InputError);
  EXPECT_EQ(open_files(), before);
}

TEST(AppsRecordingTest, ConvertedIntoATraceOfTechniqueApps) {
  const auto out = nbsim::testing::scratch_path("nbsim_apps_recording", "whole.nbt");
  const ConvertSummary s = convert_recording(write(whole(), "whole.raw"), out, {"prog.trace", "nbsim capture apitrace prog.trace -o whole.nbt"});
  EXPECT_EQ(s.frames, 2u);
  EXPECT_EQ(s.draws, 4u);
  EXPECT_EQ(s.depth_changes, 2u);
  EXPECT_EQ(s.unhandled.at("glBegin (immediate mode)"), 3u);
  trace::FrameReader frames(out);
  EXPECT_EQ(*frames.trace().property("technique"), "apps");
  EXPECT_EQ(*frames.trace().property("apitrace"), "prog.trace");
  EXPECT_EQ(*frames.trace().property("app_frames"), "5:6");
  EXPECT_EQ(*frames.trace().property("gl_renderer"), "llvmpipe (test)");
  EXPECT_EQ(*frames.trace().property("depth_format"), "DEPTH_COMPONENT24");
  int n = 0;
  while (auto f = frames.next()) {
    ++n;
    ASSERT_EQ(f->draws.size(), 2u);
    EXPECT_EQ(f->draws[0].role, apps::kAppDrawRole);
    EXPECT_EQ(f->draws[0].clip_positions.size(), 3u);
    EXPECT_EQ(f->draws[0].gl.samples_passed, 3u);
    EXPECT_EQ(f->draws[0].state.cull, scene::CullFace::Back);
    ASSERT_NE(f->depth("final"), nullptr);
    int changes = 0;
    for (const auto& r : f->technique_records) changes += r.type == trace::kAppDepthChangeChunk ? 1 : 0;
    EXPECT_EQ(changes, 1);
  }
  EXPECT_EQ(n, 2);
  // A damaged recording leaves no trace, not even a partial one.
  Bytes cut = whole();
  cut.resize(cut.size() - 8);
  const auto bad = nbsim::testing::scratch_path("nbsim_apps_recording", "cut.nbt");
  EXPECT_THROW(convert_recording(write(cut, "cut.raw"), bad, {}), InputError);
  EXPECT_FALSE(std::filesystem::exists(bad));
  EXPECT_FALSE(std::filesystem::exists(bad.string() + ".partial"));
  // An OpenGL ES context is refused by name.
  Bytes es = head();
  record(es, RawType::Note, note("GL_VERSION=OpenGL ES 3.2 Mesa 22.3.6"));
  record(es, RawType::Frame, frame_end(0, 0));
  record(es, RawType::End, {});
  try {
    convert_recording(write(es, "es.raw"), bad, {});
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("OpenGL ES context"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace nbsim::apitrace
