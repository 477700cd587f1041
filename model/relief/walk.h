// The relief ray walks of one box fragment in float, operation for operation as the capture's
// fragment shader runs them (shaders/relief/relief.frag: every expression there is `precise`, and
// this file is built with -ffp-contract=off), so that the model's hits, lookups and steps equal
// GL's bit for bit. heightfield.h states the conventions (texel space, cells, the zero border).
//
// The fragment's ray: origin o = the eye in texel space; direction d = (a * px + b * py) + c with
// (px, py) the fragment's pixel centre in window coordinates (gl_FragCoord.xy) and a, b, c the
// draw's ray frame (a perspective camera's rays are affine in the pixel centre). No varying is
// interpolated, so nothing depends on the rasterizer's attribute setup. The box [0, N]^2 x [0, 1]
// clips the ray to [t_in, t_out] (slabs; t_in >= 0); a ray that misses the box is a miss with no
// lookups.
//
// Methods (Baboud & Decoret section 4, and the N-buffer paper's future work):
// - binary: `linear_steps` equal steps from t_in to t_out until a point is below the surface, then
//   `binary_steps` bisections; the hit is the bracket's lower (below) end. Wrong at grazing angles,
//   across depth discontinuities and on thin peaks (a step jumps over them).
// - exact: the cell walk from texel centreline to centreline (Amanatides-Woo over cells); in each
//   cell the height above the surface at the cell's entry and exit, a hit when it is <= 0 at the
//   entry or the exit, refined by `root_steps` bisections inside the cell. Misses a bilinear
//   saddle the ray dips under and leaves within one cell (their Figure 3).
// - robust: steps of the texel's safety radius (radius.h) with a bisection when a step ends below;
//   where the radius is 0 (peaks), up to two cell steps of the full cell test (below).
// - robust_clamp: the same, with a radius of 0 clamped to 1 (cheaper; a peak may be stepped over).
// - nbuffer: empty-space skipping with the max N-buffer of the heightfield: from t, a span of 2^s
//   texels of horizontal travel is skipped when the ray's lower end is above the N-buffer's
//   maximum over the texels the span's surface depends on (one query of at most four lookups,
//   covered as WalkParams::covering says, model/nbuffer/covering.h); s grows by one after a skip and shrinks by one after a failed query; at
//   s = 0 a failed query walks one cell with the full cell test. The full cell test is the exact
//   walk's plus the dip: where the height above the surface is convex along the ray inside the
//   cell, its minimum (the vertex of the quadratic through the entry, the middle and the exit) is
//   tested too. So the N-buffer walk finds saddles the exact walk misses.
// A ray that leaves through the box's floor and found no hit before hits at t_out (FragmentRay).
// Lookups count every texel read the shader issues: 4 per surface height (binary, robust), 4 per
// cell (its corners; exact, nbuffer, robust's cell steps), 1 per radius, 1 to 4 per N-buffer query
// (the covering's distinct texels).
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "model/nbuffer/covering.h"

