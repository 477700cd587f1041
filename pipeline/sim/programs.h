// The frame programs that replay a technique's traces, one row per technique, chosen by the name
// the trace header carries ("technique"), and the query-structure instances a program may own.
// A technique's program is a row defined in its own folder (pipeline/techniques/<name>/program.cpp)
// for the technique's entry in the registration list; the top level (gpu.h) only wires what a row
// builds.
#pragma once

#include <any>
#include <filesystem>
#include <memory>
#include <ostream>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "model/config/schema.h"
#include "model/cp/unit.h"
#include "model/cull/unit.h"
#include "model/depth/unit.h"
#include "model/memory/memory.h"
#include "model/query/units.h"
#include "model/raster/primitive_tester.h"
#include "nbsim/technique_list.h"
#include "traces/format/header.h"

namespace nbsim::pipeline {

struct GpuConfig;

// The trace as every program sees it, from its header and scene record.
struct TraceView {
  int width_px = 0, height_px = 0;                        // the viewport
  FarOp op = FarOp::Max;                                  // farthest: Max, or Min under reversed Z
  scene::DepthFunc depth_func = scene::DepthFunc::Less;   // LESS, or GREATER under reversed Z
  const scene::SceneObjects* scene = nullptr;             // the scene record (null: the trace has none)
};

// What a program's factory gets from the top level. Units it builds become children of the top
// level's module (they are built during its elaboration).
struct ProgramContext {
  stats::Registry& registry;
  const GpuConfig& config;
  const trace::Header& header;     // the trace's, checked when it was opened: a program reads its technique's keys typed
  const TraceView& view;           // the trace's viewport, depth convention and scene
  const DepthImage& depth_buffer;  // the depth unit's
  const raster::StencilImage& stencil_buffer;  // the depth unit's (8-bit, y up; cleared to 0 at each frame's start)
  memory::Channel& memory;
  const std::filesystem::path* out = nullptr;  // the run's output folder, for a program's own logs (null: none)

