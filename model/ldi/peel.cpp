// The layered-depth-image program's plain core; see peel.h.
#include "model/ldi/peel.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "model/common/error.h"
#include "model/ldi/vpt.h"
#include "model/scene/technique_record.h"
#include "model/ldi/roles.h"

namespace nbsim::ldi {

namespace {

raster::RasterPathConfig path_config(int width, int height, bool fused) {
  if (width < 1 || width > kMaxSideTexels || height < 1 || height > kMaxSideTexels)
    throw InputError(fmt::format("the LDI is {}x{} texels; each side must be 1 to {}", width, height, kMaxSideTexels));
  raster::RasterPathConfig c;
  c.width_px = width;
  c.height_px = height;
  c.fused_interpolation = fused;
  return c;
}

constexpr const char* kImageLabel = "LdiImage (LDIL)";
constexpr const char* kTestsLabel = "LdiTests (LDIT)";
constexpr const char* kAllLabel = "LdiAllLayers (LDIA)";
constexpr std::uint32_t kLdiAllLayersRecordType = 0x4149444Cu;  // fourcc "LDIA" (traces/format/ldi/ldi_chunk.h)

template <class T>
T scalar(const scene::TechniqueRecord& rec, std::string_view name, const char* label, std::uint64_t frame) {
  return scene::record_scalar<T>(rec, name, label, frame);
}

}  // namespace

PeelReplay::PeelReplay(int width, int height, bool fused_interpolation)
    : width_(width),
      height_(height),
      depth_(path_config(width, height, fused_interpolation).width_px, height, 1.0f),
      previous_(width, height, kInvalidDepth),
      written_(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), 0),
      path_(path_config(width, height, fused_interpolation), depth_) {
  path_.set_reuse_rasterization(true);  // every pass draws the same mesh: its blocks are walked once a frame
}

void PeelReplay::begin_frame() {
  layers_.clear();
  passes_ = layer_count_ = 0;
  ended_ = false;
}

PeelPassCounts PeelReplay::pass(std::span<const geometry::ClipPosition> clip_positions, const raster::DrawState& state) {
  std::fill(depth_.texels.begin(), depth_.texels.end(), 1.0f);  // cleared to 1.0 before each pass
  std::fill(written_.begin(), written_.end(), std::uint8_t{0});
  if (ended_) std::fill(previous_.texels.begin(), previous_.texels.end(), kInvalidDepth);  // nothing left to peel
  raster::DrawState s = state;
  s.depth.peel_layer = passes_ > 0 ? &previous_ : nullptr;  // pass 0 discards none
  s.depth.passed_mask = &written_;
  const raster::DrawCounters k = path_.draw(clip_positions, s);
  PeelPassCounts c;
  c.triangles = k.geometry.prims_out;
  c.blocks = k.depth.blocks;
  c.fragments = k.depth.fragments;
  c.peel_reads = k.depth.peel_reads;
  c.peel_discarded = k.depth.peel_discarded;
  c.depth_tests = k.depth.depth_tests;
  c.samples = k.depth.passed;
  // This pass's layer: the buffer where a sample passed, +inf elsewhere; the next pass's "previous".
  for (std::size_t i = 0; i < written_.size(); ++i) {
    previous_.texels[i] = written_[i] ? depth_.texels[i] : kInvalidDepth;
    c.layer_texels += written_[i];
  }
  ++passes_;
  if (!ended_ && c.samples > 0) {
    layers_.insert(layers_.end(), previous_.texels.begin(), previous_.texels.end());
    ++layer_count_;
  } else {
    ended_ = true;
  }
  return c;
}

Ldi PeelReplay::ldi() const { return Ldi(width_, height_, layer_count_, layers_); }

namespace {

const scene::TechniqueRecord& image_record(const scene::Frame& f) {
  return scene::single_record(f, kLdiImageRecordType, kImageLabel, "the peel has no LDI size and nothing to compare with");
}

int bounded(const scene::TechniqueRecord& rec, const char* name, std::uint64_t limit, std::uint64_t frame) {
  const std::uint64_t v = scalar<std::uint64_t>(rec, name, kImageLabel, frame);
  if (v > limit) throw InputError(fmt::format("frame {}: the {} record's {} is {}, above {}", frame, kImageLabel, name, v, limit));
  return static_cast<int>(v);
}

std::array<int, 2> image_size(const scene::TechniqueRecord& rec, std::uint64_t frame) {
  const int w = bounded(rec, "width", kMaxSideTexels, frame), h = bounded(rec, "height", kMaxSideTexels, frame);
  if (w < 1 || h < 1)
    throw InputError(fmt::format("frame {}: the {} record's LDI is {}x{} texels; each side must be 1 to {}", frame, kImageLabel, w, h,
                                 kMaxSideTexels));
  return {w, h};
}

}  // namespace

