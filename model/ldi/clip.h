// The LDI applications in a scene (Trapp & Doellner's clipping and 3D lenses), the model side's plain
// core: every scene fragment runs the volumetric parity test against one to kMaxClipVolumes volumes
// before the depth test, as a fragment shader's discard (raster::FragmentShader), and is discarded
// inside a volume (clipping; a lens's context pass) or outside every volume (a lens's focus pass).
//
// The volumes come from the trace's LdiVolume records (LDIV, in the frame that built them; kept for
// the frames after): each one's GL layers, crop and compressed texture, which the model crops and
// compresses itself and compares with GL's, and its closed mesh in the unit cube with its placement
// in the world, for the exact reference. Each frame's LdiClip record (LDIC) gives the reader, the
// uniforms GL used (view_proj, one window-to-texel matrix a volume), which draws are tested and how,
// and GL's answers: per draw the fragments discarded, the texels fetched and two sums of a hash of
// each discarded fragment (shaders/ldi/clip.frag), and the final depth buffer's CRC-32.
//
// The test point: T = (M (x + 0.5, y + 0.5, z, 1)) with M the volume's window_to_texel, z the
// fragment's gl_FragCoord.z, then T.xyz / T.w, in float, each product and sum rounded as the shader
// writes them (no fused multiply-add). Outside the crop (NaN included): outside with no fetch.
// Inside: the draw's reader (vpt.h) at texel (int(T.x), int(T.y)) and depth T.z. Volumes are tested
// in order until one holds the point.
//
// The reference: the fragment's point from the same window coordinates through the double inverse
// of view_proj (clip control NEGATIVE_ONE_TO_ONE), mapped into each volume's unit cube, classified by
// the mesh exactly (model/mesh/crossings.h, double precision); a point within epsilon (unit-cube
// units) of a volume's surface is counted apart, never classified.
//
// Texel cache: every fetch is a read of a modelled texel cache (memory::LineCache) in an address
// space where each volume has its cropped layers (4 bytes a texel, layer-major) and its compressed
// texture (8 bytes a texel) at 4 KiB-aligned bases, volumes in order; misses are the memory traffic.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "model/common/depth.h"
#include "model/ldi/compression.h"
#include "model/ldi/ldi.h"
#include "model/memory/memory.h"
#include "model/mesh/crossings.h"
#include "model/mesh/mesh.h"
#include "model/raster/raster_path.h"
#include "model/scene/frame.h"

namespace nbsim::ldi {

inline constexpr int kMaxClipVolumes = 4;
inline constexpr std::uint32_t kLdiVolumeRecordType = 0x5649444Cu;  // fourcc "LDIV" (traces/format/ldi/ldi_chunk.h)
inline constexpr std::uint32_t kLdiClipRecordType = 0x4349444Cu;    // fourcc "LDIC"

// The reader the shader runs (LDIC `reader`; fixed values: they are in files).
enum class ClipReader : std::uint8_t { Layers = 0, All = 1, Ranges = 2 };
inline constexpr std::array<const char*, 3> kClipReaderNames = {"layers", "all", "ranges"};
std::optional<ClipReader> parse_clip_reader(const std::string& name);

// The hash of a discarded fragment in LDIC's sums (the shader's mix_bits twin).
constexpr std::uint32_t mix_bits(std::uint32_t x) noexcept {
  x ^= x >> 16;
  x *= 0x85ebca6bu;
  x ^= x >> 13;
  x *= 0xc2b2ae35u;
  x ^= x >> 16;
  return x;
}

// CRC-32 (zlib) of a depth buffer's float bits: LDIC's depth_crc.
std::uint32_t depth_crc(const std::vector<float>& texels);

struct ClipVolume {
  std::string shape;
  std::array<double, 3> center{};  // the unit cube's centre in the world
  double size = 1.0;               // its side: world = center + size (p - 0.5)
  mesh::TriMesh mesh;              // closed, in the unit cube
  Ldi layers{1, 1, 0, {}};         // GL's LDI
  CroppedLdi cropped;              // the model's crop of it
  CompressedLdi compressed;        // the model's compression of it
  std::shared_ptr<const mesh::CrossingReference> reference;  // along +z of the unit cube
  std::uint64_t layers_base = 0, compressed_base = 0;        // byte addresses of the texel cache's space
};

// One draw's counts (the model's, GL's beside).
struct ClipDrawCounts {
  std::uint32_t draw = 0;
  bool tested = false;  // an LDIC draw (the others ran plain)
  bool keep_inside = false;
  raster::DrawCounters path;       // the model's raster counters (fragments, depth tests, passed, ...)
  std::uint64_t gl_fragments = 0, gl_samples = 0;
  std::uint64_t tests = 0;          // fragments tested (= fragments)
  std::uint64_t volume_tests = 0;   // (fragment, volume) tests run
  std::uint64_t discarded = 0, gl_discarded = 0;
  std::uint64_t fetches = 0, gl_fetches = 0;
  std::uint32_t hash_a = 0, hash_b = 0, gl_hash_a = 0, gl_hash_b = 0;
  std::uint64_t cache_hits = 0, cache_misses = 0;
  // Against the exact reference.
  std::uint64_t classified = 0, near_surface = 0, misclassified = 0;
  bool mismatch() const noexcept;  // any of fragments, samples, discarded, fetches or the sums unlike GL's
};

struct ClipFrameCounts {
  ClipReader reader = ClipReader::All;
  std::vector<ClipDrawCounts> draws;
  std::uint64_t draw_mismatches = 0;      // draws whose counts differ from GL's (expected 0)
  std::uint64_t decision_mismatches = 0;  // draws whose discarded fragments differ from GL's (count or sums; expected 0)
  bool depth_mismatch = false;            // the final depth buffer's CRC-32 differs from GL's
  std::uint64_t volumes_loaded = 0;       // LDIV records this frame
  std::uint64_t volume_mismatches = 0;    // of those, volumes whose GL crop or compressed texture differ from the model's
  // What the three readers would fetch for the frame's tests (every reader run beside the draw's).
  std::array<std::uint64_t, 3> reader_fetches{};
};

// The clip replay: a viewport-sized depth buffer and raster path, the volumes, the texel cache.
class ClipReplay {
 public:
  ClipReplay(bool fused_interpolation, const memory::CacheConfig& cache);
  ~ClipReplay();
  ClipReplay(const ClipReplay&) = delete;
  ClipReplay& operator=(const ClipReplay&) = delete;

  // True when the frame has an LDIC record (a clipping or lens frame).
  static bool is_clip_frame(const scene::Frame& f);
  // Loads the frame's LDIV records (volumes), then replays its draws: the LDIC draws with the
  // volume test, the others plain, every one against GL's counters; InputError for a damaged record
  // (naming it), a draw the record names that does not exist, or a frame before any volume.
  ClipFrameCounts run_frame(const scene::Frame& f);

  const std::vector<ClipVolume>& volumes() const noexcept { return volumes_; }
  std::uint64_t cache_line_bytes() const noexcept;

 private:
  class VolumeTest;
  bool fused_;
  memory::CacheConfig cache_config_;
  std::unique_ptr<memory::LineCache> cache_;
  std::vector<ClipVolume> volumes_;
  int width_ = 0, height_ = 0;
  std::unique_ptr<DepthImage> depth_;
  std::unique_ptr<raster::RasterPath> path_;
};

}  // namespace nbsim::ldi