  // Builds the query structure `instance` (a name of structure_instances(), whose config keys it
  // reads) of `kind` over the viewport, farthest by `op`. Throws InputError for an unknown instance.
  std::unique_ptr<query::Structure> structure(std::string_view instance, query::Kind kind, FarOp op) const;
  // The config of N-buffer instance `instance` with a covering or alignment of "trace" made the
  // capture's (the header's nbuffer_covering, e.g. "paper/top"; corners/bottom when the header has
  // none). Throws InputError for a header value that is not a covering.
  nbuffer::NBufferUnitConfig nbuffer_config(std::string_view instance) const;
  // The covering of the capture's GL queries: the header's nbuffer_covering, corners/bottom when it
  // has none.
  CoveringSpec capture_covering() const;
  // For a technique that culls in its own way: refuses a cull.mode other than trace (the cull
  // stage's setting), saying in `how` what the technique culls with.
  void require_no_cull_mode(std::string_view how) const;
};


// A program as the top level wires it: the frame program for the command processor, and its
// listener on the depth unit and primitive tester in the raster unit when it has them.
struct Program {
  std::vector<std::unique_ptr<query::Structure>> structures;  // built before the program's unit
  std::unique_ptr<sc_core::sc_module> unit;                   // owns the program
  cp::FrameProgram* frames = nullptr;                         // null: replay the recorded draws
  depth::DepthListener* depth_listener = nullptr;
  raster::PrimitiveTester* primitive_tester = nullptr;
  std::vector<std::unique_ptr<std::ostream>> logs;  // files the program writes into the output folder
};

// A statistic of a group's values (0 when the group has none of that name), for results code.
inline std::uint64_t stat(const nlohmann::ordered_json& group, const char* name) {
  const auto it = group.find(name);
  return it == group.end() ? 0 : static_cast<std::uint64_t>(it->get<double>());
}

// |a - b| / b, 1 when b is 0 and a is not: how far a model counter is from GL's.
inline double relative_error(std::uint64_t a, std::uint64_t b) {
  if (b == 0) return a == 0 ? 0.0 : 1.0;
  const double d = static_cast<double>(a) - static_cast<double>(b);
  return (d < 0 ? -d : d) / static_cast<double>(b);
}
// The most relative_error a replay's counters may have against GL's (fragments, passed samples,
// and what a program compares with GL itself) to be within the thresholds.
inline constexpr double kCounterErrorLimit = 1e-4;

// The value of the header property `key` as written, when the header has it, into j[key].
inline void copy_property(const trace::Header& header, const char* key, nlohmann::ordered_json& j) {
  if (const std::string* v = header.property(key)) j[key] = *v;
}

// What a program's results are made from when its run is done (replay.cpp).
struct SummaryInputs {
  const nlohmann::ordered_json& group;  // the program's statistics group's values
  const nlohmann::ordered_json& stats;  // every unit's ("gpu.memory", ...)
  const GpuConfig& config;
  const trace::Header& header;
  const Program& program;  // its query structures' storage
  std::uint64_t cycles;    // the run's, at its last frame end
  std::uint64_t visible_draws_passed_below_gl;  // drawn visible objects that passed fewer samples than GL's
};

// What a program's statistics become in the replay's outputs: its per-frame values in run.json's
// frames, its totals as summary.<technique> (run.json, `nbsim compare --json`), its own comparison
// with GL in the thresholds, and its lines in `nbsim compare`'s text. Every member is optional.
struct ProgramResults {
  std::string_view group;  // its statistics group ("gpu.<unit>"); no results when the run has none
  std::string_view summary_key;  // its summary's key in run.json's summary ("": the technique's name)
  // Adds its values to the frame's object `pf` (which holds the frame's "depth_tests" already),
  // from the group's statistics at this frame end (`now`) and at the last one (`last`).
  void (*frame_values)(const nlohmann::ordered_json& now, const nlohmann::ordered_json& last, nlohmann::ordered_json& pf) = nullptr;
  // Keys of `pf` (whole numbers) its summary keeps frame by frame: the summary's "per_frame" array
  // of {"frame", these keys, "cycles"}, kept in memory (so few, small values).
  std::span<const char* const> per_frame_keys;
  nlohmann::ordered_json (*summary)(const SummaryInputs& in) = nullptr;
  // Whether what the program itself compares with GL holds (null: nothing beyond the draws').
  bool (*exact)(const nlohmann::ordered_json& summary) = nullptr;
  // `nbsim compare`'s lines for the summary, each ending in a newline (null: none).
  std::string (*describe)(const nlohmann::ordered_json& summary) = nullptr;
};

// A program's own config group (keys "<name>.<field>"), which GpuConfig holds by name without
// knowing its type: the unit config `T` declares its keys (T::describe) and, when it has one, its
// consistency check (T::validate). config_group<T>("name") makes the row's entry.
struct ConfigGroup {
  std::string_view name;  // "" for a program without a group of its own
  std::any (*defaults)() = nullptr;
  void (*describe)(config::Schema& s, std::any& value) = nullptr;
  void (*validate)(const std::any& value) = nullptr;
};

template <class T>
ConfigGroup config_group(std::string_view name) {
  return {name, [] { return std::any(T{}); },
          [](config::Schema& s, std::any& value) { T::describe(s, std::any_cast<T&>(value)); },
          [](const std::any& value) {
            if constexpr (requires(const T& t) { t.validate(); }) std::any_cast<const T&>(value).validate();
          }};
}

// A query-structure instance: its name (also its config keys' prefix: "<name>.<field>", declared
// by GpuConfig::describe), the kind of unit it configures, and what it is for. A program that
// owns several structures of one kind (a min and a max N-buffer) has one row for each.
enum class InstanceKind : std::uint8_t { NBuffer = 0, HiZ = 1 };
struct StructureInstance {
  std::string_view name;
  InstanceKind kind;
  std::string description;
};
struct ProgramRow {
  std::string_view technique;    // the trace header's "technique"
  std::string_view description;  // for --help and messages
  // The program this configuration asks for, or an empty Program to replay the recorded draws.
  // Throws InputError for a configuration the technique cannot run. Null: a technique the
  // renderer captures but the model does not replay yet; build_program refuses its traces.
  Program (*build)(const ProgramContext& context);
  ProgramResults results;
  ConfigGroup config;  // read by the program as context.config.group<T>(config.name)
  // The query-structure instances the program builds (ProgramContext::structure); programs may
  // share one (the same name and kind).
  std::vector<StructureInstance> instances;
  // Whether a cull.mode other than trace (the cull unit's: cull every candidate again) is this
  // program's to run; every other program refuses such a mode.
  bool runs_cull_mode;
};

// Each technique of the registration list (cmake/NbsimTechniques.cmake) defines its row,
// ProgramRow <name>_program(), in pipeline/techniques/<name>/program.cpp.
#define NBSIM_DECLARE_TECHNIQUE_PROGRAM(name) ProgramRow name##_program();
NBSIM_EACH_TECHNIQUE(NBSIM_DECLARE_TECHNIQUE_PROGRAM)
#undef NBSIM_DECLARE_TECHNIQUE_PROGRAM

// The rows in the registration list's order.
std::span<const ProgramRow> program_table();
// The row of `technique`, or nullptr.
const ProgramRow* find_program(std::string_view technique);

// Every program's instances, each name once (in the list's order; the descriptions of a shared one
// joined).
std::span<const StructureInstance> structure_instances();

// The program for a trace of `technique` under `config`: none with gpu.program=off (which refuses
// a cull.mode that asks to cull). A technique without a row replays its recorded draws, and refuses
// a config that asks a program to cull (cull.mode other than trace).
Program build_program(std::string_view technique, const ProgramContext& context);

}  // namespace nbsim::pipeline
