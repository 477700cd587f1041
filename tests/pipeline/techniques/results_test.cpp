// TechniqueResultsTest: the declaration table of technique results (pipeline/techniques/results.h):
// every row's metrics have names, units and sources that point into a real run.json, the headlines
// name declared metrics, the reference setting and table rows are valid config settings; and
// `nbsim explore` / `nbsim table2` on a trace whose technique declares nothing degrade clearly.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "pipeline/techniques/results.h"
#include "tests/common/run_nbsim.h"
#include "traces/format/reader.h"
#include "traces/format/writer.h"

namespace {

namespace fs = std::filesystem;
namespace tq = nbsim::techniques;
using nbsim::testing::CliResult;
using nbsim::testing::has;
using nbsim::testing::run_nbsim;

fs::path scratch(const std::string& name) { return nbsim::testing::scratch_path("nbsim_techniques", name); }

const std::string kSample = (fs::path(NBSIM_SAMPLES) / "city_small_oq.nbt").string();

// A copy of `src` whose header's technique property is `technique` (left out when empty): every
// other property and every record as they are.
void retag(const fs::path& src, const fs::path& dst, const std::string& technique) {
  namespace tr = nbsim::trace;
  tr::FrameReader in{src};
  tr::Properties props;
  for (const auto& [k, v] : in.trace().properties())
    if (k != "technique") props.emplace_back(k, v);
  if (!technique.empty()) props.emplace_back("technique", technique);
  tr::TraceWriter out(dst, props);
  if (in.trace().scene()) out.write(*in.trace().scene());
  while (const auto f = in.next()) {  // every record the frame reader groups, in the writer's order
    out.begin_frame(f->begin);
    for (const tr::DrawRecord& d : f->draws) out.write(d);
    for (const tr::DepthSnapshot& d : f->depths) out.write(d);
    for (const tr::NBufferLevels& l : f->levels) out.write(l);
    for (const tr::StencilSnapshot& st : f->stencils) out.write(st);
    if (f->light) out.write_light(*f->light);
    for (const tr::TechniqueRecord& t : f->technique_records) out.write(t);
    if (f->truth) out.write(*f->truth);
    out.end_frame(f->end);
  }
  out.close();
}

// The config schema: key -> its entry in `nbsim config --defaults --json`.
std::map<std::string, nlohmann::json> schema() {
  const CliResult r = run_nbsim("config --defaults --json");
  EXPECT_EQ(r.status, 0) << r.err;
  std::map<std::string, nlohmann::json> keys;
  for (const auto& e : nlohmann::json::parse(r.out)) keys[e["key"].get<std::string>()] = e;
  return keys;
}

std::vector<std::string> csv_header(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> cells;
  std::string cell;
  for (const char ch : line) {
    if (ch == ',') cells.push_back(std::move(cell)), cell.clear();
    else cell += ch;
  }
  cells.push_back(cell);
  return cells;
}

bool contains(const std::vector<std::string>& v, const std::string& s) { return std::find(v.begin(), v.end(), s) != v.end(); }

// Every row: a unique technique name; every metric a unique name, a unit, a description and a JSON
// pointer; derived errors name their reference column; headlines name metrics of the right kind.
TEST(TechniqueResultsTest, EveryRowIsComplete) {
  ASSERT_FALSE(tq::technique_results().empty());
  std::set<std::string> techniques;
  for (const auto& t : tq::technique_results()) {
    EXPECT_TRUE(techniques.insert(t.technique).second) << t.technique << " has two rows";
    EXPECT_EQ(tq::find_technique_results(t.technique), &t);
    EXPECT_FALSE(t.description.empty()) << t.technique;
    std::set<std::string> names;
    for (const auto& m : t.metrics) {
      EXPECT_TRUE(names.insert(m.name).second) << t.technique << ": metric " << m.name << " is declared twice";
      EXPECT_FALSE(m.name.empty()) << t.technique;
      EXPECT_FALSE(m.unit.empty()) << t.technique << "." << m.name << " has no unit";
      EXPECT_FALSE(m.description.empty()) << t.technique << "." << m.name << " has no description";
      EXPECT_EQ(m.source.rfind("/", 0), 0u) << t.technique << "." << m.name << ": the source is a JSON pointer into run.json";
      if (m.derivation != tq::Derivation::None) {
        EXPECT_FALSE(m.reference_column.empty()) << m.name << ": a derived error shows its reference's value";
        EXPECT_EQ(m.kind, tq::MetricKind::Error) << m.name;
        EXPECT_TRUE(t.reference.has_value()) << m.name << ": a derived error needs the technique's reference setting";
      }
      if (m.must_be_zero) {
        EXPECT_EQ(m.kind, tq::MetricKind::Error) << m.name << ": a correctness count is an error";
      }
    }
    const auto* cost = tq::find_metric(t, t.headline_cost);
    ASSERT_NE(cost, nullptr) << t.technique << ": headline cost '" << t.headline_cost << "' is not a metric";
    EXPECT_EQ(cost->kind, tq::MetricKind::Cost);
    const auto* error = tq::find_metric(t, t.headline_error);
    ASSERT_NE(error, nullptr) << t.technique << ": headline error '" << t.headline_error << "' is not a metric";
    EXPECT_EQ(error->kind, tq::MetricKind::Error);
    EXPECT_EQ(error->unit, "fraction") << t.technique << ": the report plots the headline error in points of %";
    if (!t.fallback_error.empty()) {
      ASSERT_NE(tq::find_metric(t, t.fallback_error), nullptr) << t.fallback_error;
      EXPECT_EQ(tq::find_metric(t, t.fallback_error)->unit, "fraction") << "plotted as 1 - value";
    }
    if (!t.memory_cost.empty()) {
      ASSERT_NE(tq::find_metric(t, t.memory_cost), nullptr) << t.memory_cost;
      EXPECT_EQ(tq::find_metric(t, t.memory_cost)->unit, "bytes");
    }
    if (t.table) {
      EXPECT_FALSE(t.table->rows.empty()) << t.technique;
      std::set<std::string> columns = {t.table->row_column, t.table->paper_label_column, t.table->paper_value_column};
      for (const auto& [name, pointer] : t.table->columns) {
        EXPECT_EQ(pointer.rfind("/", 0), 0u) << name;
        columns.insert(name);
      }
      for (const auto& c : t.table->printed) {
        EXPECT_TRUE(columns.count(c.column)) << "printed column " << c.column << " is not in the table";
      }
      if (!t.table->must_be_zero.empty()) {
        EXPECT_TRUE(columns.count(t.table->must_be_zero));
      }
      const auto row = [&](const std::string& v) {
        return std::any_of(t.table->rows.begin(), t.table->rows.end(), [&](const tq::TableRow& r) { return r.value == v; });
      };
      if (t.table->ratio) {
        EXPECT_TRUE(row(t.table->ratio->numerator) && row(t.table->ratio->denominator)) << "the ratio's rows exist";
      }
      for (const auto& n : t.table->notes) EXPECT_TRUE(row(n.row)) << n.row;
    }
    const auto j = tq::to_json(t);
    EXPECT_EQ(j["metrics"].size(), t.metrics.size());
    EXPECT_EQ(j["headline_error"], t.headline_error);
  }
  EXPECT_EQ(tq::find_technique_results("no_such_technique"), nullptr);
  EXPECT_EQ(tq::find_technique_results(""), nullptr);
}

// The reference settings, the table's row key with every row value and the row overrides are keys
// of the config schema, and the whole reference setting is accepted by the real config check
// (explore --dry-run validates every point before anything runs).
TEST(TechniqueResultsTest, ReferenceSettingParsesAgainstTheConfigSchema) {
  const auto keys = schema();
  ASSERT_FALSE(keys.empty());
  int n = 0;
  for (const auto& t : tq::technique_results()) {
    nlohmann::json points = nlohmann::json::array();
    if (t.reference) {
      for (const auto& [k, v] : t.reference->settings.items()) EXPECT_TRUE(keys.count(k)) << t.technique << ": reference key " << k;
      for (const auto& prefix : t.reference->reset_prefixes)
        EXPECT_TRUE(std::any_of(keys.begin(), keys.end(), [&](const auto& e) { return e.first.rfind(prefix, 0) == 0; })) << prefix;
      if (!t.reference->skip_key.empty()) {
        EXPECT_TRUE(keys.count(t.reference->skip_key)) << t.reference->skip_key;
      }
      points.push_back(t.reference->settings);
    }
    if (t.table) {
      EXPECT_TRUE(keys.count(t.table->row_key)) << t.table->row_key;
      for (const auto& r : t.table->rows) {
        nlohmann::json p = {{t.table->row_key, r.value}};
        for (const auto& o : r.overrides) {
          EXPECT_TRUE(keys.count(o.key)) << o.key;
          p[o.key] = o.set;
        }
        points.push_back(p);
      }
    }
    if (points.empty()) continue;
    const fs::path sweep = scratch("schema_" + std::to_string(n) + ".json");
    std::ofstream(sweep) << nlohmann::json{{"traces", {kSample}}, {"points", points}}.dump(2);
    const CliResult r = run_nbsim("explore " + sweep.string() + " --dry-run --out " + scratch("schema_out_" + std::to_string(n++)).string());
    EXPECT_EQ(r.status, 0) << t.technique << ": " << r.err;
  }
}

// A real run.json of each declared technique: occlusion culling from the occlusion sample
// (nb_hier), particles from a small fresh capture in mode nb. A row without one here fails.
nlohmann::json real_run(const std::string& technique) {
  std::string trace = kSample, sets;
  if (technique == "occlusion_culling") {
    sets = " --set cull.mode=nb_hier";
  } else if (technique == "particles") {
    trace = scratch("particles.nbt").string();
    const CliResult c = run_nbsim("capture particles --scene city --path walk --size 96x64 --frames 2 --objects 600 "
                                  "--particles 400 --sprite 16 --mode nb -o " + trace);
    EXPECT_EQ(c.status, 0) << c.out << c.err;
  } else if (technique == "shadows") {
    trace = scratch("shadows.nbt").string();
    const CliResult c = run_nbsim("capture shadows --scene boxes --path fly --size 96x64 --frames 2 --litmap 32 -o " + trace);
    EXPECT_EQ(c.status, 0) << c.out << c.err;
  } else if (technique == "ldi") {
    trace = scratch("ldi.nbt").string();
    const CliResult c = run_nbsim("capture ldi --scene boxes --boxes 0 --path fly --size 8x8 --frames 2 --shape sphere --ldi-size 32 "
                                  "--grid 2x2 --points 256 -o " + trace);
    EXPECT_EQ(c.status, 0) << c.out << c.err;
  } else if (technique == "relief") {
    trace = scratch("relief.nbt").string();
    const CliResult c = run_nbsim("capture relief --scene boxes --boxes 0 --path fly --size 48x48 --frames 2 --field fbm "
                                  "--field-size 16 --angles 30,85 -o " + trace);
    EXPECT_EQ(c.status, 0) << c.out << c.err;
  } else if (technique == "apps") {
    trace = scratch("apps.nbt").string();
    const CliResult c = run_nbsim("capture apps --scene boxes --path fly --size 48x32 --frames 2 -o " + trace);
    EXPECT_EQ(c.status, 0) << c.out << c.err;
  } else {
    ADD_FAILURE() << technique << ": no real run.json to check its row against (add its trace to real_run)";
    return nlohmann::json();
  }
  const fs::path out = scratch("run_" + technique);
  const CliResult r = run_nbsim("replay " + trace + " --out " + out.string() + sets);
  EXPECT_EQ(r.status, 0) << r.err;
  auto run = nlohmann::json::parse(std::ifstream(out / "run.json"));
  EXPECT_EQ(run["trace_properties"]["technique"], technique) << trace;
  return run;
}

// Every declared source of every row points at a value in a real run.json of its technique, and so
// does every column of its table.
TEST(TechniqueResultsTest, SourcesPointIntoARealRun) {
  for (const auto& t : tq::technique_results()) {
    SCOPED_TRACE(t.technique);
    const nlohmann::json run = real_run(t.technique);
    if (run.is_null()) continue;
    for (const auto& m : t.metrics) {
      const nlohmann::json* v = tq::at_pointer(run, m.source);
      ASSERT_NE(v, nullptr) << m.name << ": " << m.source << " is not in run.json";
      EXPECT_TRUE(v->is_number()) << m.name << ": " << m.source << " is not a number (results.csv and the report read numbers)";
    }
    if (t.table) {
      EXPECT_NE(tq::at_pointer(run, t.table->section), nullptr);
      for (const auto& [name, pointer] : t.table->columns) EXPECT_NE(tq::at_pointer(run, pointer), nullptr) << name << ": " << pointer;
    }
    EXPECT_EQ(tq::at_pointer(run, "/summary/no_such_key"), nullptr);
    EXPECT_EQ(tq::at_pointer(run, "not a pointer"), nullptr) << "a malformed pointer finds nothing";
  }
  ASSERT_NE(tq::find_technique_results("particles"), nullptr) << "particles declares its results";
}

// Particles in mode nb: conservative (no popping, no false cull), it culls, and its fractions
// against the exact sprite test add up; must_be_zero marks popping and false_culls only.
TEST(TechniqueResultsTest, ParticlesMetricsOfARealRun) {
  const auto* t = tq::find_technique_results("particles");
  ASSERT_NE(t, nullptr);
  std::set<std::string> zero;
  for (const auto& m : t->metrics)
    if (m.must_be_zero) zero.insert(m.name);
  EXPECT_EQ(zero, (std::set<std::string>{"popping", "false_culls"}));
  ASSERT_TRUE(t->reference.has_value());
  EXPECT_EQ(t->reference->settings["nbuffer.level_cap"], -1) << "the reference builds the capture's levels";
  EXPECT_TRUE(t->reference->skip_key.empty()) << "the mode is the trace's, not a config key: every point has a reference";
  const nlohmann::json run = real_run("particles");
  ASSERT_FALSE(run.is_null());
  const auto value = [&](const char* name) { return tq::at_pointer(run, tq::find_metric(*t, name)->source)->get<double>(); };
  EXPECT_EQ(value("popping"), 0.0) << "nb is conservative";
  EXPECT_EQ(value("false_culls"), 0.0) << "nb is conservative";
  EXPECT_GT(value("culled_per_frame"), 0.0) << "the walk hides sprites behind buildings";
  EXPECT_GT(value("exactly_hidden"), 0.0);
  EXPECT_DOUBLE_EQ(value("culling_efficiency") + value("culled_below_exact_fraction"), 1.0);
  EXPECT_GT(value("culling_efficiency"), 0.0);
  EXPECT_DOUBLE_EQ(value("total_depth_tests_per_frame"),
                   value("query_depth_tests_per_frame") + value("raster_depth_tests_per_frame") + value("build_texels_per_frame"));
  EXPECT_GT(value("nbuffer_memory_bytes"), 0.0);
}

// A trace whose technique declares no results, and one with no technique at all: explore runs them
// with the generic columns only and says so; mixed with an occlusion-culling trace, only that
// trace's rows fill the culling columns. table2 refuses both with exit 2.
TEST(TechniqueResultsTest, UndeclaredTechniquesDegradeClearly) {
  const fs::path unknown = scratch("unknown.nbt"), none = scratch("none.nbt");
  retag(kSample, unknown, "particles_not_declared");
  retag(kSample, none, "");
  const nlohmann::json points = {{{"gpu.quantum_cycles", 0}}};

  const fs::path out = scratch("unknown_out");
  std::ofstream(scratch("unknown.json")) << nlohmann::json{{"traces", {unknown.string()}}, {"points", points}}.dump();
  CliResult r = run_nbsim("explore " + scratch("unknown.json").string() + " --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has(r.err, "technique 'particles_not_declared' declares no results")) << r.err;
  auto header = csv_header(out / "results.csv");
  for (const char* c : {"frames", "cycles_per_frame", "counter_error", "cycle_error", "memory_bytes_per_frame"})
    EXPECT_TRUE(contains(header, c)) << "generic column " << c;
  for (const char* c : {"culling_efficiency", "efficiency_lost", "culling_reference", "false_culls"})
    EXPECT_FALSE(contains(header, c)) << c << " belongs to occlusion culling";
  const auto tr = nlohmann::json::parse(std::ifstream(out / "technique_results.json"));
  EXPECT_TRUE(tr["techniques"].empty());
  EXPECT_EQ(tr["traces"][unknown.string()], "particles_not_declared");
  ASSERT_EQ(tr["notes"].size(), 1u);

  std::vector<std::string> lines;
  {
    std::ifstream csv(out / "results.csv");
    for (std::string line; std::getline(csv, line);) lines.push_back(line);
  }
  EXPECT_EQ(lines.size(), 2u) << "one point, no technique reference point added for it";

  // Mixed with the occlusion-culling sample (culling there): its row has a culling reference, the
  // trace without a technique has none and adds no reference point.
  const fs::path mixed = scratch("mixed_out");
  const nlohmann::json mixed_points = {{{"trace", none.string()}}, {{"trace", kSample}, {"cull.mode", "nb"}}};
  std::ofstream(scratch("mixed.json")) << nlohmann::json{{"traces", {none.string(), kSample}}, {"points", mixed_points}}.dump();
  r = run_nbsim("explore " + scratch("mixed.json").string() + " --out " + mixed.string());
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has(r.err, "names no technique in its header")) << r.err;
  EXPECT_TRUE(has(r.out, "3 points (1 of them references)")) << "only the sample's nb point gets a culling reference: " << r.out;
  header = csv_header(mixed / "results.csv");
  EXPECT_TRUE(contains(header, "culling_efficiency") && contains(header, "efficiency_lost")) << "the sample's technique declares them";
  std::ifstream csv(mixed / "results.csv");
  std::string line;
  std::getline(csv, line);
  const auto col = static_cast<std::size_t>(std::find(header.begin(), header.end(), "culling_reference") - header.begin());
  int rows = 0;
  while (std::getline(csv, line)) {
    std::vector<std::string> cells;
    std::string cell;
    for (const char ch : line) {
      if (ch == ',') cells.push_back(std::move(cell)), cell.clear();
      else cell += ch;
    }
    cells.push_back(cell);
    ASSERT_EQ(cells.size(), header.size());
    EXPECT_EQ(cells[col].empty(), !has(line, kSample)) << "only occlusion-culling rows have a culling reference: " << line;
    ++rows;
  }
  EXPECT_EQ(rows, 3);

  for (const auto& [trace, message] : {std::pair{unknown, "declares no Table-2 rows"}, std::pair{none, "names no technique"}}) {
    r = run_nbsim("table2 " + trace.string());
    EXPECT_EQ(r.status, 2) << r.out << r.err;
    EXPECT_TRUE(has(r.err, message)) << r.err;
  }
}

}  // namespace