namespace nbsim::relief {

// Fixed values (they are in files: RLFF's `method`).
enum class Method : std::uint8_t { Binary = 0, Exact = 1, Robust = 2, RobustClamp = 3, NBuffer = 4 };
inline constexpr int kMethods = 5;
std::string_view to_string(Method m) noexcept;

// The bytes of the textures method `m` reads for an N x N heightfield with an N-buffer of `levels`
// levels, 4 a texel (R32F, as the capture's textures): heights for every method, plus the safety
// radii (robust, robust_clamp) or every N-buffer level (nbuffer). (The paper also stores a normal a
// texel for shading, which no walk reads: 5 floats with the radius.)
std::uint64_t storage_bytes(Method m, int size, int levels) noexcept;
std::optional<Method> parse_method(std::string_view s) noexcept;
inline constexpr std::array<Method, kMethods> kAllMethods = {Method::Binary, Method::Exact, Method::Robust, Method::RobustClamp,
                                                             Method::NBuffer};

// The tunables of the walks (the capture records them; the shader receives them as uniforms).
struct WalkParams {
  int linear_steps = 16;  // binary: 1 to 1024
  int binary_steps = 8;   // binary and robust: bisections after the bracket, 0 to 32
  int root_steps = 16;    // exact, nbuffer and robust's cell steps: bisections inside a cell, 0 to 32
  CoveringSpec covering;  // nbuffer: how a span's texel rectangle is covered (the capture's, its header's nbuffer_covering)
};

// The draw's ray frame (float, as the shader's uniforms).
// A box: origin o = `origin`, direction d = (a * px + b * py) + c.
// A reverse-perspective frustum (`frustum`): texel space is the frustum's projective image (the
// frustum -> box map F, homogeneous), where rays stay straight lines. The fragment's near-plane point
// in F's homogeneous coordinates is Q = (qa * px + qb * py) + qc and the eye's is E = eye_h; the ray
// starts at o = Q.xyz / Q.w and runs along d = E.w * Q.xyz - Q.w * E.xyz (the derivative of the
// image of q + s (q - eye) at s = 0, scaled by Q.w^2 > 0: forward whatever E.w's sign). Nothing
// divides by E.w, so an eye on or near F's w = 0 plane (the apex's plane, where the eye's image
// goes to infinity and every ray becomes parallel) needs no special case.
struct RayFrame {
  std::array<float, 3> origin{};  // the eye, texel space (a box)
  std::array<float, 3> a{}, b{}, c{};  // direction = (a * px + b * py) + c (a box)
  bool frustum = false;
  std::array<float, 4> eye_h{};         // E (a frustum)
  std::array<float, 4> qa{}, qb{}, qc{};  // Q = (qa * px + qb * py) + qc (a frustum)
};

// What the shader reads. Levels: `levels` planes of N * N (N-buffer, max), level-major.
struct FieldView {
  int size = 0;
  std::span<const float> heights;  // N * N
  std::span<const float> radius;   // N * N (robust methods), else may be empty
  std::span<const float> nbuffer;  // levels * N * N (nbuffer), else may be empty
  int levels = 0;
};

struct WalkResult {
  bool hit = false;
  float t = 0.0f;  // the hit's ray parameter (0 on a miss)
  std::uint32_t lookups = 0, steps = 0, bisections = 0;
  bool capped = false;  // the iteration cap ended the walk (counted a miss); never expected
};

// The texture a lookup reads (for the model's texel cache).
enum class Texture : std::uint8_t { Height = 0, Radius = 1, NBuffer = 2 };
// Called once per texel read, with the texture and the texel's index in it (virtual border texels
// are reads too: index -1, served without memory).
using LookupObserver = void (*)(void* context, Texture texture, std::int64_t index);

// The texel cache's address space (model/relief/unit.h): the heights, the radii and the N-buffer
// levels 2^34 bytes apart, 4 bytes a texel.
constexpr std::uint64_t texel_address(Texture texture, std::int64_t index) noexcept {
  return (static_cast<std::uint64_t>(texture) << 34) + 4 * static_cast<std::uint64_t>(index);
}

// The texel cache as a record of lookups needs to know it (model/memory LineCache's sets).
struct LineGeometry {
  int line_shift = 6;      // line = texel_address >> line_shift
  std::uint64_t sets = 0;  // set = line % sets (0: no sets, every lookup misses)
  bool merge = true;       // merge the lookups known to hit (false: a cache of 0 bytes, where none hits)
};

// The lookups of walks run one after another, recorded as the texel cache will see them, so that
// walks can run apart from the cache (on other threads) and the cache be fed later in the same
// order: each read of a texel in memory as its cache line (virtual border texels need no memory and
// are left out). With `merge`, a lookup of the line its set saw last in this record is not recorded
// but counted in `repeats`: in an LRU cache that access is a hit that changes nothing (the line is
// its set's most recently used), whatever came before the record, so the cache need not see it.
// Most of a walk's lookups are such (the four corners of a cell are two lines, read again by the
// next cell), so the cache, which must see the rest in order on one thread, has little left to do.
// (With no sets, a set count that is not a power of two or a huge cache, only a repeat of the line
// just before is merged, as it always hits.) Lookups are added through a Writer. Aligned to a
// cache line of the host: the records of runs walked at once on different threads sit side by side
// in the replay's vector, and sharing a line would bounce it between the cores at every lookup.
class alignas(64) LookupLines {
 public:
  // Empties the record and sets how the lines are taken.
  void reset(const LineGeometry& g) {
    line_shift_ = g.line_shift;
    merge_ = g.merge;
    // A huge cache's table would cost more to clear for every record than it saves, and a set count
    // that is not a power of two would cost a division a lookup: one entry then (the line just
    // before, always its set's most recently used).
    const bool table = g.sets > 0 && g.sets <= kMaxTable && (g.sets & (g.sets - 1)) == 0;
    set_mask_ = table ? static_cast<std::uint32_t>(g.sets - 1) : 0;
    last_.assign(set_mask_ + 1, kNone);
    size_ = 0;
    lookups_ = 0;
    borders_ = 0;
  }

