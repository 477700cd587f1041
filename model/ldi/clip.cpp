// The LDI applications' per-fragment volume test; see clip.h.
#include "model/ldi/clip.h"

#include <fmt/format.h>

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>

#include <zlib.h>

#include "model/common/error.h"
#include "model/ldi/vpt.h"
#include "model/scene/technique_record.h"

namespace nbsim::ldi {

namespace {

constexpr const char* kVolumeLabel = "LdiVolume (LDIV)";
constexpr const char* kClipLabel = "LdiClip (LDIC)";

template <class T>
T scalar(const scene::TechniqueRecord& rec, std::string_view name, const char* label, std::uint64_t frame) {
  return scene::record_scalar<T>(rec, name, label, frame);
}

std::uint64_t align(std::uint64_t v) { return (v + 4095) & ~std::uint64_t{4095}; }

ClipVolume read_volume(const scene::TechniqueRecord& rec, std::uint64_t frame, std::uint64_t& mismatches) {
  ClipVolume v;
  v.shape = scalar<std::string>(rec, "shape", kVolumeLabel, frame);
  v.center = {scalar<double>(rec, "center_x", kVolumeLabel, frame), scalar<double>(rec, "center_y", kVolumeLabel, frame),
              scalar<double>(rec, "center_z", kVolumeLabel, frame)};
  v.size = scalar<double>(rec, "size", kVolumeLabel, frame);
  if (!(v.size > 0.0 && std::isfinite(v.size)) || !std::isfinite(v.center[0]) || !std::isfinite(v.center[1]) || !std::isfinite(v.center[2]))
    throw InputError(fmt::format("frame {}: the {} record of '{}' has a placement that is not finite or a size that is not positive", frame,
                                 kVolumeLabel, v.shape));
  const std::vector<float>& xyz = scene::record_field<float>(rec, "mesh_vertices", kVolumeLabel, frame);
  const std::vector<std::uint32_t>& tri = scene::record_field<std::uint32_t>(rec, "mesh_triangles", kVolumeLabel, frame);
  if (xyz.size() % 3 != 0 || tri.size() % 3 != 0)
    throw InputError(fmt::format("frame {}: the {} record's mesh has {} vertex and {} index values; both must be multiples of 3", frame,
                                 kVolumeLabel, xyz.size(), tri.size()));
  for (std::size_t i = 0; i < xyz.size(); i += 3) v.mesh.vertices.push_back({xyz[i], xyz[i + 1], xyz[i + 2]});
  for (std::size_t i = 0; i < tri.size(); i += 3) v.mesh.triangles.push_back({tri[i], tri[i + 1], tri[i + 2]});
  mesh::require_closed(v.mesh, fmt::format("frame {}: the {} record's mesh of '{}'", frame, kVolumeLabel, v.shape));
  const auto u32 = [&](const char* name) { return scalar<std::uint64_t>(rec, name, kVolumeLabel, frame); };
  const std::uint64_t w = u32("width"), h = u32("height"), d = u32("layer_count");
  if (w < 1 || h < 1 || w > kMaxSideTexels || h > kMaxSideTexels || d > kMaxLayers)
    throw InputError(fmt::format("frame {}: the {} record's LDI is {}x{} with {} layers, outside the limits", frame, kVolumeLabel, w, h, d));
  try {
    v.layers = Ldi(static_cast<int>(w), static_cast<int>(h), static_cast<int>(d), scene::record_field<float>(rec, "layers", kVolumeLabel, frame));
  } catch (const InputError& e) {
    throw InputError(fmt::format("frame {}: the {} record's layers: {}", frame, kVolumeLabel, e.what()));
  }
  v.cropped = crop(v.layers);
  v.compressed = compress(v.layers);
  // GL's crop and compressed texture against the model's.
  const auto i32 = [&](const char* name) { return static_cast<int>(scalar<std::int64_t>(rec, name, kVolumeLabel, frame)); };
  const Rect gl_crop{i32("crop_x"), i32("crop_y"), i32("crop_w"), i32("crop_h")};
  const std::vector<std::uint32_t>& gl_comp = scene::record_field<std::uint32_t>(rec, "compressed", kVolumeLabel, frame);
  const bool same_crop = gl_crop.x == v.cropped.crop.rect.x && gl_crop.y == v.cropped.crop.rect.y && gl_crop.w == v.cropped.crop.rect.w &&
                         gl_crop.h == v.cropped.crop.rect.h;
  mismatches += same_crop && static_cast<std::uint64_t>(v.compressed.side) == u32("comp_side") && gl_comp == v.compressed.texels ? 0 : 1;
  v.reference = std::make_shared<const mesh::CrossingReference>(v.mesh, mesh::OrthoFrame{});
  return v;
}

}  // namespace

std::uint32_t depth_crc(const std::vector<float>& texels) {
  return static_cast<std::uint32_t>(crc32(0L, reinterpret_cast<const Bytef*>(texels.data()), static_cast<uInt>(texels.size() * sizeof(float))));
}

std::optional<ClipReader> parse_clip_reader(const std::string& name) {
  for (std::size_t i = 0; i < kClipReaderNames.size(); ++i)
    if (name == kClipReaderNames[i]) return static_cast<ClipReader>(i);
  return std::nullopt;
}

bool ClipDrawCounts::mismatch() const noexcept {
  return path.depth.fragments != gl_fragments || path.depth.passed != gl_samples || discarded != gl_discarded || fetches != gl_fetches ||
         hash_a != gl_hash_a || hash_b != gl_hash_b;
}

// The shader of an LDIC draw: the volume test, with the draw's counts and the reference kept as it runs.
class ClipReplay::VolumeTest final : public raster::FragmentShader {
 public:
  VolumeTest(const std::vector<ClipVolume>& volumes, const std::vector<float>& window_to_texel, const glm::dmat4& window_to_world,
             ClipReader reader, bool keep_inside, double epsilon, int width, memory::LineCache& cache, int line_shift,
             ClipDrawCounts& counts, std::array<std::uint64_t, 3>& reader_fetches)
      : volumes_(volumes),
        m_(window_to_texel),
        to_world_(window_to_world),
        reader_(reader),
        keep_inside_(keep_inside),
        epsilon_(epsilon),
        width_(width),
        cache_(cache),
        line_shift_(line_shift),
        c_(counts),
        reader_fetches_(reader_fetches) {}