std::array<int, 2> read_ldi_size(const scene::Frame& f) { return image_size(image_record(f), f.begin.frame); }

GlLdiImage read_ldi_image(const scene::Frame& f) {
  const std::uint64_t frame = f.begin.frame;
  const scene::TechniqueRecord& rec = image_record(f);
  const auto u32 = [&](const char* name, std::uint64_t limit) { return bounded(rec, name, limit, frame); };
  GlLdiImage g;
  const std::array<int, 2> size = image_size(rec, frame);
  g.width = size[0], g.height = size[1];
  g.layer_count = u32("layer_count", kMaxLayers);
  const std::vector<float>& layers = scene::record_field<float>(rec, "layers", kImageLabel, frame);
  try {
    g.layers = Ldi(g.width, g.height, g.layer_count, layers);
  } catch (const InputError& e) {
    throw InputError(fmt::format("frame {}: the {} record's layers: {}", frame, kImageLabel, e.what()));
  }
  const auto i32 = [&](const char* name) { return static_cast<int>(scalar<std::int64_t>(rec, name, kImageLabel, frame)); };
  g.crop = Rect{i32("crop_x"), i32("crop_y"), i32("crop_w"), i32("crop_h")};
  if (g.crop.x < 0 || g.crop.y < 0 || g.crop.w < 0 || g.crop.h < 0 || g.crop.x + g.crop.w > g.width || g.crop.y + g.crop.h > g.height)
    throw InputError(fmt::format("frame {}: the {} record's crop ({}, {}, {}x{}) is not inside the {}x{} LDI", frame, kImageLabel,
                                 g.crop.x, g.crop.y, g.crop.w, g.crop.h, g.width, g.height));
  CompressedLdi& c = g.compressed;
  c.source_width = g.width, c.source_height = g.height, c.source_layers = g.layer_count;
  c.crop.rect = g.crop;
  c.crop.depth_complexity = g.layer_count;  // LDIL's layer_count is d
  c.side = u32("comp_side", kMaxSideTexels);
  c.index_texels = static_cast<std::uint32_t>(scalar<std::uint64_t>(rec, "comp_index", kImageLabel, frame));
  c.range_texels = static_cast<std::uint32_t>(scalar<std::uint64_t>(rec, "comp_ranges", kImageLabel, frame));
  c.texels = scene::record_field<std::uint32_t>(rec, "compressed", kImageLabel, frame);
  const std::uint64_t want = 2ull * static_cast<std::uint64_t>(c.side) * static_cast<std::uint64_t>(c.side);
  if (c.texels.size() != want)
    throw InputError(fmt::format("frame {}: the {} record's compressed texture has {} values, but comp_side {} needs {}", frame,
                                 kImageLabel, c.texels.size(), c.side, want));
  return g;
}