  // Adds lookups to a record. While a writer is open on a record, its state is the writer's (held
  // in registers in a walk's loop rather than in the record's members, which every stored line
  // might alias), and nothing else may add to the record; the record is whole again once the writer
  // has gone.
  class Writer {
   public:
    explicit Writer(LookupLines& lines) noexcept : lines_(lines) { open(); }
    ~Writer() { close(); }
    Writer(const Writer&) = delete;
    Writer& operator=(const Writer&) = delete;

    // A lookup of a texel in memory (by its address). A merged one is not counted (a counter
    // bumped at nearly every lookup would chain the walk's lookups one after another): repeats() is
    // what the walks' lookups leave over.
    [[gnu::always_inline]] void add(std::uint64_t address) { put(address >> shift_); }
    // add(a) then add(b), for two texels side by side: when they share a line (15 times in 16 for
    // 64-byte lines), the second is the repeat add() would find, merged without the table.
    [[gnu::always_inline]] void add_pair(std::uint64_t a, std::uint64_t b) {
      const std::uint64_t la = a >> shift_, lb = b >> shift_;
      put(la);
      if (!merge_ || lb != la) put(lb);
    }
    // A lookup of a virtual border texel (no memory, nothing recorded).
    void add_border() noexcept { ++lines_.borders_; }
    // A walk's lookups (WalkResult::lookups: in memory or on the border), told once it has ended.
    void add_lookups(std::uint64_t n) noexcept { lines_.lookups_ += n; }

   private:
    // Without a branch on the merge (whether a line repeats its set's last follows the walk's path
    // across lines, which a branch predictor cannot guess): the line is always written to the next
    // slot, and the slot kept only when the line is not a repeat.
    [[gnu::always_inline]] void put(std::uint64_t line) {
      if (out_ == end_) grow();
      *out_ = line;
      if (merge_) {
        std::uint64_t& last = last_[line & mask_];
        out_ += line != last ? 1 : 0;
        last = line;
      } else {
        ++out_;
      }
    }
    // The storage is kept at its full size (size_ counts what is used), so a record reused for the
    // next run neither frees nor clears it.
    [[gnu::noinline]] void grow() {
      close();
      lines_.storage_.resize(std::max<std::size_t>(4096, 2 * lines_.storage_.size()));
      open();
    }
    void open() noexcept {
      out_ = lines_.storage_.data() + lines_.size_;
      end_ = lines_.storage_.data() + lines_.storage_.size();
      last_ = lines_.last_.data();
      mask_ = lines_.set_mask_;
      shift_ = lines_.line_shift_;
      merge_ = lines_.merge_;
    }
    void close() noexcept { lines_.size_ = static_cast<std::size_t>(out_ - lines_.storage_.data()); }

    LookupLines& lines_;
    // None of the types a stored line (std::uint64_t) could alias.
    std::uint64_t* out_ = nullptr;
    std::uint64_t* end_ = nullptr;
    std::uint64_t* last_ = nullptr;
    std::uint32_t mask_ = 0;
    int shift_ = 0;
    bool merge_ = true;
  };