  bool discards(int x, int y, float z) const override {
    const float fx = static_cast<float>(x) + 0.5f, fy = static_cast<float>(y) + 0.5f;
    ++c_.tests;
    bool inside = false;
    for (std::size_t v = 0; v < volumes_.size() && !inside; ++v) {
      const float* m = &m_[16 * v];
      float h[4];
      for (int k = 0; k < 4; ++k) h[k] = ((m[k] * fx + m[4 + k] * fy) + m[8 + k] * z) + m[12 + k];
      const float tx = h[0] / h[3], ty = h[1] / h[3], tz = h[2] / h[3];
      ++c_.volume_tests;
      const ClipVolume& vol = volumes_[v];
      const Rect& r = vol.cropped.crop.rect;
      if (!(tx >= static_cast<float>(r.x) && tx < static_cast<float>(r.x + r.w) && ty >= static_cast<float>(r.y) &&
            ty < static_cast<float>(r.y + r.h)))
        continue;
      const int ix = static_cast<int>(tx), iy = static_cast<int>(ty);
      const VptResult layers = vpt_layers(vol.cropped, ix, iy, tz);
      const VptResult all = vpt_all_layers(vol.cropped, ix, iy, tz);
      const VptResult ranges = vpt_ranges(vol.compressed, ix, iy, tz);
      reader_fetches_[0] += static_cast<std::uint64_t>(layers.fetches);
      reader_fetches_[1] += static_cast<std::uint64_t>(all.fetches);
      reader_fetches_[2] += static_cast<std::uint64_t>(ranges.fetches);
      const VptResult& used = reader_ == ClipReader::Layers ? layers : reader_ == ClipReader::All ? all : ranges;
      c_.fetches += static_cast<std::uint64_t>(used.fetches);
      touch(vol, used);
      inside = used.inside;
    }
    score(x, y, z, inside);
    const bool drop = inside != keep_inside_;
    if (drop) {
      std::uint32_t zbits = 0;
      std::memcpy(&zbits, &z, 4);
      const std::uint32_t pixel = static_cast<std::uint32_t>(y) * static_cast<std::uint32_t>(width_) + static_cast<std::uint32_t>(x);
      const std::uint32_t key = mix_bits(pixel ^ mix_bits(zbits));
      ++c_.discarded;
      c_.hash_a += key;
      c_.hash_b += mix_bits(key + 0x9e3779b9u);
    }
    return drop;
  }