GlLdiTests read_ldi_tests(const scene::Frame& f) {
  const std::uint64_t frame = f.begin.frame;
  const scene::TechniqueRecord& rec = scene::single_record(f, kLdiTestsRecordType, kTestsLabel, "no test point to check");
  GlLdiTests t;
  t.count = scalar<std::uint64_t>(rec, "count", kTestsLabel, frame);
  t.epsilon = scalar<double>(rec, "epsilon", kTestsLabel, frame);
  const auto vec = [&](auto& out, const char* name) {
    using V = std::remove_reference_t<decltype(out)>;
    out = scene::record_field<typename V::value_type>(rec, name, kTestsLabel, frame);
    if (out.size() != t.count)
      throw InputError(fmt::format("frame {}: the {} record's field '{}' has {} values, but count is {}", frame, kTestsLabel, name,
                                   out.size(), t.count));
  };
  vec(t.kind, "kind"), vec(t.x, "x"), vec(t.y, "y"), vec(t.z, "z");
  vec(t.gl_inside_layers, "gl_inside_layers"), vec(t.gl_fetches_layers, "gl_fetches_layers");
  vec(t.gl_inside_ranges, "gl_inside_ranges"), vec(t.gl_fetches_ranges, "gl_fetches_ranges");
  vec(t.reference, "reference");
  for (std::size_t p = 0; p < t.count; ++p) {
    const auto bad = [&](const char* what, auto value) {
      return InputError(fmt::format("frame {}: the {} record's test point {} has {} {}", frame, kTestsLabel, p, what, value));
    };
    if (t.kind[p] >= kPointKinds) throw bad("kind", t.kind[p]);
    if (t.gl_inside_layers[p] > 1) throw bad("gl_inside_layers", t.gl_inside_layers[p]);
    if (t.gl_inside_ranges[p] > 1) throw bad("gl_inside_ranges", t.gl_inside_ranges[p]);
    if (t.reference[p] < kNearSurfaceReference) throw bad("reference", t.reference[p]);
    if (std::isnan(t.z[p])) throw bad("depth z", "NaN");
  }
  bool has_all = false;
  for (const scene::TechniqueRecord& r : f.technique_records) has_all = has_all || r.type == kLdiAllLayersRecordType;
  if (has_all) {
    const scene::TechniqueRecord& all = scene::single_record(f, kLdiAllLayersRecordType, kAllLabel, "");
    const std::uint64_t count = scalar<std::uint64_t>(all, "count", kAllLabel, frame);
    if (count != t.count)
      throw InputError(fmt::format("frame {}: the {} record has {} test points, but the {} record {}", frame, kAllLabel, count, kTestsLabel,
                                   t.count));
    const auto all_vec = [&](std::vector<std::uint32_t>& out, const char* name) {
      out = scene::record_field<std::uint32_t>(all, name, kAllLabel, frame);
      if (out.size() != t.count)
        throw InputError(fmt::format("frame {}: the {} record's field '{}' has {} values, but count is {}", frame, kAllLabel, name,
                                     out.size(), t.count));
    };
    all_vec(t.gl_inside_all, "gl_inside_all"), all_vec(t.gl_fetches_all, "gl_fetches_all");
    for (std::size_t p = 0; p < t.count; ++p)
      if (t.gl_inside_all[p] > 1)
        throw InputError(fmt::format("frame {}: the {} record's test point {} has gl_inside_all {}", frame, kAllLabel, p, t.gl_inside_all[p]));
    t.has_all = true;
  }
  return t;
}