  std::span<const std::uint64_t> lines() const noexcept { return {storage_.data(), size_}; }
  // How lookups are taken (reset()'s geometry): line = address >> line_shift(); with merges(), a
  // line repeating the last of its set (line & set_mask(); 0: one entry for every line) is merged.
  int line_shift() const noexcept { return line_shift_; }
  bool merges() const noexcept { return merge_; }
  std::uint32_t set_mask() const noexcept { return set_mask_; }
  // The merged lookups: every lookup of a texel in memory but those recorded.
  std::uint64_t repeats() const noexcept { return lookups_ - borders_ - size_; }
  // Marks the N-buffer level texels the walks read, one byte a texel of FieldView::nbuffer (null:
  // none marked), for the replay's on-demand N-buffer: which texels a build on demand computes.
  // The marks are the walking thread's own (threads sharing them would take their lines from each
  // other at every first read) and outlive the record; a texel first marked while this record was
  // taken is also listed in level_texels() (emptied here), so that the record's reader can compute
  // it on demand while later runs are walked.
  void mark_levels(std::uint8_t* marks) noexcept {
    level_marks_ = marks;
    level_texels_.clear();
  }
  void add_level_texel(std::int64_t index) {
    if (level_marks_ && !level_marks_[index]) {
      level_marks_[index] = 1;
      level_texels_.push_back(static_cast<std::uint32_t>(index));
    }
  }
  std::span<const std::uint32_t> level_texels() const noexcept { return level_texels_; }

 private:
  static constexpr std::uint64_t kNone = ~std::uint64_t{0};  // no line (addresses are multiples of 4)
  static constexpr std::uint64_t kMaxTable = 4096;
  int line_shift_ = 6;
  bool merge_ = true;
  std::uint32_t set_mask_ = 0;
  std::vector<std::uint64_t> last_ = {kNone};  // per set, the line it saw last
  std::vector<std::uint64_t> storage_;
  std::size_t size_ = 0;
  std::uint64_t lookups_ = 0, borders_ = 0;
  std::uint8_t* level_marks_ = nullptr;
  std::vector<std::uint32_t> level_texels_;
};

// The ray of pixel centre (px, py) clipped to the box: false when it misses the box.
struct FragmentRay {
  std::array<float, 3> o{}, d{};
  float t_in = 0.0f, t_out = 0.0f;
  // The ray leaves the box through its floor (z = 0): the floor is the closed surface's bottom, so a
  // walk that finds nothing before t_out hits there (every method; the twin of a height-0 floor that
  // float rounding would leave a hair above the ray's end).
  bool floor_exit = false;
};
std::optional<FragmentRay> fragment_ray(const RayFrame& frame, int size, float px, float py);

// One fragment's walk with `method`. `observer` (may be null) sees every lookup.
WalkResult walk(Method method, const FieldView& field, const WalkParams& params, const FragmentRay& ray,
                LookupObserver observer = nullptr, void* context = nullptr);
// The same walk (the same result, bit for bit), its lookups appended to `lines`.
WalkResult walk(Method method, const FieldView& field, const WalkParams& params, const FragmentRay& ray, LookupLines& lines);

// The walks of a run of fragments with one method, one after another: out[k] is walk(method, field,
// params, *rays[k], ...) and `lines` (may be null) receives every walk's lookups in the order of k,
// the same records bit for bit. When the CPU has AVX2 and `lanes` is not None, the rays walk eight
// at once in lanes (each lane takes the run's next ray when its walk ends; the texels each walk read
// are logged and recorded after the run, ray by ray): every method, the N-buffer walk with the
// paper's covering (top alignment, no direct squares) only. The hits found inside a cell (exact,
// robust and N-buffer walks) are refined together, eight at a time (the refinement reads no texel).
// Otherwise the rays walk one by one. `lanes` is the instruction set of the lanes, or the best below
// it that the CPU has: AVX2, or AVX-512 (the same 256-bit operations, which the compiler encodes with
// twice the registers and masked gathers).
enum class LaneSet : std::uint8_t { None, Avx2, Avx512 };
bool lane_set_available(LaneSet set) noexcept;
LaneSet best_lane_set() noexcept;  // the best the CPU has
void walk_each(Method method, const FieldView& field, const WalkParams& params, std::span<const FragmentRay* const> rays,
               std::span<WalkResult> out, LookupLines* lines, LaneSet lanes = best_lane_set());

// The iteration cap of every walk's main loop (a walk that reaches it is a capped miss).
int walk_iteration_cap(int size) noexcept;

}  // namespace nbsim::relief