 private:
  // The fetches through the texel cache.
  void touch(const ClipVolume& vol, const VptResult& r) const {
    const auto read = [&](std::uint64_t address) { ++(cache_.read(address >> line_shift_) ? c_.cache_hits : c_.cache_misses); };
    if (reader_ == ClipReader::Ranges) {
      for (int i = 0; i < r.fetches; ++i)
        read(vol.compressed_base + 8 * (i == 0 ? r.texel : static_cast<std::uint64_t>(r.first_range) + static_cast<std::uint64_t>(i - 1)));
    } else {
      const Rect& c = vol.cropped.crop.rect;
      const std::uint64_t plane = static_cast<std::uint64_t>(c.w) * static_cast<std::uint64_t>(c.h);
      for (int i = 0; i < r.fetches; ++i) read(vol.layers_base + 4 * (r.texel + static_cast<std::uint64_t>(i) * plane));
    }
  }

  // The exact reference of the fragment's point (clip.h).
  void score(int x, int y, float z, bool answer) const {
    const glm::dvec4 w = to_world_ * glm::dvec4(x + 0.5, y + 0.5, static_cast<double>(z), 1.0);
    const glm::dvec3 p = glm::dvec3(w) / w.w;
    bool inside = false, near = false;
    for (const ClipVolume& vol : volumes_) {
      mesh::Vec3d u{};
      bool in_cube = true;
      for (int k = 0; k < 3; ++k) {
        u[static_cast<std::size_t>(k)] = (p[k] - vol.center[static_cast<std::size_t>(k)]) / vol.size + 0.5;
        in_cube = in_cube && u[static_cast<std::size_t>(k)] >= 0.0 && u[static_cast<std::size_t>(k)] <= 1.0;
      }
      if (!in_cube) continue;
      const mesh::CrossingCount n = vol.reference->count(u);
      if (n.at_point > 0 || n.nearest_distance < epsilon_) near = true;
      inside = inside || n.inside();
    }
    if (near) {
      ++c_.near_surface;
      return;
    }
    ++c_.classified;
    c_.misclassified += inside != answer ? 1 : 0;
  }