LdiFrameCounts run_frame(const scene::Frame& f, PeelReplay& peel) {
  const std::uint64_t frame = f.begin.frame;
  // Everything the frame needs is read and checked first (a damaged trace: exit 2, nothing run).
  const GlLdiImage gl = read_ldi_image(f);
  const GlLdiTests tests = read_ldi_tests(f);
  if (gl.width != peel.width() || gl.height != peel.height())
    throw InputError(fmt::format("frame {}: the LDI is {}x{}, the peel's render target {}x{}", frame, gl.width, gl.height,
                                 peel.width(), peel.height()));
  // GL's texture must give GL's layers back (the compression is lossless).
  try {
    const Ldi back = decompress(gl.compressed);
    if (!bit_equal(back, gl.layers))
      throw InputError("it decompresses to other layers than the record's");
  } catch (const InputError& e) {
    throw InputError(fmt::format("frame {}: GL's compressed LDI texture (LDIL 'compressed'): {}", frame, e.what()));
  }

  LdiFrameCounts k;
  // 1. The peel, pass by pass.
  peel.begin_frame();
  for (const scene::DrawRecord& d : f.draws) {
    if (d.role != kLdiPeelRole) continue;
    if (d.topology != scene::Topology::Triangles || d.clip_positions.size() % 3 != 0)
      throw InputError(fmt::format("frame {}: peel draw {} is not a list of triangles", frame, d.index));
    const PeelPassCounts p = peel.pass(d.clip_positions, draw_state(d.state));
    k.peel_fragments += p.fragments, k.gl_peel_fragments += d.gl.fragments;
    k.peel_samples += p.samples, k.gl_peel_samples += d.gl.samples_passed;
    k.peel_pass_mismatches += p.fragments != d.gl.fragments || p.samples != d.gl.samples_passed ? 1 : 0;
    k.passes.push_back(p);
  }
  // The model's layers break ldi.h's rules only if the rasterizer interpolates a depth outside
  // [0, 1] (clip positions outside the zero-to-one range with depth clamp on): the trace's fault.
  const Ldi model = [&] {
    try {
      return peel.ldi();
    } catch (const InputError& e) {
      throw InputError(fmt::format("frame {}: the model's peel of the recorded draws is not an LDI: {}", frame, e.what()));
    }
  }();
  k.layers = model.layer_count();
  k.gl_layers = gl.layer_count;
  const int layers = std::max(k.layers, k.gl_layers);
  for (int l = 0; l < layers; ++l)
    for (int y = 0; y < gl.height; ++y)
      for (int x = 0; x < gl.width; ++x) {
        const float a = l < k.layers ? model.depth(x, y, l) : kInvalidDepth;
        const float b = l < k.gl_layers ? gl.layers.depth(x, y, l) : kInvalidDepth;
        k.layer_texel_mismatches += std::bit_cast<std::uint32_t>(a) != std::bit_cast<std::uint32_t>(b) ? 1 : 0;
      }

  // 2. Crop and compression of the model's own LDI.
  const CroppedLdi cropped = crop(model);
  const CompressedLdi compressed = compress(model);
  const Rect& r = cropped.crop.rect;
  // An empty crop is any rectangle of zero area.
  k.crop_mismatch = r.empty() && gl.crop.empty() ? false : (r.x != gl.crop.x || r.y != gl.crop.y || r.w != gl.crop.w || r.h != gl.crop.h);
  const std::size_t n = std::max(compressed.texels.size(), gl.compressed.texels.size());
  for (std::size_t i = 0; i < n; ++i) {
    const bool both = i < compressed.texels.size() && i < gl.compressed.texels.size();
    k.compressed_mismatches += !both || compressed.texels[i] != gl.compressed.texels[i] ? 1 : 0;
  }
  k.m_crop = compressed.m_crop();
  k.m_comp = compressed.m_comp();

  // 3. The parity test on the model's LDI at GL's points.
  k.test_points = tests.count;
  for (std::size_t p = 0; p < tests.count; ++p) {
    const VptResult a = vpt_layers(cropped, tests.x[p], tests.y[p], tests.z[p]);
    const VptResult b = vpt_ranges(compressed, tests.x[p], tests.y[p], tests.z[p]);
    k.fetches_layers += static_cast<std::uint64_t>(a.fetches);
    k.fetches_ranges += static_cast<std::uint64_t>(b.fetches);
    k.gl_fetches_layers += tests.gl_fetches_layers[p];
    k.gl_fetches_ranges += tests.gl_fetches_ranges[p];
    k.parity_mismatches_layers += a.inside != (tests.gl_inside_layers[p] == 1) ? 1 : 0;
    k.parity_mismatches_ranges += b.inside != (tests.gl_inside_ranges[p] == 1) ? 1 : 0;
    k.fetch_mismatches_layers += static_cast<std::uint32_t>(a.fetches) != tests.gl_fetches_layers[p] ? 1 : 0;
    k.fetch_mismatches_ranges += static_cast<std::uint32_t>(b.fetches) != tests.gl_fetches_ranges[p] ? 1 : 0;
    VptResult c;
    if (tests.has_all) {
      c = vpt_all_layers(cropped, tests.x[p], tests.y[p], tests.z[p]);
      ++k.all_points;
      k.fetches_all += static_cast<std::uint64_t>(c.fetches);
      k.gl_fetches_all += tests.gl_fetches_all[p];
      k.parity_mismatches_all += c.inside != (tests.gl_inside_all[p] == 1) ? 1 : 0;
      k.fetch_mismatches_all += static_cast<std::uint32_t>(c.fetches) != tests.gl_fetches_all[p] ? 1 : 0;
    }
    const std::uint32_t kind = tests.kind[p];
    ++k.kind_points[kind];
    if (tests.reference[p] == kNearSurfaceReference) {
      ++k.near_surface_points;
      continue;
    }
    const bool inside = tests.reference[p] % 2 == 1;
    ++k.classified_points, ++k.kind_classified[kind];
    if (a.inside != inside) ++k.misclassified_layers, ++k.kind_misclassified_layers[kind];
    if (b.inside != inside) ++k.misclassified_ranges, ++k.kind_misclassified_ranges[kind];
    if (tests.has_all && c.inside != inside) ++k.misclassified_all;
  }
  return k;
}

}  // namespace nbsim::ldi
