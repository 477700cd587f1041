// SampleTraceTest: the committed sample traces (traces/samples/, made by scripts/make_samples on
// Mesa) read back whole and check themselves: the GLSL N-buffer levels equal the C++ core's levels
// built from the recorded depth, and GL's counters and the ground truth are consistent.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <set>
#include <string>

#include "model/nbuffer/nbuffer.h"
#include "traces/format/reader.h"

namespace nbsim {
namespace {

class SampleTraceTest : public ::testing::TestWithParam<const char*> {};

// Every frame of the sample reads, and its recorded results agree with each other and the core.
TEST_P(SampleTraceTest, ChecksItself) {
  const std::filesystem::path file = std::filesystem::path(NBSIM_SAMPLES) / GetParam();
  ASSERT_TRUE(std::filesystem::exists(file)) << file << " missing: run scripts/make_samples";
  trace::FrameReader frames(file);
  ASSERT_NE(frames.trace().property("depth_func"), nullptr);
  const FarOp op = frames.trace().header().far_op();
  int count = 0, with_levels = 0;
  while (auto f = frames.next()) {
    ++count;
    for (const auto& d : f->draws) EXPECT_LE(d.gl.samples_passed, d.gl.fragments) << "frame " << f->begin.frame << " draw " << d.index;
    ASSERT_TRUE(f->truth.has_value());
    std::uint64_t px = 0;
    std::set<std::int32_t> drawn;
    for (const auto& d : f->draws)
      if (d.role == trace::DrawRole::Occluder || d.role == trace::DrawRole::Visible) drawn.insert(d.object);
    for (std::size_t o = 0; o < f->truth->visible_pixels.size(); ++o) {
      px += f->truth->visible_pixels[o];
      if (f->truth->visible_pixels[o]) {
        EXPECT_TRUE(drawn.count(static_cast<std::int32_t>(o))) << "false cull: object " << o << " in frame " << f->begin.frame;
      }
    }
    EXPECT_EQ(px, f->truth->covered_pixels);
    if (const trace::NBufferLevels* l = f->nbuffer(op)) {
      ++with_levels;
      const trace::DepthSnapshot* d = f->depth(trace::DepthWhich::AfterOccluders);
      ASSERT_NE(d, nullptr);
      DepthImage img(d->width, d->height, 0.0f);
      img.texels = d->texels;
      const NBuffer core(img, {op, StorageFormat::F32, -1});
      ASSERT_EQ(l->levels, core.level_count());
      for (int i = 0; i < core.level_count(); ++i)
        EXPECT_EQ(std::memcmp(l->texels.data() + static_cast<std::size_t>(i) * core.level(i).size(), core.level(i).data(),
                              core.level(i).size() * 4),
                  0)
            << "GLSL level " << i << " differs from the core's in frame " << f->begin.frame;
    }
  }
  EXPECT_GT(count, 0);
  std::printf("%s: %d frames, %d with N-buffer levels\n", GetParam(), count, with_levels);
}

INSTANTIATE_TEST_SUITE_P(Samples, SampleTraceTest,
                         ::testing::Values("city_walk_512.nbt", "city_small_oq.nbt", "city_small_nb_reversed.nbt"),
                         [](const ::testing::TestParamInfo<const char*>& p) {  // the file name without .nbt
                           const std::string file = p.param;
                           return file.substr(0, file.find('.'));
                         });

}  // namespace
}  // namespace nbsim