  const std::vector<ClipVolume>& volumes_;
  const std::vector<float>& m_;
  glm::dmat4 to_world_;
  ClipReader reader_;
  bool keep_inside_;
  double epsilon_;
  int width_;
  memory::LineCache& cache_;
  int line_shift_;
  ClipDrawCounts& c_;
  std::array<std::uint64_t, 3>& reader_fetches_;
};

ClipReplay::ClipReplay(bool fused_interpolation, const memory::CacheConfig& cache)
    : fused_(fused_interpolation), cache_config_(cache), cache_(std::make_unique<memory::LineCache>(cache)) {}

ClipReplay::~ClipReplay() = default;

std::uint64_t ClipReplay::cache_line_bytes() const noexcept { return static_cast<std::uint64_t>(cache_config_.line_bytes); }

bool ClipReplay::is_clip_frame(const scene::Frame& f) {
  return std::any_of(f.technique_records.begin(), f.technique_records.end(),
                     [](const scene::TechniqueRecord& r) { return r.type == kLdiClipRecordType; });
}

ClipFrameCounts ClipReplay::run_frame(const scene::Frame& f) {
  const std::uint64_t frame = f.begin.frame;
  ClipFrameCounts out;
  // 1. Volumes built this frame (they replace the ones before).
  std::vector<ClipVolume> loaded;
  for (const scene::TechniqueRecord& r : f.technique_records) {
    if (r.type != kLdiVolumeRecordType) continue;
    if (!r.decoded) throw InputError(fmt::format("frame {}: the {} record was not decoded", frame, kVolumeLabel));
    loaded.push_back(read_volume(r, frame, out.volume_mismatches));
  }
  if (!loaded.empty()) {
    if (loaded.size() > static_cast<std::size_t>(kMaxClipVolumes))
      throw InputError(fmt::format("frame {}: {} {} records; at most {} volumes", frame, loaded.size(), kVolumeLabel, kMaxClipVolumes));
    volumes_ = std::move(loaded);
    out.volumes_loaded = volumes_.size();
    std::uint64_t base = 0;
    for (ClipVolume& v : volumes_) {
      v.layers_base = base;
      base = align(base + 4 * v.cropped.depths.size());
      v.compressed_base = base;
      base = align(base + 4 * v.compressed.texels.size());
    }
    cache_->invalidate();
  }
  const scene::TechniqueRecord& rec = scene::single_record(f, kLdiClipRecordType, kClipLabel, "a clipping frame tests its draws");
  if (volumes_.empty()) throw InputError(fmt::format("frame {}: an {} record before any {} record", frame, kClipLabel, kVolumeLabel));
  const std::uint64_t count = scalar<std::uint64_t>(rec, "volume_count", kClipLabel, frame);
  if (count != volumes_.size())
    throw InputError(fmt::format("frame {}: the {} record tests {} volumes, but {} were built", frame, kClipLabel, count, volumes_.size()));
  const std::uint64_t reader = scalar<std::uint64_t>(rec, "reader", kClipLabel, frame);
  if (reader > 2) throw InputError(fmt::format("frame {}: the {} record's reader is {}, not 0, 1 or 2", frame, kClipLabel, reader));
  out.reader = static_cast<ClipReader>(reader);
  const int width = static_cast<int>(scalar<std::uint64_t>(rec, "width", kClipLabel, frame));
  const int height = static_cast<int>(scalar<std::uint64_t>(rec, "height", kClipLabel, frame));
  if (width < 1 || height < 1 || width > 16384 || height > 16384)
    throw InputError(fmt::format("frame {}: the {} record's viewport is {}x{}", frame, kClipLabel, width, height));
  if (!path_ || width != width_ || height != height_) {
    width_ = width, height_ = height;
    path_.reset();
    depth_ = std::make_unique<DepthImage>(width, height, 1.0f);
    raster::RasterPathConfig c;
    c.width_px = width, c.height_px = height, c.fused_interpolation = fused_;
    path_ = std::make_unique<raster::RasterPath>(c, *depth_);
  }
  std::fill(depth_->texels.begin(), depth_->texels.end(), 1.0f);
  const double epsilon = scalar<double>(rec, "epsilon", kClipLabel, frame);
  const std::vector<float>& vp = scene::record_field<float>(rec, "view_proj", kClipLabel, frame);
  const std::vector<float>& m = scene::record_field<float>(rec, "window_to_texel", kClipLabel, frame);
  const std::vector<std::uint32_t>& draws = scene::record_field<std::uint32_t>(rec, "draws", kClipLabel, frame);
  const std::vector<std::uint32_t>& keep = scene::record_field<std::uint32_t>(rec, "keep_inside", kClipLabel, frame);
  const std::vector<std::uint32_t>& gl_discarded = scene::record_field<std::uint32_t>(rec, "gl_discarded", kClipLabel, frame);
  const std::vector<std::uint32_t>& gl_fetches = scene::record_field<std::uint32_t>(rec, "gl_fetches", kClipLabel, frame);
  const std::vector<std::uint32_t>& gl_a = scene::record_field<std::uint32_t>(rec, "gl_hash_a", kClipLabel, frame);
  const std::vector<std::uint32_t>& gl_b = scene::record_field<std::uint32_t>(rec, "gl_hash_b", kClipLabel, frame);
  if (vp.size() != 16 || m.size() != 16 * count)
    throw InputError(fmt::format("frame {}: the {} record has {} view_proj and {} window_to_texel values; 16 and 16 a volume expected",
                                 frame, kClipLabel, vp.size(), m.size()));
  for (const auto* v : {&keep, &gl_discarded, &gl_fetches, &gl_a, &gl_b})
    if (v->size() != draws.size())
      throw InputError(fmt::format("frame {}: the {} record's per-draw fields differ in length from 'draws' ({})", frame, kClipLabel, draws.size()));
  // Window coordinates to the world: NDC = 2 window / size - 1, z likewise, through view_proj's inverse.
  glm::dmat4 view_proj(0.0), window_to_ndc(1.0);
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) view_proj[c][r] = static_cast<double>(vp[static_cast<std::size_t>(4 * c + r)]);
  window_to_ndc[0][0] = 2.0 / width, window_to_ndc[1][1] = 2.0 / height, window_to_ndc[2][2] = 2.0;
  window_to_ndc[3] = glm::dvec4(-1.0, -1.0, -1.0, 1.0);
  const glm::dmat4 window_to_world = glm::inverse(view_proj) * window_to_ndc;

