"""AnalysisTest: analysis/report.py on a fixture of real nbsim outputs (tests/analysis/fixture, refreshed by
make_fixture.sh) and on hand-made inputs. Run: /usr/bin/python3 -m unittest discover -s tests/analysis -v
"""
import csv
import json
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

sys.dont_write_bytecode = True
HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
SCRIPT = ROOT / "analysis" / "report.py"
FIXTURE = HERE / "fixture"
PYTHON = "/usr/bin/python3" if os.path.exists("/usr/bin/python3") else sys.executable
sys.path.insert(0, str(ROOT / "analysis"))
import report  # noqa: E402
import report_data  # noqa: E402
import table1  # noqa: E402


def load_technique_module(technique, name):
    """analysis/techniques/TECHNIQUE/NAME.py under a name of its own (every technique has a section.py)."""
    import importlib.util
    spec = importlib.util.spec_from_file_location(f"{technique}_{name}", ROOT / "analysis" / "techniques" / technique / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module

# Each technique's report section (analysis/techniques/NAME/section.py), by name.
SECTIONS = {s.NAME: s for s in report.technique_sections()}


def run_report(d):
    p = subprocess.run([PYTHON, str(SCRIPT), str(d)], capture_output=True, text=True, timeout=300)
    return p.returncode, p.stdout, p.stderr


def png_size(path):
    """(width, height) from the IHDR chunk; AssertionError when the file is not a PNG."""
    data = Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", f"{path} is not a PNG"
    assert data[12:16] == b"IHDR", f"{path} has no IHDR chunk first"
    assert data.rstrip(b"\x00").endswith(b"IEND\xaeB`\x82"), f"{path} is truncated"
    return struct.unpack(">II", data[16:24])


def write_sweep(d, name, header, rows, parameters):
    """A sweep folder as nbsim explore writes it: results.csv, sweep.json and technique_results.json (the
    fixture's, occlusion culling's declared results)."""
    s = Path(d) / "sweeps" / name
    s.mkdir(parents=True)
    with open(s / "results.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows(rows)
    (s / "sweep.json").write_text(json.dumps({"name": name, "nbsim_version": "test", "parameters": parameters}))
    shutil.copy(FIXTURE / "sweeps" / "small" / "technique_results.json", s)
    return s


class FixtureReport(unittest.TestCase):
    """The report on the fixture: every section, every image, the CSV copies."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.dir = Path(cls.tmp.name) / "out"
        shutil.copytree(FIXTURE, cls.dir)
        cls.rc, cls.out, cls.err = run_report(cls.dir)
        cls.version = json.loads((FIXTURE / "table2" / "table2.json").read_text())["nbsim_version"]
        cls.html = (cls.dir / "report" / "index.html").read_text() if (cls.dir / "report" / "index.html").exists() else ""

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_exit_zero_and_no_missing_inputs(self):
        # a complete fixture renders with exit 0 and reports nothing missing
        self.assertEqual(self.rc, 0, f"report failed on the fixture: {self.err}")
        self.assertNotIn("inputs missing", self.html, "the fixture has every input")
        self.assertNotIn("Not rendered", self.html)

    def test_every_section_is_there(self):
        # one heading per section, one per sweep, and the speed plot of the fidelity sweep
        for title in ["Table 1: N-buffer build cost", "Figure 4: covering tightness", "Table 2: depth tests per frame",
                      "Depth tests per frame along the walkthrough", "Sweep small", "Sweep nbuffer_resolution",
                      "Sweep fidelity", "simulator speed", f"nbsim version {self.version}"]:
            self.assertIn(title, self.html, f"index.html lacks '{title}'")
        self.assertIn("fidelity_speed_vs_cycle_error.png", self.html, "a fidelity sweep must get the speed plot")
        self.assertNotIn("small_speed_vs_cycle_error.png", self.html, "small.json has no fidelity knob")

    def test_images_exist_and_are_valid_pngs(self):
        # every <img> points at a real PNG of a readable size
        srcs = [s.split('"')[0] for s in self.html.split('<img src="')[1:]]
        self.assertGreaterEqual(len(srcs), 11, f"too few images: {srcs}")
        for s in srcs:
            p = self.dir / "report" / s
            self.assertTrue(p.exists(), f"{s} is referenced but not written")
            w, h = png_size(p)
            self.assertTrue(500 <= w <= 2000 and 300 <= h <= 1500, f"{s} is {w}x{h} pixels")
            self.assertGreater(p.stat().st_size, 10_000, f"{s} is suspiciously small")

    def test_tables_have_csv_copies_and_thousands_separators(self):
        # each table links its CSV copy, which exists; big numbers are grouped
        links = [s.split('"')[0] for s in self.html.split('<a href="')[1:] if s.split('"')[0].endswith(".csv")]
        for name in ["table1.csv", "figure4.csv", "table2.csv", "table2_ratios.csv", "small_points.csv"]:
            self.assertIn(name, links)
        for link in links:
            self.assertTrue((self.dir / "report" / link).exists(), f"{link} is linked but not written")
        self.assertRegex(self.html, r">\d{1,3},\d{3}<", "no number with a thousands separator")

    def test_pareto_csv_written_per_sweep(self):
        # <sweep>_pareto.csv holds every results.csv row plus a pareto column, and some points are on the front
        for name in ["small", "nbuffer_resolution", "fidelity"]:
            with open(self.dir / "sweeps" / name / "results.csv") as f:
                n = len(list(csv.DictReader(f)))
            with open(self.dir / "report" / f"{name}_pareto.csv") as f:
                rows = list(csv.DictReader(f))
            self.assertEqual(len(rows), n, f"{name}_pareto.csv lost rows")
            self.assertIn("pareto", rows[0])
            self.assertTrue(any(r["pareto"] == "yes" for r in rows), f"{name}: nothing on the front")
            self.assertTrue(all(r["pareto"] in ("yes", "no", "") for r in rows))

    def test_table2_names_trace_and_ratio(self):
        # the trace and the oq/nb ratio beside the paper's 400x
        self.assertIn("traces/samples/city_small_oq.nbt", self.html)
        t = json.loads((FIXTURE / "table2" / "table2.json").read_text())
        by = {r["mode"]: r for r in t["rows"]}
        ours = by["oq"]["query_depth_tests_per_frame"] / by["nb"]["query_depth_tests_per_frame"]
        self.assertIn(f"oq / nb: {ours:,.0f}x (paper 400x)", self.html)

    def test_headline_tables(self):
        # headline.md: Table 2 beside the paper, then per sweep a Markdown table of its Pareto front (one
        # row per point marked on the cycles front), or the cycle-error summary of a sweep that culls alike
        text = (self.dir / "report" / "headline.md").read_text()
        self.assertIn("| mode | paper | query depth tests |", text)
        for name in ["small", "nbuffer_resolution", "fidelity"]:
            self.assertIn(f"Sweep {name}: Pareto-optimal points", text)
        block = text.split("Sweep nbuffer_resolution:")[1].split("Sweep ")[0]
        table = [line for line in block.splitlines() if line.startswith("| ") and not line.startswith("| trace")]
        with open(self.dir / "report" / "nbuffer_resolution_pareto.csv") as f:
            front = [r for r in csv.DictReader(f) if r["pareto"] == "yes"]
        self.assertGreater(len(front), 1, "the fixture sweep has a trade-off")
        self.assertEqual(len(table), len(front), block)
        for line in table:
            self.assertEqual(line.count("|"), 8, line)
        fidelity = text.split("Sweep fidelity:")[1].split("Sweep ")[0]
        self.assertIn("every point culls alike", fidelity)
        self.assertIn("largest |cycle error|", fidelity)
        self.assertTrue(text.split("\n\n", 1)[0].startswith("Table 2"), "Table 2 comes first")
        last = text.split("Sweep fidelity:")[1]
        self.assertIn("Particles (particles_none, particles_center, particles_nb, particles_hiz)", last,
                      "the particles table follows the sweeps (scripts/demo ends on it and the shadows table)")
        self.assertIn("Shadows (9 traces of boxes, terrain, city)", last.split("Particles (")[1],
                      "the shadows table follows the particles table")
        self.assertIn("Layered depth images (2 shapes, 4 LDIs)", last.split("Shadows (")[1],
                      "the LDI table follows the shadows table")
        self.assertIn("Relief textures (10 traces: 5 heightfields at 32² and 64², 4 view angles each)",
                      last.split("Layered depth images (")[1], "the relief table is the last block, after the LDI table")

    def test_ldi_section_from_nbsim_ldi_table1(self):
        # ldi/ldi.json (nbsim ldi table1 --out): its rows in the table and CSV copy, the plot, the paper's sphere row
        rows = json.loads((FIXTURE / "ldi" / "ldi.json").read_text())
        self.assertIn("ldi/ldi.json", self.html, "the page names its input")
        with open(self.dir / "report" / "ldi.csv") as f:
            table = list(csv.DictReader(f))
        self.assertEqual([(t["shape"], int(t["ldi_size"])) for t in table], [(r["shape"], r["ldi_size"]) for r in rows])
        for t, r in zip(table, rows):
            self.assertEqual(int(t["m_comp"]), r["m_comp"], "memory is nbsim's own")
            if r["shape"] == "sphere":
                self.assertEqual(float(t["paper_c_ratio"]), 1.78)
        png_size(self.dir / "report" / "ldi.png")
        self.assertIn("C_ratio", (self.dir / "report" / "headline.md").read_text())

    def test_relief_section_from_nbsim_relief(self):
        # relief/relief.json (nbsim relief --out): the ranking, the N-buffer walk against the exact walk and the
        # paper's table with their CSV copies, the plot, and readings whose numbers are the fixture's own
        doc = json.loads((FIXTURE / "relief" / "relief.json").read_text())
        self.assertIn("Relief textures: the methods&#x27; cost against hit error", self.html)
        self.assertIn("relief/relief.json", self.html, "the page names its input")
        png_size(self.dir / "report" / "relief.png")
        self.assertIn('<img src="relief.png"', self.html)
        with open(self.dir / "report" / "relief_ranking.csv") as f:
            ranking = list(csv.DictReader(f))
        self.assertEqual([r["method"] for r in ranking], [r["method"] for r in doc["ranking"]], "nbsim's order, cheapest first")
        for t, r in zip(ranking, doc["ranking"]):
            self.assertAlmostEqual(float(t["cycles_per_frame"]), r["cycles_per_frame"], msg="cycles are nbsim's own")
            self.assertEqual(t["pareto_mark"], "yes (front)" if r["pareto"] else "no", f"{r['method']}: Pareto mark")
            self.assertIn(f">{100 * r['error_rate']:.3f}%<", self.html, f"{r['method']}: hit error in %")
        with open(self.dir / "report" / "relief_nbuffer_vs_exact.csv") as f:
            self.assertEqual(len(list(csv.DictReader(f))), len(doc["nbuffer_vs_exact"]))
        nve = doc["nbuffer_vs_exact"]
        fewer = sum(1 for r in nve if r["lookup_ratio"] < 1)
        extra = sum(1 for r in nve if r["extra_errors"] > 0)
        self.assertGreater(fewer, 0, "the fixture's N-buffer walk saves lookups somewhere")
        self.assertIn(f"The N-buffer walk read fewer lookups per fragment than the exact walk on {fewer} of {len(nve)} "
                      "heightfields", self.html, "the count is the fixture's")
        self.assertIn(f"with extra hit errors on {extra}:" if extra else "with 0 extra hit errors on any of them", self.html)
        with open(self.dir / "report" / "relief_paper.csv") as f:
            paper = list(csv.DictReader(f))
        self.assertEqual(len(paper), len(doc["paper"]))
        self.assertIn("ranks the methods by frame rate on a 2006 GPU", self.html)
        for size in sorted({r["field_size"] for r in doc["paper"] if r["cycles_per_frame"] is not None}):
            g = [r for r in doc["paper"] if r["field_size"] == size and r["cycles_per_frame"] is not None]
            by_hz = ", ".join(r["method"] for r in sorted(g, key=lambda r: -r["paper_hz"]))
            by_cycles = ", ".join(r["method"] for r in sorted(g, key=lambda r: r["cycles_per_frame"]))
            self.assertIn(f"At {size}², the paper: {by_hz} (", self.html, f"the paper's order at {size}")
            self.assertIn(f"; ours: {by_cycles} (", self.html, f"our order at {size}")
        self.assertTrue(all(r["walk_mismatches"] == 0 and r["pixel_mismatches"] == 0 for r in doc["rows"]),
                        "the fixture's walks are GL's")
        self.assertIn(f"The model&#x27;s walks and pixels are GL&#x27;s in every row ({len(doc['rows'])} rows", self.html)
        self.assertNotIn("GL AND THE MODEL DISAGREE", self.html)
        with open(self.dir / "report" / "relief_rows.csv") as f:
            self.assertEqual(len(list(csv.DictReader(f))), len(doc["rows"]), "every row in relief_rows.csv")
        text = (self.dir / "report" / "headline.md").read_text()
        block = text.split("Relief textures (")[1]
        lines = []  # the block's first table (the blocks after it have theirs)
        for line in block.splitlines():
            if line.startswith("|"):
                lines.append(line)
            elif lines:
                break
        lines = [line for line in lines if line.startswith("| ") and not line.startswith("| method")]
        self.assertEqual(len(lines), len(doc["ranking"]), block)
        front = [r["method"] for r in doc["ranking"] if r["pareto"]]
        self.assertIn(f"Pareto front of cycles per box draw against hit error: {front[0]} (", block)

    def test_apps_section_beside_the_walkthrough(self):
        # apps/table2.json: the real program's rows beside the walkthrough's (table2/table2.json), its CSV copy,
        # and a reading whose numbers are the fixture's own
        apps = json.loads((FIXTURE / "apps" / "table2.json").read_text())
        city = json.loads((FIXTURE / "table2" / "table2.json").read_text())
        self.assertIn("A real program: its draw calls culled in every mode", self.html)
        self.assertIn("apps/table2.json", self.html, "the page names its input")
        with open(self.dir / "report" / "apps.csv") as f:
            table = list(csv.DictReader(f))
        self.assertEqual(len(table), len(apps["rows"]) + len(city["rows"]), "both programs' rows")
        self.assertEqual([r["mode"] for r in table[:len(apps["rows"])]], [r["mode"] for r in apps["rows"]])
        for got, r in zip(table, apps["rows"] + city["rows"]):
            self.assertEqual(float(got["total_depth_tests_per_frame"]), float(r["total_depth_tests_per_frame"]))
            self.assertEqual(int(float(got["false_culls"])), int(r["false_culls"]))
        rows = {r["mode"]: r for r in apps["rows"]}
        best = min((r for r in apps["rows"] if r["mode"] != "none"), key=lambda r: r["total_depth_tests_per_frame"])
        self.assertIn(f"with {best['mode']} ({best['total_depth_tests_per_frame']:,.0f} a frame)", self.html)
        ratio = rows["oq"]["query_depth_tests_per_frame"] / rows["nb"]["query_depth_tests_per_frame"]
        self.assertIn(f"occlusion queries read {ratio:,.0f} times", self.html)
        self.assertTrue((self.dir / "report" / "apps.png").exists())
        headline = (self.dir / "report" / "headline.md").read_text()
        self.assertIn("Culling a real program's draw calls", headline)

    def test_particles_section_per_mode_beside_the_paper(self):
        # particles/particles.json: one row per mode beside the paper's 256 N and N, its CSV copy, and a
        # reading whose numbers are the fixture's own
        rows = {r["mode"]: r for r in json.loads((FIXTURE / "particles" / "particles.json").read_text())}
        self.assertEqual(set(rows), {"none", "center", "nb", "hiz"}, "the fixture has one capture per mode")
        self.assertIn("Particles: depth tests per frame beside the paper", self.html)
        self.assertIn("particles/particles.json", self.html, "the page names its input")
        with open(self.dir / "report" / "particles.csv") as f:
            table = {r["mode"]: r for r in csv.DictReader(f)}
        self.assertEqual(list(table), ["none", "center", "nb", "hiz"], "rows in mode order")
        n = rows["nb"]["particles_per_frame"]
        self.assertEqual(float(table["none"]["paper_depth_tests_per_frame"]), 256 * n, "none: the paper's 256 N")
        self.assertEqual(float(table["nb"]["paper_depth_tests_per_frame"]), n, "nb: the paper's N")
        self.assertAlmostEqual(float(table["nb"]["ours_over_paper"]), rows["nb"]["query_depth_tests_per_frame"] / n,
                               msg="nb's ours / paper is its query depth tests over N")
        for k in ["query_depth_tests_per_frame", "raster_depth_tests_per_frame", "build_texels_per_frame",
                  "total_depth_tests_per_frame", "culled_per_frame", "popping", "false_culls", "cycles_per_frame"]:
            for m, r in rows.items():
                self.assertEqual(float(table[m][k]), float(r[k]), f"particles.csv {m}.{k} is not particles.json's")
                self.assertIn(f">{report_data.fmt(r[k])}<", self.html, f"{m}.{k} is not in the page")
        q, raster = rows["nb"]["query_depth_tests_per_frame"], rows["none"]["total_depth_tests_per_frame"]
        self.assertIn(f"reads {q:,.0f} texels a frame for {n:,.0f} sprites, {q / n:.2f} per sprite", self.html)
        self.assertIn(f"queries are {raster / q:,.0f} times fewer depth tests than rasterizing every sprite", self.html)
        self.assertGreater(rows["center"]["popping"], 0, "the fixture's center capture pops")
        self.assertIn(f"center {rows['center']['popping']:,.0f}; 0 in none, nb and hiz", self.html)
        self.assertIn("particles.png", self.html)


    def test_shadows_section_per_scene_and_mode_beside_the_paper(self):
        # shadows/shadows.json: one row per scene and mode in scene and mode order, its CSV copy, the paper's
        # clamped ratio on the clamped rows, and a reading whose numbers are the fixture's own
        rows = json.loads((FIXTURE / "shadows" / "shadows.json").read_text())
        self.assertEqual({(r["scene"], r["shadow_mode"]) for r in rows},
                         {(s, m) for s in ["boxes", "terrain", "city"] for m in ["infinite", "culled", "clamped"]},
                         "the fixture has one capture per scene and mode")
        self.assertIn("Shadows: fill per frame beside the paper", self.html)
        self.assertIn("shadows/shadows.json", self.html, "the page names its input")
        with open(self.dir / "report" / "shadows.csv") as f:
            table = list(csv.DictReader(f))
        self.assertEqual([(r["scene"], r["shadow_mode"]) for r in table],
                         [(s, m) for s in ["boxes", "terrain", "city"] for m in ["infinite", "culled", "clamped"]],
                         "rows by scene, then mode")
        by = {(r["scene"], r["shadow_mode"]): r for r in rows}
        for t in table:
            r = by[(t["scene"], t["shadow_mode"])]
            for k in ["fill_per_frame", "build_texels_per_frame", "lookups_per_frame", "cycles_per_frame", "mask_diff",
                      "mask_diff_infinite"]:
                self.assertEqual(float(t[k]), float(r[k]), f"shadows.csv {t['scene']} {t['shadow_mode']}.{k} is not shadows.json's")
            self.assertEqual(float(t["casters_culled_per_frame"]), r["gl_culled_per_frame"] + r["outside_per_frame"],
                             "casters culled: GL's culls and the casters outside the light's frustum")
            self.assertAlmostEqual(float(t["ratio"]), r["ratio_to_infinite"], msg="the ratio is nbsim shadows' own")
            self.assertEqual(t["paper_text"], {"boxes": "~20%", "terrain": "2.5%", "city": "2.5% (20 M -> 512 K px)"}[
                t["scene"]] if t["shadow_mode"] == "clamped" else "", "the paper's ratio on clamped rows only")
        for scene in ["boxes", "terrain", "city"]:
            c = by[(scene, "clamped")]
            self.assertIn(f"{scene}: clamping cuts the fill to {c['ratio_to_infinite']:.1%} of the infinite volumes&#x27;",
                          self.html, "the reading quotes the table's ratio")
            i = by[(scene, "infinite")]
            self.assertIn(f"fall from {i['cycles_per_frame']:,.0f} (infinite) to {c['cycles_per_frame']:,.0f} (clamped)",
                          self.html)
        self.assertIn("Culling and clamping changed no shadow-mask pixel", self.html, "every fixture row has 0 mask pixels")
        self.assertIn("shadows.png", self.html)
        png_size(self.dir / "report" / "shadows.png")
        text = (self.dir / "report" / "headline.md").read_text()
        block = text.split("Shadows (")[1].split("Layered depth images (")[0]
        lines = [line for line in block.splitlines() if line.startswith("| ") and not line.startswith("| scene")]
        self.assertEqual(len(lines), 9, block)
        self.assertIn("| city | - | clamped | 64 |", block)

    def test_relief_figure12_points(self):
        # The Figure 12 series: per radius (strict first, then paper by combination and epsilon) the robust
        # searches' mean cycles and hit error over their rows.
        relief_section = load_technique_module("relief", "section")

        def row(radius, combine, eps, method, cycles, errors, fragments=100):
            return {"radius": radius, "radius_combine": combine, "radius_epsilon": eps, "radius_mean": 1.5, "method": method,
                    "cycles": cycles, "errors": errors, "fragments": fragments}
        doc = {"rows": [row("paper", "min", 0.05, "robust", 10, 2), row("paper", "min", 0.05, "robust", 20, 0),
                        row("strict", None, 0.0, "robust", 40, 0), row("paper", "min", 0.0, "robust", 30, 0),
                        row("paper", "min", 0.0, "exact", 99, 9)]}
        pts = relief_section.figure12_points(doc)
        self.assertEqual([(p["radius"], p["epsilon"]) for p in pts], [("strict", 0.0), ("paper", 0.0), ("paper", 0.05)])
        self.assertEqual(pts[2]["robust_cycles"], 15)
        self.assertAlmostEqual(pts[2]["robust_error"], 0.01)
        self.assertIsNone(pts[0]["robust_clamp_cycles"])

    def test_shadows_reading_per_camera_path(self):
        # Rows of one scene on two camera paths (the flyover and the paper's observer on the ground):
        # sorted fly first, and the reading names the path of each clamped ratio.
        shadows_section = load_technique_module("shadows", "section")
        base = json.loads((FIXTURE / "shadows" / "shadows.json").read_text())
        city = [r for r in base if r["scene"] == "city"]
        ground = [dict(r, path="ground", fill_per_frame=r["fill_per_frame"] / 2,
                       ratio_to_infinite=r.get("ratio_to_infinite") and r["ratio_to_infinite"] / 2) for r in city]
        rows = shadows_section.shadows_rows([dict(r, path="fly") for r in city] + ground)
        self.assertEqual([r["path"] for r in rows], ["fly"] * len(city) + ["ground"] * len(city))
        reading = " ".join(shadows_section.shadows_reading(rows))
        self.assertIn("city (fly path): clamping cuts the fill", reading)
        self.assertIn("city (ground path): clamping cuts the fill", reading)


class Pareto(unittest.TestCase):
    """Pareto marks on hand-made points: minimise cost and error, per trace, ok sweep rows only."""

    def test_flags_known_points(self):
        # dominated, non-dominated and tied points (equal points stay on the front together)
        pts = [(1, 5), (2, 3), (2, 3), (3, 3), (4, 1), (5, 1), (0.5, 10), (2, 5), None]
        self.assertEqual(report_data.pareto_flags(pts), [True, True, True, False, True, False, True, False, None])

    def test_equal_cost_lower_error_dominates(self):
        # same cost, strictly lower error: the other is dominated (<= in both, < in one)
        self.assertEqual(report_data.pareto_flags([(1, 2), (1, 1)]), [False, True])
        self.assertEqual(report_data.pareto_flags([(7, 7)]), [True])

    def test_report_marks_per_trace_and_skips_failed_and_reference(self):
        # through the whole script: a tiny results.csv with two traces, a failed and a reference row
        header = ["point_id", "trace", "nbuffer.resolution_divisor", "status", "role", "cycles_per_frame",
                  "total_depth_tests_per_frame", "culling_efficiency", "efficiency_lost", "false_culls", "host_seconds"]
        rows = [
            ["a", "t1.nbt", 1, "ok", "sweep", 100, 1000, 0.9, 0.00, 0, 0.1],   # best error: front
            ["b", "t1.nbt", 2, "ok", "sweep", 50, 900, 0.8, 0.10, 0, 0.1],     # cheaper, worse: front
            ["c", "t1.nbt", 4, "ok", "sweep", 60, 800, 0.7, 0.20, 0, 0.1],     # dominated by b in cycles
            ["d", "t1.nbt", 8, "ok", "sweep", 50, 950, 0.8, 0.10, 1, 0.1],     # ties b in cycles: front
            ["e", "t1.nbt", 16, "failed", "sweep", "", "", "", "", "", ""],    # failed: not considered
            ["f", "t1.nbt", 1, "ok", "reference", 1, 1, 1.0, 0.0, 0, 0.1],     # reference: never dominates
            ["g", "t2.nbt", 4, "ok", "sweep", 500, 5000, 0.5, 0.40, 0, 0.1],   # alone on its trace: front
        ]
        with tempfile.TemporaryDirectory() as d:
            write_sweep(d, "tiny", header, rows, ["nbuffer.resolution_divisor"])
            rc, _, err = run_report(d)
            self.assertEqual(rc, 0, err)
            with open(Path(d) / "report" / "tiny_pareto.csv") as f:
                got = {r["point_id"]: (r["pareto"], r["pareto_depth_tests"]) for r in csv.DictReader(f)}
            html = (Path(d) / "report" / "index.html").read_text()
        self.assertEqual({k: v[0] for k, v in got.items()},
                         {"a": "yes", "b": "yes", "c": "no", "d": "yes", "e": "", "f": "", "g": "yes"})
        # total depth tests: c (800, 20%) is cheapest, a has the least error, b (900, 10%) in between
        self.assertEqual({k: v[1] for k, v in got.items()},
                         {"a": "yes", "b": "yes", "c": "yes", "d": "no", "e": "", "f": "", "g": "yes"})
        self.assertIn("efficiency lost", html)
        self.assertIn('<tr class="bad">', html, "the row with a false cull (d) must be flagged")


class FutureColumns(unittest.TestCase):
    """Columns results.csv is getting (role, nbuffer_memory_bytes, efficiency_lost, cycle_error,
    counter_error), added here to a real results.csv of the fixture."""

    def test_reference_rows_memory_plot_and_cycle_error(self):
        # reference rows stay out of the fronts, N-buffer memory gets its plot, cycle_error the speed plot
        with open(FIXTURE / "sweeps" / "nbuffer_resolution" / "results.csv") as f:
            rows = list(csv.DictReader(f))
        header = list(rows[0]) + ["role", "nbuffer_memory_bytes", "efficiency_lost", "cycle_error", "counter_error"]
        ref = dict(rows[0], point_id="reference")
        ref["cull.mode"] = "nb"  # at the reference settings: culls better than any point of the sweep
        ref_ce = max(float(r["culling_efficiency"]) for r in rows) + 0.01
        ref["culling_efficiency"] = str(ref_ce)
        out = []
        for k, r in enumerate([ref] + rows):
            d = int(r["nbuffer.resolution_divisor"])
            out.append(dict(r, role="reference" if r is ref else "sweep",
                            nbuffer_memory_bytes=str(49152 * 7 // (d * d)),
                            efficiency_lost=str(ref_ce - float(r["culling_efficiency"])),
                            cycle_error=str(0.001 * (k % 4)), counter_error="0"))
        with tempfile.TemporaryDirectory() as d:
            s = Path(d) / "sweeps" / "res"
            s.mkdir(parents=True)
            for name in ["sweep.json", "technique_results.json"]:
                shutil.copy(FIXTURE / "sweeps" / "nbuffer_resolution" / name, s)
            with open(s / "results.csv", "w", newline="") as f:
                w = csv.DictWriter(f, fieldnames=header)
                w.writeheader()
                w.writerows(out)
            rc, _, err = run_report(d)
            self.assertEqual(rc, 0, err)
            html = (Path(d) / "report" / "index.html").read_text()
            with open(Path(d) / "report" / "res_pareto.csv") as f:
                got = {r["point_id"]: r for r in csv.DictReader(f)}
            for png in ["res_memory_vs_error.png", "res_speed_vs_cycle_error.png", "res_cycles_vs_error.png"]:
                self.assertIn(png, html)
                png_size(Path(d) / "report" / png)
        self.assertEqual(got["reference"]["pareto"], "", "a reference row is never on a front")
        self.assertIn("pareto_memory", got["reference"])
        self.assertIn("efficiency lost", html)
        self.assertIn("cycle_error column", html)


class OneSweepFolder(unittest.TestCase):
    def test_report_on_an_explore_out_folder(self):
        # `nbsim report DIR` on DIR = `nbsim explore --out DIR`: the sweep alone, named after the folder
        with tempfile.TemporaryDirectory() as t:
            d = Path(t) / "mysweep"
            shutil.copytree(FIXTURE / "sweeps" / "small", d)
            rc, out, err = run_report(d)
            self.assertEqual(rc, 0, err)
            self.assertIn("Sweep mysweep", (d / "report" / "index.html").read_text())
            self.assertTrue((d / "report" / "mysweep_pareto.csv").exists())
            self.assertIn("Sweep mysweep: Pareto-optimal points", (d / "report" / "headline.md").read_text())


class Labels(unittest.TestCase):
    """place_labels: one annotation per place, clear of every marker, labelled or not."""

    def test_labels_clear_of_markers_and_each_other(self):
        import report_plots
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(7, 4.5), constrained_layout=True)
        xs = [1, 2, 3, 3.02, 4, 5]
        ys = [5, 3, 1, 1.0, 0.5, 0.2]
        unlabelled = [(x + 0.08, y + 0.15) for x, y in zip(xs, ys)]  # where the first-choice labels would go
        ax.scatter(xs + [p[0] for p in unlabelled], ys + [p[1] for p in unlabelled])
        report_plots.freeze_layout(fig)
        report_plots.place_labels(ax, xs, ys, [f"p{i}" for i in range(len(xs))], avoid=unlabelled)
        texts = ax.texts
        self.assertEqual(len(texts), 5, "the two points at one place share one label")
        self.assertIn("p2\np3", [t.get_text() for t in texts])
        r = fig.canvas.get_renderer()
        boxes = [t.get_window_extent(r) for t in texts]
        for x, y in list(zip(xs, ys)) + unlabelled:
            px, py = ax.transData.transform((x, y))
            for t, b in zip(texts, boxes):
                self.assertFalse(b.x0 < px < b.x1 and b.y0 < py < b.y1, f"label {t.get_text()!r} covers ({x}, {y})")
        for i in range(len(boxes)):
            for j in range(i):
                self.assertFalse(boxes[i].overlaps(boxes[j]), f"{texts[i].get_text()!r} overlaps {texts[j].get_text()!r}")
        plt.close(fig)


class ShortLabels(unittest.TestCase):
    """short_label: the point labels of sweep tables and plots."""

    def test_two_nbuffer_instances_named_once(self):
        # litmap_min.* and litmap_max.* set alike (the shadows sweep) read as one N-buffer design; set apart, both show
        keys = [f"{u}.{f}" for u in ("litmap_min", "litmap_max") for f in ("resolution_divisor", "format", "level_cap")]
        alike = {f"{u}.{f}": v for u in ("litmap_min", "litmap_max")
                 for f, v in (("resolution_divisor", "2"), ("format", "u16"), ("level_cap", "4"))}
        self.assertEqual(report_data.short_label(alike, keys), "div=2 u16 cap=4")
        apart = dict(alike, **{"litmap_max.resolution_divisor": "4"})
        self.assertEqual(report_data.short_label(apart, keys), "div=2 u16 cap=4 div=4")
        self.assertEqual(report_data.short_label({"nbuffer.resolution_divisor": "2", "nbuffer.format": "u16"},
                                                 ["nbuffer.resolution_divisor", "nbuffer.format"]), "div=2 u16")


class Table2Ratio(unittest.TestCase):
    """table2_ratios of the occlusion culling section (analysis/techniques/occlusion/section.py)."""

    def test_ratio_against_paper(self):
        # oq/nb and oq_hier/nb_hier from query depth tests, beside the paper's 400x and 3143x
        rows = [{"mode": "oq", "query_depth_tests_per_frame": 20000.0, "paper_depth_tests_per_frame": 200000.0},
                {"mode": "nb", "query_depth_tests_per_frame": 400.0, "paper_depth_tests_per_frame": 500.0},
                {"mode": "oq_hier", "query_depth_tests_per_frame": 3000.0, "paper_depth_tests_per_frame": 1100000.0},
                {"mode": "nb_hier", "query_depth_tests_per_frame": 300.0, "paper_depth_tests_per_frame": 350.0},
                {"mode": "hiz_tile", "query_depth_tests_per_frame": 700.0, "paper_depth_tests_per_frame": None}]
        r = {x["ratio"]: x for x in SECTIONS["occlusion"].table2_ratios(rows)}
        self.assertAlmostEqual(r["oq / nb"]["ours"], 50.0)
        self.assertAlmostEqual(r["oq / nb"]["paper"], 400.0)
        self.assertAlmostEqual(r["oq_hier / nb_hier"]["ours"], 10.0)
        self.assertAlmostEqual(r["oq_hier / nb_hier"]["paper"], 1100000 / 350)

    def test_ratio_needs_both_modes(self):
        # without nb there is no oq/nb ratio (not a division by a missing row)
        self.assertEqual(SECTIONS["occlusion"].table2_ratios([{"mode": "oq", "query_depth_tests_per_frame": 1.0}]), [])


class TechniqueDeclarations(unittest.TestCase):
    """The sweep section takes its cost and error metrics from technique_results.json (nbsim explore writes
    it from pipeline/techniques/results.cpp), not from fixed names."""

    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = Path(self.tmp.name)

    def tearDown(self):
        self.tmp.cleanup()

    def test_sweep_without_declaration_exit_2(self):
        # a sweep folder without technique_results.json (run before nbsim explore wrote it): exit 2 naming the
        # file and what writes it; the other sweeps are still rendered
        for name in ["small", "fidelity"]:
            shutil.copytree(FIXTURE / "sweeps" / name, self.dir / "sweeps" / name)
        (self.dir / "sweeps" / "small" / "technique_results.json").unlink()
        rc, _, err = run_report(self.dir)
        self.assertBroken(rc, err, str(Path("sweeps") / "small" / "technique_results.json"))
        self.assertIn("nbsim explore writes it", err)
        self.assertIn("re-run the sweep", err)
        html = (self.dir / "report" / "index.html").read_text()
        self.assertIn("fidelity_cycles_vs_error.png", html, "the sweep with its declaration is still rendered")
        self.assertNotIn("small_cycles_vs_error.png", html)

    def test_metric_names_come_from_the_declaration(self):
        # a made-up technique with its own names: its columns are plotted, labelled and flagged
        header = ["point_id", "role", "trace", "nbsim_version", "x.y", "status", "cycles_per_frame",
                  "sprite_tests_per_frame", "popping", "sprite_efficiency", "popping_lost", "sprite_memory_bytes"]
        rows = [["a", "sweep", "t.nbt", "0", "1", "ok", "100", "50", "0", "0.9", "0.05", "4096"],
                ["b", "sweep", "t.nbt", "0", "2", "ok", "80", "70", "0", "0.8", "0.15", "2048"],
                ["c", "sweep", "t.nbt", "0", "3", "ok", "60", "90", "2", "0.7", "0.25", "1024"]]
        s = write_sweep(self.dir, "p", header, rows, ["x.y"])
        labels = {"error_axis": "popping lost (points of %)", "error_text": "sprites popping lost (popping_lost)",
                  "error_column": "popping lost (points)", "fallback_axis": "sprites not culled (%)",
                  "fallback_text": "1 - sprite efficiency", "fallback_column": "not culled (%)",
                  "cost_axis": "sprite depth tests per frame", "cost_column": "sprite tests/frame",
                  "cost_pareto": "pareto_sprite_tests", "cost_short": "sprites", "memory_axis": "sprite memory (KiB)",
                  "memory_pareto": "pareto_sprite_memory", "memory_short": "spritemem",
                  "quality_column": "sprite efficiency", "must_be_zero": "popped sprites", "alike": "pops alike"}
        metrics = [{"name": n, "must_be_zero": n == "popping"} for n in
                   ["sprite_tests_per_frame", "popping", "sprite_efficiency", "popping_lost", "sprite_memory_bytes"]]
        (s / "technique_results.json").write_text(json.dumps({"traces": {"t.nbt": "particles"}, "techniques": [{
            "technique": "particles", "metrics": metrics, "headline_cost": "sprite_tests_per_frame",
            "headline_error": "popping_lost", "fallback_error": "sprite_efficiency",
            "memory_cost": "sprite_memory_bytes", "report": labels}], "notes": []}))
        rc, _, err = run_report(self.dir)
        self.assertEqual(rc, 0, err)
        html = (self.dir / "report" / "index.html").read_text()
        for text in ["sprites popping lost (popping_lost)", "sprite tests/frame", "popping lost (points)",
                     "sprite efficiency", "popped sprites", "sprite memory (KiB)"]:
            self.assertIn(text, html, f"the declared label {text!r} is not in the page")
        self.assertNotIn("culling efficiency", html.split("<h2 id=\"sweep-p\">")[1])
        for png in ["p_sprites_vs_error.png", "p_spritemem_vs_error.png", "p_cycles_vs_error.png"]:
            png_size(self.dir / "report" / png)
        with open(self.dir / "report" / "p_pareto.csv") as f:
            pareto = list(csv.DictReader(f))
        self.assertIn("pareto_sprite_tests", pareto[0])
        self.assertEqual([float(r["error_axis"]) for r in pareto], [5.0, 15.0, 25.0], "the error axis is popping_lost in points")
        with open(self.dir / "report" / "p_points.csv") as f:
            points = f.read()
        self.assertIn("sprite_memory_kib", points.splitlines()[0])
        headline = (self.dir / "report" / "headline.md").read_text()
        self.assertIn("| sprite depth tests per frame | sprite memory (KiB) |", headline, "the headline uses the declared words")

    def test_techniques_without_declarations_exit_2(self):
        # every trace of the sweep names a technique without declared results: no axis to plot, clear message
        s = write_sweep(self.dir, "u", ["trace", "status", "cycles_per_frame"], [["t.nbt", "ok", "1"]], [])
        (s / "technique_results.json").write_text(json.dumps({"traces": {"t.nbt": "relief"}, "techniques": [],
                                                              "notes": ["technique 'relief' declares no results"]}))
        rc, _, err = run_report(self.dir)
        self.assertBroken(rc, err, str(Path("sweeps") / "u" / "results.csv"))
        self.assertIn("declare no results", err)
        self.assertIn("technique 'relief'", err)

    def test_incomplete_declaration_exit_2(self):
        # a technique_results.json whose technique lacks the report's labels: exit 2 naming the file
        shutil.copytree(FIXTURE / "sweeps" / "small", self.dir / "sweeps" / "small")
        f = self.dir / "sweeps" / "small" / "technique_results.json"
        j = json.loads(f.read_text())
        del j["techniques"][0]["report"]["cost_axis"]
        f.write_text(json.dumps(j))
        rc, _, err = run_report(self.dir)
        self.assertBroken(rc, err, "technique_results.json")
        self.assertIn("cost_axis", err)

    def assertBroken(self, rc, err, name):
        self.assertEqual(rc, 2, f"{name}: exit 2")
        self.assertIn(name, err, "the message must name the file")
        self.assertNotIn("Traceback", err)


def particle_row(mode, **kw):
    """A particles.json row (nbsim particles --out) of 1,000 16 px sprites; kw overrides."""
    r = {"trace": f"t_{mode}.nbt", "mode": mode, "sprite": "16", "particles_per_frame": 1000.0,
         "paper_depth_tests_per_frame": {"none": 256000.0, "nb": 1000.0}.get(mode), "culled_per_frame": 0.0,
         "query_depth_tests_per_frame": 0.0, "raster_depth_tests_per_frame": 100000.0, "build_texels_per_frame": 0.0,
         "total_depth_tests_per_frame": 100000.0, "cycles_per_frame": 50000.0, "popping": 0, "false_culls": 0,
         "decision_mismatches": 0, "kept_too_large": 0}
    r.update(kw)
    return r


def shadow_row(scene, mode, **kw):
    """A shadows.json row (nbsim shadows --out): 100 casters, 4 frames, no mask pixel differing; kw overrides."""
    fill = {"infinite": 100000.0, "culled": 60000.0, "clamped": 10000.0}[mode]
    r = {"trace": f"{scene}_{mode}.nbt", "scene": scene, "shadow_mode": mode, "litmap_size": "64", "settings": [],
         "frames": 4, "casters_per_frame": 100.0, "culled_per_frame": 50.0, "gl_culled_per_frame": 40.0,
         "outside_per_frame": 5.0, "fill_per_frame": fill, "reference_fill_per_frame": 100000.0,
         "ratio_to_infinite": fill / 100000.0, "build_texels_per_frame": 50000.0, "lookups_per_frame": 500.0,
         "cycles_per_frame": fill / 2, "mask_diff": 0, "mask_diff_infinite": 0, "decision_mismatches": 0}
    r.update(kw)
    return r


class ShadowsReading(unittest.TestCase):
    """The shadows section's reading follows the rows it is given, not fixed text."""

    def reading(self, rows):
        return " ".join(SECTIONS["shadows"].shadows_reading(SECTIONS["shadows"].shadows_rows(rows)))

    def test_ratios_against_the_paper(self):
        # the clamped ratio is compared with the paper's figure of its scene, in either direction
        text = self.reading([shadow_row("city", m) for m in ["infinite", "culled", "clamped"]])
        self.assertIn("city: clamping cuts the fill to 10.0% of the infinite volumes' (the paper: 2.5% (20 M -> 512 K px); "
                      "ours is 4.0 times the paper's)", text)
        self.assertIn("city: culling alone keeps 60.0% of the fill; clamping the volumes that remain takes it to 10.0%", text)
        self.assertIn("fall from 50,000 (infinite) to 5,000 (clamped), 10.0 times fewer", text)
        self.assertIn("build costs 100 to 100 times their lookups (texels a frame): the build dominates", text)
        text = self.reading([shadow_row("boxes", "clamped")])
        self.assertIn("(the paper: ~20%; ours is 2.0 times lower)", text)
        self.assertIn("45.0 of 100 casters culled a frame", text, "GL's culls and the casters outside the light")
        self.assertNotIn("culling alone", text, "no culled row: nothing said about it")

    def test_mask_pixels_differing_are_named(self):
        # a row whose mask differs is named, and the all-clear sentence goes
        text = self.reading([shadow_row("terrain", "infinite"), shadow_row("terrain", "clamped", mask_diff_infinite=3)])
        self.assertIn("MASK PIXELS DIFFERING in terrain clamped (0 from GL's mask, 3 from its infinite reference)", text)
        self.assertNotIn("changed no shadow-mask pixel", text)
        self.assertIn("changed no shadow-mask pixel", self.reading([shadow_row("terrain", "clamped")]))

    def test_ratio_from_the_reference_fill_when_absent(self):
        # a row without ratio_to_infinite takes fill / reference_fill; without either, no ratio sentence
        r = shadow_row("city", "clamped", ratio_to_infinite=None, fill_per_frame=25000.0)
        self.assertIn("clamping cuts the fill to 25.0%", self.reading([r]))
        r = shadow_row("city", "clamped", ratio_to_infinite=None, reference_fill_per_frame=None)
        self.assertNotIn("clamping cuts", self.reading([r]))


def ldi_row(shape, size, **kw):
    """An ldi.json row (nbsim ldi table1 --out): 4,096 points, 96 near a surface; kw overrides."""
    r = {"shape": shape, "ldi_size": size, "vertices": 994, "triangles": 1984, "d_min": 2, "d_max": 4, "layers": 2,
         "direction": 0, "m_crop": 2 * size * size, "m_comp": 3 * size * size, "c_ratio": 1.5, "ms_viewpoint": 120.0,
         "ms_peel": 30.0, "ms_crop": 1.0, "ms_compress": 2.0, "points": 4096, "classified": 4000, "near_surface": 96,
         "misclassified_layers": 40 * 64 // size, "misclassified_ranges": 40 * 64 // size,
         "fetches_per_test_layers": 1.5, "fetches_per_test_ranges": 1.8, "gl_parity_mismatches": 0}
    r.update(kw)
    return r


class LdiReading(unittest.TestCase):
    """The LDI section's reading follows the rows it is given, not fixed text."""

    def reading(self, rows):
        return " ".join(SECTIONS["ldi"].ldi_reading(SECTIONS["ldi"].ldi_rows(rows)))

    def test_rates_and_the_paper(self):
        text = self.reading([ldi_row("sphere", 256), ldi_row("sphere", 64)])
        self.assertIn("Both readers misclassify the same number of points in every row (2 rows)", text)
        self.assertIn("sphere: misclassified 1.00% of its test points at 64² and 0.25% at 256²", text, "sorted by size")
        self.assertIn("C_ratio 1.50 (the paper's Sphere, 994 vertices, d = 2: 1.78)", text)
        self.assertNotIn("the paper's", self.reading([ldi_row("knot", 64)]), "no paper row for the knot")

    def test_disagreements_are_named(self):
        text = self.reading([ldi_row("knot", 128, misclassified_ranges=3), ldi_row("coil", 64, gl_parity_mismatches=7)])
        self.assertIn("THE READERS DISAGREE in knot 128", text)
        self.assertIn("GL AND THE MODEL DISAGREE on coil 64 (7)", text)
        self.assertNotIn("Both readers misclassify", text)


def relief_row(field_size, method, **kw):
    """A relief.json row (nbsim relief --out): the fbm heightfield at field_size, frame 0, 1,000 fragments; kw overrides."""
    r = {"trace": f"fbm_{field_size}.nbt", "field": "fbm:0 seed 5", "field_size": field_size, "frame": 0, "angle": 0.0,
         "method": method, "fragments": 1000, "gl_fragments": 1000, "lookups": 20000, "steps": 3000, "errors": 0,
         "reference_hits": 800, "cycles": 10000, "pixel_mismatches": 0, "walk_mismatches": 0}
    r.update(kw)
    for k, n in (("lookups_per_fragment", "lookups"), ("steps_per_fragment", "steps"), ("error_rate", "errors")):
        r.setdefault(k, r[n] / r["fragments"] if r["fragments"] else None)
    return r


def relief_doc(rows=None, ranking=None, nbuffer_vs_exact=None, paper=None):
    """A relief.json (nbsim relief --out) of exact and nbuffer walks at 32 and 64, by default with the N-buffer walk
    cheaper at 64 and the paper's Table 1 rows at 32 and 64."""
    rows = rows if rows is not None else [relief_row(32, "exact"), relief_row(32, "nbuffer", lookups=25000),
                                          relief_row(64, "exact", lookups=40000, errors=3),
                                          relief_row(64, "nbuffer", lookups=30000)]
    ranking = ranking if ranking is not None else [
        {"method": "nbuffer", "fragments": 2000, "lookups_per_fragment": 27.5, "steps_per_fragment": 3.0,
         "cycles_per_frame": 10000.0, "errors": 0, "error_rate": 0.0, "pareto": True},
        {"method": "exact", "fragments": 2000, "lookups_per_fragment": 30.0, "steps_per_fragment": 3.0,
         "cycles_per_frame": 12000.0, "errors": 3, "error_rate": 0.0015, "pareto": False}]
    nve = nbuffer_vs_exact if nbuffer_vs_exact is not None else [
        {"field": "fbm:0 seed 5", "field_size": 32, "exact_lookups_per_fragment": 20.0,
         "nbuffer_lookups_per_fragment": 25.0, "lookup_ratio": 1.25, "exact_errors": 0, "nbuffer_errors": 0,
         "extra_errors": 0},
        {"field": "fbm:0 seed 5", "field_size": 64, "exact_lookups_per_fragment": 40.0,
         "nbuffer_lookups_per_fragment": 30.0, "lookup_ratio": 0.75, "exact_errors": 3, "nbuffer_errors": 0,
         "extra_errors": -3}]
    paper = paper if paper is not None else [
        {"method": m, "field_size": n, "paper_hz": hz, "cycles_per_frame": c, "lookups_per_fragment": None}
        for m, n, hz, c in [("exact", 32, 115.0, 9000.0), ("robust", 32, 116.0, 9500.0),
                            ("exact", 64, 87.0, 20000.0), ("robust", 64, 105.0, 15000.0),
                            ("exact", 128, 58.0, None), ("robust", 128, 97.0, None)]]
    return {"settings": [], "rows": rows, "ranking": ranking, "nbuffer_vs_exact": nve, "paper": paper}


class ReliefReading(unittest.TestCase):
    """The relief section's reading follows relief.json, not fixed text."""

    def reading(self, doc):
        return " ".join(SECTIONS["relief"].relief_reading(doc, SECTIONS["relief"].relief_ranking(doc),
                                                   SECTIONS["relief"].relief_paper_rows(doc["paper"])))

    def test_front_nbuffer_against_exact_and_the_paper(self):
        # the front, the N-buffer walk's lookups and errors per heightfield, and the two rankings per size
        text = self.reading(relief_doc())
        self.assertIn("The model's walks and pixels are GL's in every row (4 rows: 2 traces, 1 view angles, 2 methods)", text)
        self.assertIn("Pareto front of cycles per box draw against hit error: nbuffer (10,000 cycles, 0.000% hit errors). "
                      "Cheapest: nbuffer; dearest: exact (12,000 cycles, 1.20 times).", text)
        self.assertIn("fewer lookups per fragment than the exact walk on 1 of 2 heightfields (N-buffer / exact 0.75 to "
                      "1.25; more on fbm:0 seed 5 at 32²), with 0 extra hit errors on any of them (N-buffer 0 errors, "
                      "exact 3)", text)
        self.assertIn("At 32², the paper: robust, exact (116, 115 Hz); ours: exact, robust (9,000, 9,500 cycles); "
                      "another order.", text)
        self.assertIn("At 64², the paper: robust, exact (105, 87 Hz); ours: robust, exact (15,000, 20,000 cycles); "
                      "the same order.", text)
        self.assertIn("No fbm rows of ours at 128²", text)

    def test_extra_errors_are_named(self):
        # an N-buffer walk with more hit errors than the exact walk on a heightfield: said, with how many
        doc = relief_doc()
        doc["nbuffer_vs_exact"][1].update(nbuffer_errors=7, extra_errors=4)
        text = self.reading(doc)
        self.assertIn("with extra hit errors on 1: fbm:0 seed 5 at 64² (+4)", text)
        self.assertNotIn("0 extra hit errors", text)

    def test_disagreements_with_gl_are_loud(self):
        # walks, pixels or fragment counts unlike GL's are named, and the all-clear sentence goes
        doc = relief_doc()
        doc["rows"][1].update(walk_mismatches=12)
        doc["rows"][2].update(pixel_mismatches=3, gl_fragments=999)
        text = self.reading(doc)
        self.assertIn("GL AND THE MODEL DISAGREE: walks differing from GL's in 1 row (fbm_32 frame 0 nbuffer: 12); "
                      "pixels differing from GL's in 1 row (fbm_64 frame 0 exact: 3); fragment counts unlike GL's in "
                      "1 row (fbm_64 frame 0 exact: 1,000 against 999)", text)
        self.assertNotIn("walks and pixels are GL's", text)
        ranking = {r["method"]: r for r in SECTIONS["relief"].relief_ranking(doc)}
        self.assertEqual((ranking["nbuffer"]["walk_mismatches"], ranking["exact"]["pixel_mismatches"]), (12, 3))


class ParticlesReading(unittest.TestCase):
    """The particles section's reading follows the rows it is given, not fixed text."""

    def reading(self, rows):
        return " ".join(SECTIONS["particles"].particles_reading(SECTIONS["particles"].particles_rows(rows)))

    def test_build_cheaper_than_the_culling_saves(self):
        # nb culls half the fragments with a small build: its build costs less than it saves, and it is cheapest
        nb = particle_row("nb", culled_per_frame=500.0, query_depth_tests_per_frame=1200.0,
                          raster_depth_tests_per_frame=50000.0, build_texels_per_frame=10000.0,
                          total_depth_tests_per_frame=61200.0)
        text = self.reading([particle_row("none"), nb])
        self.assertIn("1.20 per sprite", text)
        self.assertIn("83 times fewer", text, "100,000 raster depth tests over 1,200 queries")
        self.assertIn("The build in nb (10,000 texels a frame, 16% of its total) costs less than its culling saves",
                      text)
        self.assertIn("Fewest depth tests in total (queries + sprite fragments + N-buffer or Hi-Z build): nb", text)
        self.assertIn("No mode pops or culls a visible sprite (none and nb)", text)

    def test_build_dearer_than_the_culling_saves_and_popping_named(self):
        # a big build, and center popping: both said, the cheapest non-popping culling mode named
        nb = particle_row("nb", culled_per_frame=500.0, query_depth_tests_per_frame=1200.0,
                          raster_depth_tests_per_frame=50000.0, build_texels_per_frame=90000.0,
                          total_depth_tests_per_frame=141200.0)
        center = particle_row("center", culled_per_frame=700.0, query_depth_tests_per_frame=1000.0,
                              raster_depth_tests_per_frame=30000.0, total_depth_tests_per_frame=31000.0,
                              popping=1234, false_culls=1234)
        text = self.reading([nb, center, particle_row("none")])
        self.assertIn("costs more than its culling saves", text)
        self.assertIn("its total is 1.41 times none's", text)
        self.assertIn("Popping (sprites culled while GL's reference pass shows them, over every frame): center 1,234; "
                      "0 in none and nb", text)
        self.assertIn(": center (31,000 a frame); of the culling modes that never pop, nb (141,200)", text)
        self.assertNotIn("FALSE CULLS", text, "center's false culls are its popping, by design")

    def test_false_culls_in_a_conservative_mode_and_no_none_row(self):
        # nb alone with false culls: flagged; no comparison with rasterization without a none row
        text = self.reading([particle_row("nb", query_depth_tests_per_frame=900.0, false_culls=3)])
        self.assertIn("FALSE CULLS in nb", text)
        self.assertNotIn("times fewer", text)
        self.assertNotIn("Rasterizing every sprite", text)

    def test_one_mode_alone(self):
        # the demo's sample is nb alone: no comparison between modes, its build share still said
        text = self.reading([particle_row("nb", query_depth_tests_per_frame=900.0, build_texels_per_frame=100000.0,
                                          total_depth_tests_per_frame=200900.0)])
        self.assertIn("Mode nb neither pops nor culls a visible sprite.", text)
        self.assertNotIn("Fewest", text, "one mode is compared with nothing")
        self.assertIn("The build in nb is 100,000 texels a frame, 50% of its total depth tests", text)

    def test_sprite_sizes_read_apart(self):
        # rows of two sprite sizes are read per size; the paper's claim only for 16 px
        text = self.reading([particle_row("nb", query_depth_tests_per_frame=900.0),
                             particle_row("nb", sprite="atten", paper_depth_tests_per_frame=None,
                                          query_depth_tests_per_frame=700.0)])
        self.assertIn("[16 px sprites] The N-buffer (nb) reads 900 texels a frame for 1,000 sprites, 0.90 per sprite "
                      "(the paper's claim", text)
        self.assertIn("[atten sprites] The N-buffer (nb) reads 700 texels a frame for 1,000 sprites, 0.70 per "
                      "sprite.", text)


class MissingAndBroken(unittest.TestCase):
    """Missing inputs are named in the page; malformed ones exit 2 naming the file, without a traceback."""

    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = Path(self.tmp.name)

    def tearDown(self):
        self.tmp.cleanup()

    def test_missing_inputs_are_reported(self):
        # only Table 1 present: exit 0, the page names what the other sections lacked
        shutil.copy(FIXTURE / "table1.jsonl", self.dir)
        rc, out, err = run_report(self.dir)
        self.assertEqual(rc, 0, err)
        html = (self.dir / "report" / "index.html").read_text()
        self.assertIn("Table 1: N-buffer build cost", html)
        for missing in ["figure4_map.csv", "table2/table2.json", "sweeps/NAME/results.csv", "particles/particles.json",
                        "shadows/shadows.json", "ldi/ldi.json", "relief/relief.json", "apps/table2.json"]:
            self.assertIn(missing, html, f"the page does not say {missing} is missing")
        self.assertIn("missing inputs", out)

    def test_walkthrough_without_table2_json(self):
        # run.json files alone still give the walkthrough plot; Table 2 is reported missing
        shutil.copytree(FIXTURE / "table2", self.dir / "table2")
        (self.dir / "table2" / "table2.json").unlink()
        rc, _, err = run_report(self.dir)
        self.assertEqual(rc, 0, err)
        html = (self.dir / "report" / "index.html").read_text()
        self.assertIn("walkthrough.png", html)
        self.assertIn("table2/table2.json", html)

    def test_empty_and_absent_dir_exit_2(self):
        # nothing usable, or no folder at all: exit 2 with a message
        rc, _, err = run_report(self.dir)
        self.assertEqual(rc, 2)
        self.assertIn("nothing usable", err)
        rc, _, err = run_report(self.dir / "nope")
        self.assertEqual(rc, 2)
        self.assertIn("no such folder", err)

    def assertBroken(self, rc, err, name):
        self.assertEqual(rc, 2, f"a malformed {name} must exit 2")
        self.assertIn(name, err, "the message must name the file")
        self.assertNotIn("Traceback", err)

    def test_bad_results_csv_header(self):
        # a results.csv without the columns of nbsim explore: exit 2, file named, other sections still written
        shutil.copytree(FIXTURE, self.dir / "out")
        (self.dir / "out" / "sweeps" / "small" / "results.csv").write_text("foo,bar\n1,2\n")
        rc, _, err = run_report(self.dir / "out")
        self.assertBroken(rc, err, "sweeps/small/results.csv")
        self.assertIn("trace", err, "the message should say which column is missing")
        self.assertTrue((self.dir / "out" / "report" / "table1.png").exists(), "the other sections are still rendered")

    def test_ragged_and_non_numeric_results_csv(self):
        # a short row, then a non-number in a metric column
        header = ["point_id", "trace", "nbsim_version", "x.y", "status", "cycles_per_frame", "culling_efficiency"]
        s = write_sweep(self.dir, "r", header, [["a", "t.nbt", "0", "1", "ok", "10", "0.5"], ["b", "t.nbt"]], ["x.y"])
        rc, _, err = run_report(self.dir)
        self.assertBroken(rc, err, str(Path("sweeps") / "r" / "results.csv"))
        self.assertIn("line 3", err)
        with open(s / "results.csv", "w") as f:
            f.write(",".join(header) + "\na,t.nbt,0,1,ok,fast,0.5\n")
        rc, _, err = run_report(self.dir)
        self.assertBroken(rc, err, "results.csv")
        self.assertIn("cycles_per_frame", err)

    def test_broken_json(self):
        # table2.json and sweep.json that are not JSON
        shutil.copytree(FIXTURE / "table2", self.dir / "table2")
        (self.dir / "table2" / "table2.json").write_text('{"rows": [')
        rc, _, err = run_report(self.dir)
        self.assertBroken(rc, err, "table2.json")
        shutil.rmtree(self.dir / "table2")
        s = write_sweep(self.dir, "s", ["trace", "status", "cycles_per_frame", "culling_efficiency"],
                        [["t", "ok", "1", "0.5"]], [])
        (s / "sweep.json").write_text("not json")
        rc, _, err = run_report(self.dir)
        self.assertBroken(rc, err, "sweep.json")

    def test_bad_table1_and_coverage(self):
        # a broken Table 1 file and a coverage CSV without its columns
        (self.dir / "table1.jsonl").write_text('{"bench": "build", "size": \n')
        (self.dir / "figure4_map.csv").write_text("a,b\n1,2\n")
        rc, _, err = run_report(self.dir)
        self.assertBroken(rc, err, "table1.jsonl")
        self.assertIn("figure4_map.csv", err)

    def test_particles_json_of_nbsim_particles_out_dir(self):
        # DIR/particles.json (nbsim particles --out DIR) renders alone; a malformed one exits 2 naming the file
        (self.dir / "particles.json").write_text(json.dumps([particle_row("none"), particle_row("nb")]))
        rc, out, err = run_report(self.dir)
        self.assertEqual(rc, 0, err)
        self.assertIn("1 sections", out)
        self.assertIn("Particles (t_none, t_nb)", (self.dir / "report" / "headline.md").read_text())
        html_text = (self.dir / "report" / "index.html").read_text()
        self.assertIn("their settings are not recorded there", html_text, "a particles.json without settings says so")
        # rows with their settings and a replay in another mode than the capture's say both
        (self.dir / "particles.json").write_text(json.dumps([
            particle_row("none", settings=[]),
            particle_row("nb", trace="t_none.nbt", capture_mode="none", settings=["particles.mode=nb", "nbuffer.format=u16"])]))
        rc, out, err = run_report(self.dir)
        self.assertEqual(rc, 0, err)
        html_text = (self.dir / "report" / "index.html").read_text()
        self.assertIn("--set nbuffer.format=u16 --set particles.mode=nb", html_text)
        self.assertIn("t_none captured in none", html_text)
        for bad, says in [("[]", "non-empty JSON list"), ('{"rows": []}', "non-empty JSON list"),
                          (json.dumps([{"mode": "nb"}]), "lacks particles_per_frame"),
                          (json.dumps([particle_row("nb", popping="many")]), "rows[0].popping is not a number"),
                          (json.dumps([particle_row("nb", particles_per_frame=0)]), "particles_per_frame must be above 0"),
                          ("[{", "broken JSON")]:
            (self.dir / "particles.json").write_text(bad)
            rc, _, err = run_report(self.dir)
            self.assertBroken(rc, err, "particles.json")
            self.assertIn(says, err, bad)

    def test_shadows_json_of_nbsim_shadows_out_dir(self):
        # DIR/shadows.json (nbsim shadows --out DIR) renders alone; a malformed one exits 2 naming the file
        (self.dir / "shadows.json").write_text(json.dumps([shadow_row("boxes", "infinite"), shadow_row("boxes", "clamped")]))
        rc, out, err = run_report(self.dir)
        self.assertEqual(rc, 0, err)
        self.assertIn("1 sections", out)
        self.assertIn("Shadows (boxes_infinite, boxes_clamped)", (self.dir / "report" / "headline.md").read_text())
        self.assertIn("the model's default settings", (self.dir / "report" / "index.html").read_text())
        for bad, says in [("[]", "non-empty JSON list"), ('{"rows": []}', "non-empty JSON list"),
                          (json.dumps([{"scene": "city"}]), "lacks shadow_mode"),
                          (json.dumps([shadow_row("city", "clamped", mask_diff="none")]), "rows[0].mask_diff is not a number"),
                          (json.dumps([shadow_row("city", "clamped", shadow_mode=3)]), "rows[0].shadow_mode is not a string"),
                          (json.dumps([shadow_row("city", "clamped", frames=0)]), "frames must be above 0"),
                          ("[{", "broken JSON")]:
            (self.dir / "shadows.json").write_text(bad)
            rc, _, err = run_report(self.dir)
            self.assertBroken(rc, err, "shadows.json")
            self.assertIn(says, err, bad)

    def test_ldi_json_of_nbsim_ldi_out_dir(self):
        # DIR/ldi.json (nbsim ldi table1 --out DIR) renders alone with its plot; a malformed one exits 2 naming the file
        (self.dir / "ldi.json").write_text(json.dumps([ldi_row("sphere", 64), ldi_row("sphere", 128), ldi_row("knot", 64)]))
        rc, out, err = run_report(self.dir)
        self.assertEqual(rc, 0, err)
        self.assertIn("1 sections", out)
        self.assertIn("Layered depth images (2 shapes, 3 LDIs)", (self.dir / "report" / "headline.md").read_text())
        png_size(self.dir / "report" / "ldi.png")
        with open(self.dir / "report" / "ldi.csv") as f:
            self.assertEqual(len(list(csv.DictReader(f))), 3)
        for bad, says in [("[]", "non-empty JSON list"), (json.dumps([{"shape": "sphere"}]), "lacks ldi_size"),
                          (json.dumps([ldi_row("sphere", 64, m_crop="big")]), "rows[0].m_crop is not a number"),
                          (json.dumps([ldi_row("sphere", 64, classified=5000)]), "classified within [0, points]"),
                          (json.dumps([ldi_row("sphere", 64, misclassified_layers=4001)]), "more points misclassified"),
                          ("[{", "broken JSON")]:
            (self.dir / "ldi.json").write_text(bad)
            rc, _, err = run_report(self.dir)
            self.assertBroken(rc, err, "ldi.json")
            self.assertIn(says, err, bad)

    def test_relief_json_of_nbsim_relief_out_dir(self):
        # DIR/relief.json (nbsim relief --out DIR) renders alone with its plot; a malformed one exits 2 naming the
        # file and the row
        good = relief_doc()
        (self.dir / "relief.json").write_text(json.dumps(good))
        rc, out, err = run_report(self.dir)
        self.assertEqual(rc, 0, err)
        self.assertIn("1 sections", out)
        self.assertIn("Relief textures (2 traces: 1 heightfields at 32² and 64², 1 view angles each)",
                      (self.dir / "report" / "headline.md").read_text())
        png_size(self.dir / "report" / "relief.png")

        def broken(change):
            d = json.loads(json.dumps(good))
            change(d)
            return json.dumps(d)
        for bad, says in [
                (broken(lambda d: d["rows"][0].pop("method")), "rows[0] lacks method"),
                (broken(lambda d: d["rows"][1].update(lookups=-5)), "rows[1].lookups must be a count"),
                (broken(lambda d: d["rows"][0].update(cycles=1.5)), "rows[0].cycles must be a count"),
                (broken(lambda d: d["rows"][0].update(errors=10 ** 6)), "rows[0]: errors and reference_hits"),
                (broken(lambda d: d["rows"][0].update(lookups_per_fragment="many")),
                 "rows[0].lookups_per_fragment is not a number"),
                (broken(lambda d: d["ranking"][0].update(errors=-1)), "ranking[0].errors must be a count"),
                (broken(lambda d: d["ranking"][1].update(pareto="yes")), "ranking[1].pareto is not true or false"),
                (broken(lambda d: d["ranking"][0].update(cycles_per_frame=None)), "ranking[0]: cycles_per_frame and error_rate"),
                (broken(lambda d: d["nbuffer_vs_exact"][0].update(nbuffer_errors=-2)),
                 "nbuffer_vs_exact[0].nbuffer_errors must be a count"),
                (broken(lambda d: d["paper"][0].update(paper_hz=0)), "paper[0].paper_hz must be above 0"),
                (broken(lambda d: d["paper"][0].update(method=3)), "paper[0].method is not a string"),
                (broken(lambda d: d.pop("paper")), "lacks paper"),
                (broken(lambda d: d.update(rows=[])), "rows is not a non-empty list"),
                (broken(lambda d: d.update(settings="x")), "settings is not a list of strings"),
                ("[]", "expected an object"), ('{"rows": [', "broken JSON")]:
            (self.dir / "relief.json").write_text(bad)
            rc, _, err = run_report(self.dir)
            self.assertBroken(rc, err, "relief.json")
            self.assertIn(says, err, bad)

    def test_help(self):
        # --help works and describes the inputs
        p = subprocess.run([PYTHON, str(SCRIPT), "--help"], capture_output=True, text=True, timeout=60)
        self.assertEqual(p.returncode, 0)
        self.assertIn("results.csv", p.stdout)


class Table1Input(unittest.TestCase):
    def test_reads_lines_and_the_json_out_array(self):
        # nbsim bench prints JSON lines; --json-out writes one array: both give the same rows
        import io
        objs = [{"bench": "build", "size": "256x256", "levels": 8, "build_ms": 0.1, "copy_ms": 0.05, "ratio": 2.0},
                {"bench": "query", "size": "256x256"}]
        lines = table1.read_rows(io.StringIO("\n".join(json.dumps(o) for o in objs)))
        array = table1.read_rows(io.StringIO(json.dumps(objs, indent=2)))
        self.assertEqual(lines, array)
        self.assertEqual(len(array), 1)
        self.assertEqual(table1.table_rows(array)[0]["paper_ms_2005_gpu"], 2.0)

    def test_update_rows_and_their_rate(self):
        # update lines are read apart from build lines; texels_per_s is taken as given, or derived when absent
        import io
        objs = [{"bench": "build", "size": "256x256", "levels": 8, "build_ms": 0.1, "copy_ms": 0.05, "ratio": 2.0},
                {"bench": "update", "size": "1024x1024", "dirty": "8x8", "update_ms": 0.002, "rebuild_ms": 2.0,
                 "ratio": 0.001, "texels_recomputed": 500, "texels_per_s": 250000000},
                {"bench": "update", "size": "1024x1024", "dirty": "1x1", "update_ms": 0.0001, "rebuild_ms": 2.0,
                 "ratio": 0.00005, "texels_recomputed": 5}]
        text = "\n".join(json.dumps(o) for o in objs)
        self.assertEqual(len(table1.read_rows(io.StringIO(text))), 1, "update lines are not build rows")
        u = table1.update_table_rows(table1.read_update_rows(io.StringIO(text)))
        self.assertEqual([r["dirty"] for r in u], ["8x8", "1x1"])
        self.assertEqual(u[0]["texels_per_s"], 250000000.0)
        self.assertAlmostEqual(u[1]["texels_per_s"], 5 / 0.0001e-3, delta=1.0, msg="derived: texels / update seconds")
        with self.assertRaises(ValueError):
            table1.update_table_rows([{"bench": "update", "size": "1x1", "dirty": "1x1", "update_ms": "x"}])

    def test_report_shows_update_table_when_present(self):
        # table1.jsonl with update lines (--only build,update): the Table 1 section adds the update table and its CSV
        with tempfile.TemporaryDirectory() as tmp:
            d = Path(tmp)
            lines = [json.dumps(o) for o in json.loads((FIXTURE / "table1.jsonl").read_text())]
            lines.append(json.dumps({"bench": "update", "size": "1024x1024", "dirty": "64x64", "update_ms": 0.03,
                                     "rebuild_ms": 3.0, "ratio": 0.01, "texels_recomputed": 41471,
                                     "texels_per_s": 1382000000}))
            (d / "table1.jsonl").write_text("\n".join(lines) + "\n")
            rc, _, err = run_report(d)
            self.assertEqual(rc, 0, err)
            html = (d / "report" / "index.html").read_text()
            self.assertIn("texels/s", html)
            self.assertIn("1382 M", html, "the update's rate in millions of texels per second")
            rows = (d / "report" / "table1_update.csv").read_text().splitlines()
            self.assertEqual(rows[0].split(",")[:2], ["size", "dirty"])
            self.assertEqual(len(rows), 2, "one row per update line")


if __name__ == "__main__":
    unittest.main()
