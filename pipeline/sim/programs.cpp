// The frame-program and structure-instance tables; see programs.h.
#include "pipeline/sim/programs.h"

#include <fmt/format.h>

#include <array>
#include <fstream>
#include <string>

#include "model/common/error.h"
#include "pipeline/sim/gpu.h"

namespace nbsim::pipeline {

namespace {

// Occlusion culling (the N-buffer paper, 3.1/4.2): cull.mode picks the query; "trace" replays.
Program occlusion_culling(const ProgramContext& c) {
  Program p;
  c.config.cull.parsed_granularity();  // refuses cull.granularity=primitive with nothing to test against
  if (c.config.cull.parsed_mode() == cull::CullMode::Trace) return p;
  // The mode's query structure: the N-buffer unit, or the Hi-Z baselines.
  if (const std::optional<query::Kind> kind = c.config.cull.structure_kind())
    p.structures.push_back(c.structure(*kind == query::Kind::NBuffer ? "nbuffer" : "hiz", *kind, c.setup.op));
  auto unit = std::make_unique<cull::CullUnit>("cull", c.registry, c.config.cull, c.setup, c.depth_buffer,
                                               p.structures.empty() ? nullptr : p.structures.front().get());
  if (c.out) {  // every bounds test with its decision, cost and ground truth
    auto log = std::make_unique<std::ofstream>(*c.out / "culls.csv");
    if (!*log) throw InputError(fmt::format("cannot write into '{}'", c.out->string()));
    unit->set_test_log(log.get());
    p.logs.push_back(std::move(log));
  }
  p.frames = unit.get();
  p.depth_listener = unit.get();
  if (unit->granularity() == cull::Granularity::Primitive) p.primitive_tester = unit.get();
  p.unit = std::move(unit);
  return p;
}

// A technique with its own culling refuses occlusion culling's cull.mode (`how`: what it culls with).
void require_no_cull_mode(const ProgramContext& c, std::string_view how) {
  if (c.config.cull.parsed_mode() != cull::CullMode::Trace)
    throw InputError(fmt::format("cull.mode={} is occlusion culling's; {} (leave cull.mode at trace)", c.config.cull.mode, how));
  c.config.cull.parsed_granularity();
}

// Point-sprite particles (the N-buffer paper, 3.2/4.3): the trace's particle_mode is the test; the
// N-buffer instance "nbuffer" (mode nb) is built up to the capture's top level (levels_built - 1)
// unless nbuffer.level_cap sets another; mode hiz reads the "hiz" instance's format and timing.
Program particles(const ProgramContext& c) {
  require_no_cull_mode(c, "a particles trace culls with its own particle_mode");
  particles::ParticlesSetup s;
  s.width_px = c.setup.width_px;
  s.height_px = c.setup.height_px;
  s.op = c.setup.op;
  s.depth_func = c.setup.depth_func;
  // The header's particle keys were checked against their declarations when the trace was opened
  // (traces/format/particles/particles_chunk.cpp): the mode is a known one, the levels 0 .. 31.
  s.mode = *particles::parse_mode(c.header.text("particle_mode"));
  s.top_level = static_cast<int>(c.header.whole("levels_built")) - 1;
  s.margin = static_cast<float>(c.header.real("cull_margin"));
  if (c.config.particles.mode != "trace") {
    // Another test than the capture's: the levels it builds follow from the capture's sprite sizes
    // and level cap, as the capture computes them for that mode.
    const auto other = particles::parse_mode(c.config.particles.mode);
    if (!other) throw InputError(fmt::format("particles.mode '{}' is not one of trace, none, center, nb, hiz", c.config.particles.mode));
    const std::string& sprite = c.header.text("sprite");
    const int largest = sprite == "atten" ? static_cast<int>(particles::kMaxAttenuatedPx) : static_cast<int>(c.header.whole("sprite"));
    const int level_cap = static_cast<int>(c.header.whole("level_cap"));
    if (*other != s.mode) s.top_level = particles::top_level_needed(*other, largest, level_cap);
    s.mode = *other;
  }
  Program p;
  const HiZUnitConfig* hiz = nullptr;
  if (s.mode == particles::Mode::NBuffer) {
    nbuffer::NBufferUnitConfig nb = c.nbuffer_config("nbuffer");
    if (nb.level_cap < 0) nb.level_cap = s.top_level;  // the partial build the capture made
    nb.direct_squares = true;  // a power-of-two sprite is one lookup (the paper's direct covering, 3.2)
    s.top_level = nb.level_cap;
    p.structures.push_back(std::make_unique<query::NBufferStructure>("nbuffer", c.registry, nb, c.setup.width_px,
                                                                     c.setup.height_px, c.setup.op, &c.memory));
  } else if (s.mode == particles::Mode::HiZ) {
    hiz = &c.config.hiz.at("hiz");
  }
  auto unit = std::make_unique<particles::ParticlesUnit>("particles", c.registry, c.config.particles, s, c.depth_buffer,
                                                         p.structures.empty() ? nullptr : p.structures.front().get(), hiz);
  p.frames = unit.get();
  p.depth_listener = unit.get();
  p.unit = std::move(unit);
  return p;
}

// Shadow volumes with litmaps (the N-buffer paper, 3.3/4.4): the trace's shadow_mode drew the
// volumes; the min and max N-buffer instances "litmap_min" and "litmap_max" are built over the
// litmaps (litmap_size square) and queried per caster, and the model's stencil gives the mask.
Program shadows(const ProgramContext& c) {
  require_no_cull_mode(c, "a shadows trace culls its casters with the litmaps");
  shadows::ShadowsSetup s;
  s.width_px = c.setup.width_px;
  s.height_px = c.setup.height_px;
  // The header's shadows keys were checked against their declarations when the trace was opened
  // (traces/format/shadows/shadows_chunk.cpp).
  s.mode = *shadows::parse_mode(c.header.text("shadow_mode"));
  s.litmap_size = static_cast<int>(c.header.whole("litmap_size"));
  s.margin = *shadows::parse_clamp_margin(c.header.text("clamp_margin"));
  Program p;
  const auto nbuffer = [&](const char* instance, FarOp op) {
    return std::make_unique<query::NBufferStructure>(instance, c.registry, c.nbuffer_config(instance), s.litmap_size,
                                                     s.litmap_size, op, &c.memory);
  };
  auto min_nb = nbuffer("litmap_min", FarOp::Min);
  auto max_nb = nbuffer("litmap_max", FarOp::Max);
  auto unit = std::make_unique<shadows::ShadowsUnit>("shadows", c.registry, c.config.shadows, s, c.stencil_buffer, *min_nb, *max_nb);
  p.structures.push_back(std::move(min_nb));
  p.structures.push_back(std::move(max_nb));
  p.frames = unit.get();
  p.depth_listener = unit.get();
  p.unit = std::move(unit);
  return p;
}

// Layered depth images (Trapp & Doellner): the peel replayed at the LDI's size (LDIL) with its own
// depth buffer and the strict compare against the previous layer, the model's LDI cropped and
// compressed and compared with GL's, and the parity test at GL's test points (LDIT).
Program ldi(const ProgramContext& c) {
  require_no_cull_mode(c, "an ldi trace peels and tests its own shape");
  Program p;
  auto unit = std::make_unique<ldi::LdiUnit>("ldi", c.registry, c.config.ldi, c.memory, c.config.depth.fused_interpolation);
  p.frames = unit.get();
  p.unit = std::move(unit);
  return p;
}

// Relief textures (Baboud & Decoret) and the N-buffer walk: every relief_box draw rasterized with the
// early depth test, each fragment's walk run with the draw's method and compared with GL's, and
// scored against the exact reference.
Program relief(const ProgramContext& c) {
  require_no_cull_mode(c, "a relief trace walks its own rays");
  const double box_height = c.header.real("relief_box_height");  // above 0: checked when the trace was opened
  Program p;
  // The N-buffer walk covers as the capture did (its GL walks are compared one by one).
  auto unit = std::make_unique<relief::ReliefUnit>("relief", c.registry, c.config.relief, c.memory, c.setup.width_px, c.setup.height_px,
                                                   box_height, c.config.depth.fused_interpolation, c.capture_covering());
  p.frames = unit.get();
  p.unit = std::move(unit);
  return p;
}

constexpr std::array<ProgramRow, 5> kPrograms = {{
    {"occlusion_culling",
     "occlusion culling of a scene's objects (cull.mode: trace replays the recorded draws; none, oq, oq_hier, nb, "
     "nb_hier, hiz_tile, hiz_pyramid cull every candidate again)",
     occlusion_culling},
    {"particles",
     "point-sprite particles culled in the vertex stage (the trace's particle_mode: none, center, nb, hiz), each "
     "decision made again by the model and compared with GL's; GL's particle draws rasterized",
     particles},
    {"shadows",
     "shadow volumes culled and clamped with min/max litmaps (the trace's shadow_mode): GL's scene and volume draws "
     "rasterized with the stencil test, a min and a max N-buffer built over GL's litmaps and queried per caster, the "
     "decisions and the shadow mask compared with GL's",
     shadows},
    {"ldi",
     "layered depth images and the volumetric parity test: GL's peel passes replayed at the LDI's size with the strict "
     "compare against the previous layer, the model's LDI, crop and compressed texture compared with GL's, and the parity "
     "test (uncompressed and compressed) at GL's test points against GL's answers and the exact reference",
     ldi},
    {"relief",
     "relief textures: every relief_box draw rasterized with the early depth test, each fragment's ray walk (binary, "
     "exact, robust, robust_clamp or nbuffer, as the draw's RLFF says) run through the ray-walk unit and its texel cache, "
     "compared with GL's per fragment and scored against the exact reference",
     relief},
}};

constexpr std::array<StructureInstance, 4> kInstances = {{
    {"nbuffer", InstanceKind::NBuffer,
     "occlusion culling's N-buffer unit (cull.mode nb, nb_hier); the particles' max N-buffer (particle_mode nb, level_cap -1: "
     "the capture's levels)"},
    {"hiz", InstanceKind::HiZ,
     "occlusion culling's Hi-Z baselines (cull.mode hiz_tile, hiz_pyramid); the particles' Hi-Z pyramid format and timing "
     "(particle_mode hiz)"},
    {"litmap_min", InstanceKind::NBuffer,
     "shadows: the min N-buffer over the min litmap (litmap_size square), queried for each caster's z_min"},
    {"litmap_max", InstanceKind::NBuffer,
     "shadows: the max N-buffer over the max litmap (litmap_size square), queried for each caster's z_max"},
}};

std::string technique_list() {
  std::string s;
  for (const ProgramRow& r : kPrograms)
    if (r.build) s += (s.empty() ? "" : ", ") + std::string(r.technique);
  return s;
}

}  // namespace

std::span<const ProgramRow> program_table() { return kPrograms; }
std::span<const StructureInstance> structure_instances() { return kInstances; }

std::unique_ptr<query::Structure> ProgramContext::structure(std::string_view instance, query::Kind kind, FarOp op) const {
  const std::string name(instance);
  const int w = setup.width_px, h = setup.height_px;
  const auto nb = config.nbuffers.find(instance);
  if (nb != config.nbuffers.end() && kind == query::Kind::NBuffer)
    return std::make_unique<query::NBufferStructure>(name.c_str(), registry, nbuffer_config(instance), w, h, op, &memory);
  const auto hiz = config.hiz.find(instance);
  if (hiz != config.hiz.end() && kind == query::Kind::TileHiZ)
    return std::make_unique<query::TileHiZUnit>(name.c_str(), registry, hiz->second, w, h, op);
  if (hiz != config.hiz.end() && kind == query::Kind::HiZPyramid)
    return std::make_unique<query::HiZPyramidUnit>(name.c_str(), registry, hiz->second, op);
  throw InputError(fmt::format("no query structure instance '{}' of kind {}", instance, query::to_string(kind)));
}

CoveringSpec ProgramContext::capture_covering() const {
  return header.covering.value_or(CoveringSpec{CoveringKind::Corners, CoveringAlign::Bottom});
}

nbuffer::NBufferUnitConfig ProgramContext::nbuffer_config(std::string_view instance) const {
  nbuffer::NBufferUnitConfig nb = config.nbuffers.at(std::string(instance));
  nb.validate();
  const CoveringSpec spec = nb.covering_spec(capture_covering());
  nb.covering = std::string(to_string(spec.kind));
  nb.align = std::string(to_string(spec.align));
  return nb;
}

Program build_program(std::string_view technique, const ProgramContext& context) {
  if (context.config.program == "off") {
    if (context.config.cull.parsed_mode() != cull::CullMode::Trace)
      throw InputError(fmt::format("gpu.program=off runs no program, but cull.mode={} asks a program to cull "
                                   "(leave cull.mode at trace, or gpu.program at auto)",
                                   context.config.cull.mode));
    return {};
  }
  for (const ProgramRow& r : kPrograms) {
    if (r.technique != technique) continue;
    if (!r.build)
      throw InputError(fmt::format("no model program for technique '{}' yet: its traces can be read (nbsim trace info, "
                                   "dump) but not replayed (programs exist for: {})",
                                   technique, technique_list()));
    return r.build(context);
  }
  if (context.config.cull.parsed_mode() != cull::CullMode::Trace)
    throw InputError(fmt::format(
        "cull.mode={} culls with occlusion culling's program, but the trace's technique is '{}' (programs exist for: "
        "{}); cull.mode=trace replays the recorded draws of any technique",
        context.config.cull.mode, technique.empty() ? "(none)" : std::string(technique), technique_list()));
  context.config.cull.parsed_granularity();
  return {};
}

}  // namespace nbsim::pipeline