  int line_shift = 0;
  while ((1 << line_shift) < cache_config_.line_bytes) ++line_shift;
  std::size_t next = 0;
  for (const scene::DrawRecord& d : f.draws) {
    const bool tested = next < draws.size() && draws[next] == d.index;
    if (d.topology != scene::Topology::Triangles || d.clip_positions.size() % 3 != 0)
      throw InputError(fmt::format("frame {}: draw {} is not a list of triangles", frame, d.index));
    raster::DrawState state = raster::draw_state(d.state);
    ClipDrawCounts c;
    c.draw = d.index;
    c.gl_fragments = d.gl.fragments, c.gl_samples = d.gl.samples_passed;
    std::optional<VolumeTest> test;
    if (tested) {
      if (keep[next] > 1) throw InputError(fmt::format("frame {}: the {} record's keep_inside of draw {} is {}", frame, kClipLabel, d.index, keep[next]));
      c.tested = true;
      c.keep_inside = keep[next] == 1;
      c.gl_discarded = gl_discarded[next], c.gl_fetches = gl_fetches[next], c.gl_hash_a = gl_a[next], c.gl_hash_b = gl_b[next];
      test.emplace(volumes_, m, window_to_world, out.reader, c.keep_inside, epsilon, width, *cache_, line_shift, c, out.reader_fetches);
      state.depth.shader = &*test;
      ++next;
    }
    c.path = path_->draw(d.clip_positions, state);
    out.draw_mismatches += c.mismatch() ? 1 : 0;
    out.decision_mismatches += c.discarded != c.gl_discarded || c.hash_a != c.gl_hash_a || c.hash_b != c.gl_hash_b ? 1 : 0;
    out.draws.push_back(c);
  }
  if (next != draws.size())
    throw InputError(fmt::format("frame {}: the {} record names draw {}, which the frame does not have (or not in order)", frame, kClipLabel,
                                 draws[next]));
  out.depth_mismatch = depth_crc(depth_->texels) != static_cast<std::uint32_t>(scalar<std::uint64_t>(rec, "depth_crc", kClipLabel, frame));
  return out;
}

}  // namespace nbsim::ldi
