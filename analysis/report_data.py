"""The data side of nbsim's exploration report (report.py): reading the CSV/JSON outputs, point labels,
Pareto marks, and the Markdown headline. No plotting here: report_plots.py has that.
"""
import csv
import json
import math
import os

MODE_ORDER = ["oq_hier", "oq", "nb_hier", "nb", "hiz_tile", "hiz_pyramid"]
# The paper's ratios of depth tests per frame (Table 2: 200 000 / 500 and 1 100 000 / 350).
RATIO_PAIRS = [("oq", "nb"), ("oq_hier", "nb_hier")]
# Knobs that change how closely the model follows llvmpipe, not the design under study.
FIDELITY_KNOBS = ["geometry.batch_triangles", "geometry.fused_viewport", "depth.fused_interpolation",
                  "gpu.quantum_cycles", "gpu.fifo_depth"]
# Short names for point labels; "" shows the value alone (it names itself: nb_hier, u16, eager).
SHORT = {
    "cull.mode": "", "nbuffer.format": "", "nbuffer.update_policy": "", "cull.granularity": "",
    "nbuffer.resolution_divisor": "div", "nbuffer.level_cap": "cap", "nbuffer.capped_max_lookups": "maxlk",
    "nbuffer.cache_size_bytes": "nb$", "depth.cache_size_bytes": "z$", "nbuffer.lookup_latency_cycles": "lat",
    "nbuffer.lookups_per_cycle": "lk/c", "geometry.batch_triangles": "batch", "geometry.fused_viewport": "fma-vp",
    "depth.fused_interpolation": "fma-z", "gpu.fifo_depth": "fifo", "gpu.quantum_cycles": "quantum",
    "hiz.tile_px": "tile", "hiz.format": "hiz",
}
# The technique-independent sweep columns the report reads as numbers (when present); each
# technique's declared metrics (technique_results.json) are read as numbers too.
NUMERIC = ["cycles_per_frame", "depth_tests_per_frame", "memory_bytes_per_frame", "nbuffer_bytes_per_frame",
           "fragment_error", "passed_error", "host_seconds", "cycles_per_host_second", "cycle_error", "counter_error"]
# The declared results of occlusion culling as nbsim wrote them before technique_results.json
# existed (pipeline/techniques/results.cpp holds the declaration; only what the report reads is
# here): a sweep folder without that file is read with these. AnalysisTest checks that they agree
# with the file nbsim explore writes.
LEGACY_TECHNIQUE = {
    "technique": "occlusion_culling",
    "metrics": [{"name": n, "must_be_zero": n == "false_culls"} for n in (
        "query_depth_tests_per_frame", "update_texels_per_frame", "total_depth_tests_per_frame", "false_culls",
        "culling_efficiency", "culled", "candidates_not_visible", "max_lookups_per_test", "nbuffer_memory_bytes",
        "structure_memory_bytes", "efficiency_lost")],
    "headline_cost": "total_depth_tests_per_frame",
    "headline_error": "efficiency_lost",
    "fallback_error": "culling_efficiency",
    "memory_cost": "nbuffer_memory_bytes",
    "report": {
        "error_axis": "culling efficiency lost vs full-res f32 N-buffer (points of %)",
        "error_text": "culling efficiency lost against the full-resolution float32 N-buffer (efficiency_lost)",
        "error_column": "efficiency lost (points)",
        "fallback_axis": "hidden objects not culled (%, = 1 - culling efficiency)",
        "fallback_text": "hidden objects left unculled, 1 - culling efficiency (no efficiency_lost column)",
        "fallback_column": "not culled (%)",
        "cost_axis": "total depth tests per frame", "cost_column": "total depth tests/frame",
        "cost_pareto": "pareto_depth_tests", "cost_short": "tests",
        "memory_axis": "N-buffer memory (KiB)", "memory_pareto": "pareto_memory", "memory_short": "memory",
        "quality_column": "culling efficiency", "must_be_zero": "false culls", "alike": "culls alike",
    },
}



class BadInput(Exception):
    """A malformed input; str() starts with the file's path."""


class Missing(Exception):
    """A section's inputs are absent; args[0] lists them (paths relative to DIR)."""


# ----------------------------------------------------------------------------------------- helpers

def fmt(v, digits=4):
    """Numbers for tables: thousands separators, a few significant digits, '-' for nothing."""
    if v is None or v == "" or (isinstance(v, float) and math.isnan(v)):
        return "-"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, int):
        return f"{v:,}"
    if isinstance(v, float):
        if v == int(v) and abs(v) < 1e15:
            return f"{int(v):,}"
        if abs(v) >= 1000:
            return f"{v:,.0f}"
        return f"{v:.{digits}g}"
    return str(v)


def pct(v, digits=1):
    return "-" if v is None else f"{100 * v:.{digits}f}%"


def number(s):
    """A CSV cell as a float, None when empty; ValueError otherwise."""
    s = s.strip()
    if s == "" or s.lower() in ("null", "none", "nan"):
        return None
    return float(s)


def load_json(path):
    try:
        with open(path) as f:
            return json.load(f)
    except json.JSONDecodeError as e:
        raise BadInput(f"{path}: broken JSON: {e}") from e
    except (OSError, UnicodeDecodeError) as e:
        raise BadInput(f"{path}: cannot read: {e}") from e


def read_csv(path, required):
    """Rows of a CSV as dicts; a header without the required columns or a ragged row is a BadInput."""
    try:
        with open(path, newline="") as f:
            reader = csv.DictReader(f)
            header = reader.fieldnames or []
            lacking = [c for c in required if c not in header]
            if lacking:
                raise BadInput(f"{path}: the header lacks column(s) {', '.join(lacking)} "
                               f"(header: {','.join(header)[:200] or 'empty file'})")
            rows = []
            for r in reader:
                if None in r or any(v is None for v in r.values()):
                    raise BadInput(f"{path}: line {reader.line_num} has {len(r) - (None in r) + len(r.get(None) or [])} "
                                   f"fields, the header {len(header)}")
                rows.append(r)
            return header, rows
    except csv.Error as e:
        raise BadInput(f"{path}: not a valid CSV: {e}") from e
    except (OSError, UnicodeDecodeError) as e:
        raise BadInput(f"{path}: cannot read: {e}") from e


def short_value(key, v):
    s = str(v)
    if key.endswith("_bytes"):
        try:
            b = int(float(s))
            return f"{b // 1024}K" if b >= 1024 and b % 1024 == 0 else str(b)
        except ValueError:
            return s
    if s in ("true", "false"):
        return "on" if s == "true" else "off"
    if s.endswith(".0"):
        s = s[:-2]
    return s


def short_label(params, keys):
    """'nb_hier div=2 u16': the values of the given parameters, keys abbreviated. Another N-buffer instance's
    keys (litmap_min.format) take the nbuffer.* abbreviations; a part two instances share is named once."""
    parts = []
    for k in keys:
        abbr = SHORT.get(k, SHORT.get("nbuffer." + k.split(".")[-1], k.split(".")[-1]))
        v = short_value(k, params.get(k, ""))
        if v == "":
            continue
        parts.append(v if abbr == "" else f"{abbr}={v}")
    return " ".join(dict.fromkeys(parts))


def sorted_modes(modes):
    return sorted(modes, key=lambda m: (MODE_ORDER.index(m) if m in MODE_ORDER else len(MODE_ORDER), m))


def trace_name(t):
    return os.path.basename(t).removesuffix(".nbt")


# ---------------------------------------------------------------------------------------- Pareto

def pareto_flags(points):
    """For (cost, error) pairs (None: left out) whether each is Pareto-optimal when minimising both: no
    other point is <= in both and < in one. Equal points do not dominate each other (both stay)."""
    flags = []
    for p in points:
        if p is None:
            flags.append(None)
            continue
        dominated = any(q is not None and q[0] <= p[0] and q[1] <= p[1] and (q[0] < p[0] or q[1] < p[1])
                        for q in points)
        flags.append(not dominated)
    return flags


def mark_pareto(rows, cost, error):
    """Pareto flags per trace (different traces are different scenes): True/False for ok sweep rows
    with both values, None for failed rows, reference rows and rows without the values."""
    flags = [None] * len(rows)
    by_trace = {}
    for i, r in enumerate(rows):
        by_trace.setdefault(r.get("trace", ""), []).append(i)
    for idx in by_trace.values():
        pts = []
        for i in idx:
            r = rows[i]
            c, e = r.get(cost), r.get(error)
            usable = (r.get("status", "ok") == "ok" and r.get("role", "sweep") != "reference"
                      and isinstance(c, float) and isinstance(e, float) and math.isfinite(c) and math.isfinite(e))
            pts.append((c, e) if usable else None)
        for i, f in zip(idx, pareto_flags(pts)):
            flags[i] = f
    return flags


def table2_ratios(rows):
    """Query depth tests per frame of occlusion queries over the N-buffer's, ours beside the paper's."""
    by = {r["mode"]: r for r in rows}
    out = []
    for a, b in RATIO_PAIRS:
        if a in by and b in by:
            qa, qb = by[a].get("query_depth_tests_per_frame"), by[b].get("query_depth_tests_per_frame")
            pa, pb = by[a].get("paper_depth_tests_per_frame"), by[b].get("paper_depth_tests_per_frame")
            out.append({"ratio": f"{a} / {b}", "ours": qa / qb if qa is not None and qb else None,
                        "paper": pa / pb if pa is not None and pb else None})
    return out


# -------------------------------------------------------------------------------------- headline

def headline_table2(t, rows, ratios):
    """Table 2 beside the paper, as Markdown."""
    lines = [f"Table 2 ({trace_name(str(t.get('trace', '?')))}, settings: {', '.join(t.get('settings') or []) or 'defaults'}): "
             "depth tests per frame",
             "",
             "| mode | paper | query depth tests | total depth tests | cycles | culling efficiency | false culls |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        p = r.get("paper_depth_tests_per_frame")
        lines.append(f"| {r['mode']} | {'-' if not p else format(p, ',.0f')} | {r['query_depth_tests_per_frame']:,.0f} | "
                     f"{r['total_depth_tests_per_frame']:,.0f} | {r['cycles_per_frame']:,.0f} | "
                     f"{100 * r['culling_efficiency']:.1f}% | {int(r.get('false_culls') or 0)} |")
    rt = "; ".join(f"{r['ratio']} {r['ours']:,.0f}x (paper {r['paper']:,.0f}x)" for r in ratios
                   if r["ours"] is not None and r["paper"] is not None)
    if rt:
        lines += ["", f"Occlusion queries over N-buffer, query depth tests: {rt}."]
    return "\n".join(lines)


def cell(r, key, spec):
    """A Markdown table cell: r[key] formatted with `spec`, '-' when absent."""
    v = r.get(key)
    return "-" if v is None else format(v, spec)


def technique_results(d, path):
    """The declared results of the technique of sweep folder d's traces (its technique_results.json,
    the first technique that declares any), LEGACY_TECHNIQUE when the folder has no such file, or
    BadInput when its traces' techniques declare no results (no cost or error axis to plot)."""
    f = os.path.join(d, "technique_results.json")
    if not os.path.exists(f):
        return LEGACY_TECHNIQUE
    j = load_json(f)
    if not isinstance(j, dict) or not isinstance(j.get("techniques"), list):
        raise BadInput(f"{f}: expected an object with a \"techniques\" list (nbsim explore)")
    if not j["techniques"]:
        notes = "; ".join(str(n) for n in j.get("notes", [])) or "no technique named"
        raise BadInput(f"{path}: its traces' techniques declare no results, nothing to plot against ({notes})")
    t = j["techniques"][0]
    need = ["metrics", "headline_cost", "headline_error", "fallback_error", "memory_cost", "report"]
    if not isinstance(t, dict) or any(k not in t for k in need):
        raise BadInput(f"{f}: techniques[0] lacks one of {', '.join(need)}")
    if not isinstance(t["metrics"], list) or not all(isinstance(m, dict) and isinstance(m.get("name"), str) for m in t["metrics"]):
        raise BadInput(f"{f}: techniques[0].metrics must be a list of objects with a name")
    labels = LEGACY_TECHNIQUE["report"].keys()
    if not isinstance(t["report"], dict) or any(not isinstance(t["report"].get(k), str) for k in labels):
        raise BadInput(f"{f}: techniques[0].report needs the labels {', '.join(labels)}")
    return t


def kib_key(metric):
    """The row key of a memory metric in KiB: nbuffer_memory_bytes -> nbuffer_memory_kib."""
    return (metric[:-len("_bytes")] if metric.endswith("_bytes") else metric) + "_kib"


def headline_sweep(name, rows, traces, err_label, tech=LEGACY_TECHNIQUE):
    """The Pareto-optimal points of a sweep (cycles per frame against its error), as a Markdown table;
    a sweep whose points all cull alike (a fidelity sweep) gets its cycle error and host time instead.
    tech: the technique's declared results (technique_results)."""
    lab = tech["report"]
    lines = [f"Sweep {name}: Pareto-optimal points, cycles per frame against {err_label}", "",
             f"| trace | point | cycles per frame | error | {lab['cost_axis']} | {lab['memory_axis']} | host s |",
             "|---|---|---:|---:|---:|---:|---:|"]
    alike = []
    for t in traces:
        ok = [r for r in rows if r["trace"] == t and r["status"] == "ok" and r["role"] == "sweep"]
        errs = {r["error_axis"] for r in ok if r.get("error_axis") is not None}
        if ok and len(errs) <= 1:  # no culling trade-off here: timing error and speed instead
            ce = [abs(r["cycle_error"]) for r in ok if r.get("cycle_error") is not None]
            hs = [r["host_seconds"] for r in ok if r.get("host_seconds") is not None]
            alike.append(f"- {trace_name(t)}: every point {lab['alike']}; cycles per frame "
                         f"{min(r['cycles_per_frame'] for r in ok):,.0f} to {max(r['cycles_per_frame'] for r in ok):,.0f}"
                         + (f", largest |cycle error| {max(ce):.3%}" if ce else "")
                         + (f", host {min(hs):.2f} to {max(hs):.2f} s" if hs else ""))
            continue
        front = sorted((r for r in rows if r["trace"] == t and r.get("pareto")), key=lambda r: r["cycles_per_frame"])
        for r in front:
            lines.append(f"| {trace_name(t)} | {r['label']} | {cell(r, 'cycles_per_frame', ',.0f')} | "
                         f"{cell(r, 'error_axis', '.2f')} | {cell(r, tech['headline_cost'], ',.0f')} | "
                         f"{cell(r, kib_key(tech['memory_cost']), ',.0f')} | {cell(r, 'host_seconds', '.2f')} |")
    if len(lines) == 4:  # no front anywhere: the fidelity summary alone
        lines = lines[:2]
    elif alike:
        lines.append("")
    return "\n".join(lines + alike)


# ------------------------------------------------------------------------------------- particles

PARTICLE_MODES = ["none", "center", "nb", "hiz"]
# What a row of particles.json (nbsim particles --out) must hold for the report's table and reading.
PARTICLE_NEED = ["mode", "particles_per_frame", "culled_per_frame", "query_depth_tests_per_frame",
                 "raster_depth_tests_per_frame", "build_texels_per_frame", "total_depth_tests_per_frame",
                 "cycles_per_frame", "popping", "false_culls"]
# The paper's claim (Décoret 2005, 3.2 and 4.3) for 16 px sprites: rasterizing them costs 256 N depth
# tests, the N-buffer N (one lookup each); nbsim particles writes it as paper_depth_tests_per_frame.
PAPER_RASTER_PER_SPRITE = 256


def load_rows(path, command, need, strings, numbers):
    """The rows of a table a technique command writes with --out (a non-empty JSON list of objects), each
    with the keys `need`, `strings` of them strings and `numbers` (when present and not null) numbers;
    BadInput naming the file otherwise."""
    t = load_json(path)
    if not isinstance(t, list) or not t:
        raise BadInput(f"{path}: expected a non-empty JSON list of rows ({command} --out)")
    return check_rows(path, "rows", t, need, strings, numbers)


def check_rows(path, name, t, need, strings, numbers, counts=()):
    """The list `name` of the file `path`: objects with the keys `need`, `strings` of them strings, `numbers`
    (when present and not null) numbers and `counts` whole numbers not below 0; BadInput naming the file
    and the row otherwise."""
    for i, r in enumerate(t):
        if not isinstance(r, dict):
            raise BadInput(f"{path}: {name}[{i}] is not an object")
        lacking = [k for k in need if k not in r]
        if lacking:
            raise BadInput(f"{path}: {name}[{i}] lacks {', '.join(lacking)}")
        for k in strings:
            if not isinstance(r[k], str):
                raise BadInput(f"{path}: {name}[{i}].{k} is not a string: {r[k]!r}")
        for k in numbers:
            v = r.get(k)
            if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float))):
                raise BadInput(f"{path}: {name}[{i}].{k} is not a number: {v!r}")
        for k in counts:
            v = r[k]
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v < 0 or v != int(v):
                raise BadInput(f"{path}: {name}[{i}].{k} must be a count (a whole number not below 0), not {v!r}")
    return t


def load_particles(path):
    """The rows of particles.json (a JSON list, one object per replayed trace), checked; BadInput otherwise."""
    t = load_rows(path, "nbsim particles", PARTICLE_NEED, ["mode"],
                  PARTICLE_NEED[1:] + ["paper_depth_tests_per_frame", "decision_mismatches", "kept_too_large"])
    for i, r in enumerate(t):
        if r["particles_per_frame"] <= 0:
            raise BadInput(f"{path}: rows[{i}].particles_per_frame must be above 0, not {r['particles_per_frame']!r}")
    return t


def particles_rows(rows):
    """The rows in mode order (none, center, nb, hiz, then others), each with ours_over_paper: the count the
    paper's claim is about (nb: query depth tests; none: total, all rasterization) over the claim."""
    out = []
    for r in sorted(rows, key=lambda r: (str(r.get("sprite", "")),
                                         PARTICLE_MODES.index(r["mode"]) if r["mode"] in PARTICLE_MODES else 99)):
        rr = dict(r)
        p = r.get("paper_depth_tests_per_frame")
        ours = r["query_depth_tests_per_frame"] if r["mode"] == "nb" else r["total_depth_tests_per_frame"]
        rr["ours_over_paper"] = ours / p if p else None
        out.append(rr)
    return out


def _modes(names):
    return ", ".join(names[:-1]) + " and " + names[-1] if len(names) > 1 else names[0]


def particles_reading(rows):
    """What the particles table shows, as plain sentences computed from its rows (one group per sprite size)."""
    groups = {}
    for r in rows:
        groups.setdefault(str(r.get("sprite", "")), []).append(r)
    out = []
    for sprite, g in groups.items():
        pre = "" if len(groups) == 1 else f"[{sprite or '?'}{' px' if sprite.isdigit() else ''} sprites] "
        by = {}
        for r in g:
            by.setdefault(r["mode"], r)  # the first row of a mode speaks for it
        nb, none = by.get("nb"), by.get("none")
        if nb:
            n, q = nb["particles_per_frame"], nb["query_depth_tests_per_frame"]
            claim = " (the paper's claim: N, one per sprite)" if nb.get("paper_depth_tests_per_frame") else ""
            out.append(f"{pre}The N-buffer (nb) reads {q:,.0f} texels a frame for {n:,.0f} sprites, "
                       f"{q / n:.2f} per sprite{claim}.")
        if none:
            n, t = none["particles_per_frame"], none["total_depth_tests_per_frame"]
            paper = none.get("paper_depth_tests_per_frame")
            out.append(f"{pre}Rasterizing every sprite (none) costs {t:,.0f} depth tests a frame, {t / n:,.0f} per sprite"
                       + (f": {t / paper:.0%} of the paper's {PAPER_RASTER_PER_SPRITE} N (sprites wholly or partly "
                          "off-screen have fewer fragments)" if paper else "") + ".")
        if nb and none and nb["query_depth_tests_per_frame"] > 0:
            ratio = none["total_depth_tests_per_frame"] / nb["query_depth_tests_per_frame"]
            out.append(f"{pre}The N-buffer's queries are {ratio:,.0f} times fewer depth tests than rasterizing every "
                       f"sprite (the paper: {PAPER_RASTER_PER_SPRITE} times for 16 px sprites).")
        culls = [f"{m} {r['culled_per_frame']:,.0f} ({r['culled_per_frame'] / r['particles_per_frame']:.1%})"
                 for m, r in by.items() if r["culled_per_frame"] > 0]
        if culls:
            out.append(f"{pre}Sprites culled a frame: {', '.join(culls)}.")
        pops = [m for m, r in by.items() if r["popping"] > 0]
        clean = [m for m, r in by.items() if r["popping"] == 0 and r["false_culls"] == 0]
        if pops:
            out.append(f"{pre}Popping (sprites culled while GL's reference pass shows them, over every frame): "
                       + ", ".join(f"{m} {by[m]['popping']:,.0f}" for m in pops)
                       + (f"; 0 in {_modes(clean)}" if clean else "") + ".")
        elif len(clean) == 1:
            out.append(f"{pre}Mode {clean[0]} neither pops nor culls a visible sprite.")
        elif clean:
            out.append(f"{pre}No mode pops or culls a visible sprite ({_modes(clean)}).")
        unsafe = [m for m, r in by.items() if r["false_culls"] > 0 and m != "center"]
        if unsafe:
            out.append(f"{pre}FALSE CULLS in {_modes(unsafe)}: a conservative test must have none.")
        if len(by) > 1:
            cheapest = min(by.values(), key=lambda r: r["total_depth_tests_per_frame"])
            safe = [r for r in by.values() if r["popping"] == 0 and r["false_culls"] == 0 and r["mode"] != "none"]
            s = (f"{pre}Fewest depth tests in total (queries + sprite fragments + N-buffer or Hi-Z build): "
                 f"{cheapest['mode']} ({cheapest['total_depth_tests_per_frame']:,.0f} a frame)")
            if safe and cheapest not in safe:
                best = min(safe, key=lambda r: r["total_depth_tests_per_frame"])
                s += f"; of the culling modes that never pop, {best['mode']} ({best['total_depth_tests_per_frame']:,.0f})"
            fastest = min(by.values(), key=lambda r: r["cycles_per_frame"])
            out.append(s + f"; fewest cycles: {fastest['mode']} ({fastest['cycles_per_frame']:,.0f} a frame).")
        for m in ("nb", "hiz"):
            r = by.get(m)
            if not r or r["build_texels_per_frame"] <= 0:
                continue
            if not none:
                out.append(f"{pre}The build in {m} is {r['build_texels_per_frame']:,.0f} texels a frame, "
                           f"{r['build_texels_per_frame'] / r['total_depth_tests_per_frame']:.0%} of its total depth "
                           "tests (no none row here to weigh it against what culling saves).")
                continue
            saved = none["raster_depth_tests_per_frame"] - r["raster_depth_tests_per_frame"]
            b = r["build_texels_per_frame"]
            verdict = "more than" if b > saved else "less than"
            out.append(f"{pre}The build in {m} ({b:,.0f} texels a frame, {b / r['total_depth_tests_per_frame']:.0%} of its "
                       f"total) costs {verdict} its culling saves in sprite fragments ({saved:,.0f} against none): "
                       f"its total is {r['total_depth_tests_per_frame'] / none['total_depth_tests_per_frame']:.2f} times "
                       "none's.")
        bad = [m for m, r in by.items() if (r.get("decision_mismatches") or 0) > 0]
        if bad:
            out.append(f"{pre}Decisions that differ from GL's recorded ones in {_modes(bad)}: the model's test is not "
                       "the capture's.")
    return out


def headline_particles(label, rows, reading):
    """The particles table beside the paper's claim and its reading, as Markdown."""
    lines = [f"Particles ({label}): depth tests per frame beside the paper's claim (16 px sprites: "
             f"{PAPER_RASTER_PER_SPRITE} N by rasterization, N with the N-buffer)",
             "",
             "| mode | sprite | paper | culled | query | raster | build | total | cycles | popping | false culls |",
             "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(f"| {r['mode']} | {r.get('sprite') or '-'} | {cell(r, 'paper_depth_tests_per_frame', ',.0f')} | "
                     f"{r['culled_per_frame']:,.0f} | {r['query_depth_tests_per_frame']:,.0f} | "
                     f"{r['raster_depth_tests_per_frame']:,.0f} | {r['build_texels_per_frame']:,.0f} | "
                     f"{r['total_depth_tests_per_frame']:,.0f} | {r['cycles_per_frame']:,.0f} | "
                     f"{r['popping']:,.0f} | {r['false_culls']:,.0f} |")
    return "\n".join(lines + [""] + [f"- {s}" for s in reading])


# --------------------------------------------------------------------------------------- shadows

SHADOW_SCENES = ["boxes", "terrain", "city"]
SHADOW_MODES = ["infinite", "culled", "clamped"]
# What a row of shadows.json (nbsim shadows --out) must hold for the report's table and reading.
SHADOW_NEED = ["scene", "shadow_mode", "frames", "casters_per_frame", "gl_culled_per_frame", "outside_per_frame",
               "fill_per_frame", "build_texels_per_frame", "lookups_per_frame", "cycles_per_frame", "mask_diff",
               "mask_diff_infinite"]
SHADOW_OPTIONAL_NUMBERS = ["reference_fill_per_frame", "ratio_to_infinite", "decision_mismatches", "draws", "draws_exact",
                           "nbuffer_memory_bytes"]
# The paper's fill ratio clamped / infinite (Décoret 2005, 4.4, 640x480): 2.5 % in the city (20 M -> 512 K
# pixels) and on the terrain, "about 20 %" on simpler scenes (our boxes). Fixed by the paper.
PAPER_CLAMPED_RATIO = {"city": (0.025, "2.5% (20 M -> 512 K px)"), "terrain": (0.025, "2.5%"),
                       "boxes": (0.20, "~20%")}


def load_shadows(path):
    """The rows of shadows.json (a JSON list, one object per replayed trace), checked; BadInput otherwise."""
    t = load_rows(path, "nbsim shadows", SHADOW_NEED, ["scene", "shadow_mode"], SHADOW_NEED[2:] + SHADOW_OPTIONAL_NUMBERS)
    for i, r in enumerate(t):
        if r["frames"] <= 0 or r["casters_per_frame"] < 0 or r["fill_per_frame"] < 0:
            raise BadInput(f"{path}: rows[{i}]: frames must be above 0 and casters and fill not negative")
    return t


def _order(names, v):
    return names.index(v) if v in names else len(names)


def shadows_rows(rows):
    """The rows by scene (boxes, terrain, city, then others), mode (infinite, culled, clamped) and litmap size, each
    with casters_culled_per_frame (GL's culls, outside the light's frustum included), ratio (fill over GL's
    infinite fill of the same frames: the row's ratio_to_infinite, else fill / reference_fill) and the paper's
    ratio for clamped rows."""
    out = []
    for r in sorted(rows, key=lambda r: (_order(SHADOW_SCENES, r["scene"]), r["scene"],
                                         _order(SHADOW_MODES, r["shadow_mode"]), str(r.get("litmap_size", "")))):
        rr = dict(r)
        rr["casters_culled_per_frame"] = r["gl_culled_per_frame"] + r["outside_per_frame"]
        ratio = r.get("ratio_to_infinite")
        if ratio is None and r.get("reference_fill_per_frame"):
            ratio = r["fill_per_frame"] / r["reference_fill_per_frame"]
        rr["ratio"] = ratio
        paper = PAPER_CLAMPED_RATIO.get(r["scene"]) if r["shadow_mode"] == "clamped" else None
        rr["paper_ratio"] = paper[0] if paper else None
        rr["paper_text"] = paper[1] if paper else ""
        rr["mask_pixels_differing"] = r["mask_diff"] + r["mask_diff_infinite"]
        out.append(rr)
    return out


def shadows_reading(rows):
    """What the shadows table shows, as plain sentences computed from its rows."""
    out = []
    bad = [r for r in rows if r["mask_pixels_differing"] > 0]
    total_frames = sum(r["frames"] for r in rows)
    if bad:
        out.append("MASK PIXELS DIFFERING in " + ", ".join(
            f"{r['scene']} {r['shadow_mode']} ({r['mask_diff']:,} from GL's mask, {r['mask_diff_infinite']:,} from its "
            "infinite reference)" for r in bad) + ": culling and clamping must change no pixel.")
    else:
        out.append(f"Culling and clamping changed no shadow-mask pixel: 0 differing from GL's mask and from its infinite "
                   f"reference in every row ({len(rows)} traces, {total_frames} frames).")
    for scene in dict.fromkeys(r["scene"] for r in rows):
        g = [r for r in rows if r["scene"] == scene]
        for r in (r for r in g if r["shadow_mode"] == "clamped" and r["ratio"] is not None):
            lit = f" (litmap {r['litmap_size']})" if r.get("litmap_size") and \
                sum(1 for x in g if x["shadow_mode"] == "clamped") > 1 else ""
            s = f"{scene}{lit}: clamping cuts the fill to {r['ratio']:.1%} of the infinite volumes'"
            if r["paper_ratio"] is not None:
                f = r["ratio"] / r["paper_ratio"]
                s += (f" (the paper: {r['paper_text']}; ours is {f:.1f} times the paper's)" if f >= 1.05 else
                      f" (the paper: {r['paper_text']}; ours is {1 / f:.1f} times lower)" if f <= 0.95 else
                      f" (the paper: {r['paper_text']}, alike)")
            out.append(s + f", {r['casters_culled_per_frame']:,.1f} of {r['casters_per_frame']:,.0f} casters culled a frame.")
        culled = [r for r in g if r["shadow_mode"] == "culled" and r["ratio"] is not None]
        clamped = [r for r in g if r["shadow_mode"] == "clamped" and r["ratio"] is not None]
        if culled and clamped:
            out.append(f"{scene}: culling alone keeps {culled[0]['ratio']:.1%} of the fill; clamping the volumes that "
                       f"remain takes it to {clamped[0]['ratio']:.1%}.")
        inf = next((r for r in g if r["shadow_mode"] == "infinite"), None)
        if inf and clamped and inf["cycles_per_frame"] > 0:
            c = clamped[0]
            out.append(f"{scene}: the model's cycles per frame fall from {inf['cycles_per_frame']:,.0f} (infinite) to "
                       f"{c['cycles_per_frame']:,.0f} (clamped), {inf['cycles_per_frame'] / max(c['cycles_per_frame'], 1):.1f} "
                       "times fewer.")
    nb = [r for r in rows if r["lookups_per_frame"] > 0]
    if nb:
        lo = min(r["build_texels_per_frame"] / r["lookups_per_frame"] for r in nb)
        hi = max(r["build_texels_per_frame"] / r["lookups_per_frame"] for r in nb)
        out.append(f"The two N-buffers' build costs {lo:,.0f} to {hi:,.0f} times their lookups (texels a frame): "
                   + ("the build dominates the N-buffer cost." if lo > 1 else "the lookups cost more in some row."))
    mism = [r for r in rows if (r.get("decision_mismatches") or 0) > 0]
    if mism:
        out.append("Cull decisions unlike the cull rule on GL's own values in " +
                   ", ".join(f"{r['scene']} {r['shadow_mode']}" for r in mism) + ".")
    return out


def headline_shadows(label, rows, reading):
    """The shadows table beside the paper's ratios and its reading, as Markdown."""
    lines = [f"Shadows ({label}): fill per frame beside the paper's clamped / infinite ratio (640x480: city 20 M -> "
             "512 K px, 2.5%; simpler scenes about 20%)",
             "",
             "| scene | mode | litmap | fill | ratio | paper | casters culled | build | lookups | cycles | mask px differing |",
             "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(f"| {r['scene']} | {r['shadow_mode']} | {r.get('litmap_size') or '-'} | {r['fill_per_frame']:,.0f} | "
                     f"{pct(r['ratio'])} | {r['paper_text'] or '-'} | "
                     f"{r['casters_culled_per_frame']:,.1f} of {r['casters_per_frame']:,.0f} | "
                     f"{r['build_texels_per_frame']:,.0f} | {r['lookups_per_frame']:,.0f} | {r['cycles_per_frame']:,.0f} | "
                     f"{r['mask_diff']:,}, {r['mask_diff_infinite']:,} |")
    return "\n".join(lines + [""] + [f"- {s}" for s in reading])


# ------------------------------------------------------------------------------ layered depth images
LDI_NEED = ["shape", "ldi_size", "vertices", "d_min", "d_max", "layers", "m_crop", "m_comp", "points", "classified",
            "near_surface", "misclassified_layers", "misclassified_ranges", "fetches_per_test_layers",
            "fetches_per_test_ranges"]
LDI_OPTIONAL_NUMBERS = ["c_ratio", "ms_viewpoint", "ms_peel", "ms_crop", "ms_compress", "triangles",
                        "paper_c_ratio", "gl_parity_mismatches", "classified_anywhere", "misclassified_anywhere",
                        "fetches_anywhere_layers", "fetches_anywhere_ranges"]
# The paper's Table 1 rows set beside ours (Trapp & Doellner 2008, 1024x1024 LDIs): the two
# compression ratios at the ends of its range; its other rows are not reproduced. Fixed by the paper.
PAPER_LDI = {"sphere": ("Sphere, 994 vertices, d = 2", 1.78), "nested": ("Hebe, d up to 18", 0.32)}


def load_ldi(path):
    """The rows of ldi.json (nbsim ldi table1 --out: one object per shape and LDI size), checked; BadInput otherwise."""
    t = load_rows(path, "nbsim ldi table1", LDI_NEED, ["shape"], LDI_NEED[1:] + LDI_OPTIONAL_NUMBERS)
    for i, r in enumerate(t):
        if r["ldi_size"] <= 0 or r["points"] < 0 or r["classified"] < 0 or r["classified"] > r["points"]:
            raise BadInput(f"{path}: rows[{i}]: ldi_size must be above 0 and classified within [0, points]")
        if r["misclassified_layers"] > r["classified"] or r["misclassified_ranges"] > r["classified"]:
            raise BadInput(f"{path}: rows[{i}]: more points misclassified than classified")
    return t


def ldi_rows(rows):
    """The rows by shape (as given, first appearance) and LDI size, each with the misclassification rates of both
    readers (over the classified points; None without any) and the paper's ratio where it has one."""
    shapes = list(dict.fromkeys(r["shape"] for r in rows))
    out = []
    for r in sorted(rows, key=lambda r: (shapes.index(r["shape"]), r["ldi_size"])):
        rr = dict(r)
        n = r["classified"]
        rr["error_layers"] = r["misclassified_layers"] / n if n else None
        rr["error_ranges"] = r["misclassified_ranges"] / n if n else None
        na = r.get("classified_anywhere")
        rr["error_anywhere"] = r["misclassified_anywhere"] / na if na and r.get("misclassified_anywhere") is not None else None
        base = r["shape"].split(":")[0]
        paper = PAPER_LDI.get(base)
        rr["paper_text"] = paper[0] if paper else ""
        rr["paper_c_ratio"] = r.get("paper_c_ratio", paper[1] if paper else None)
        out.append(rr)
    return out


def ldi_reading(rows):
    """What the LDI table shows, as plain sentences computed from its rows."""
    out = []
    lossless = [r for r in rows if r["error_layers"] is not None and r["misclassified_layers"] != r["misclassified_ranges"]]
    if lossless:
        out.append("THE READERS DISAGREE in " + ", ".join(f"{r['shape']} {r['ldi_size']}" for r in lossless) +
                   ": compression is lossless, so both must misclassify the same points.")
    else:
        out.append(f"Both readers misclassify the same number of points in every row ({len(rows)} rows): the compression "
                   "is lossless, so it changes the cost of a test, not its answer.")
    bad_gl = [r for r in rows if r.get("gl_parity_mismatches")]
    if bad_gl:
        out.append("GL AND THE MODEL DISAGREE on " + ", ".join(f"{r['shape']} {r['ldi_size']} ({r['gl_parity_mismatches']:,})"
                                                              for r in bad_gl) + " parity answers.")
    for shape in dict.fromkeys(r["shape"] for r in rows):
        g = [r for r in rows if r["shape"] == shape and r["error_layers"] is not None]
        if not g:
            continue
        lo, hi = g[0], g[-1]
        s = (f"{shape}: misclassified {pct(lo['error_layers'], 2)} of its test points at {lo['ldi_size']}² "
             + (f"and {pct(hi['error_layers'], 2)} at {hi['ldi_size']}²" if hi is not lo else "")
             + ("" if lo.get("error_anywhere") is None else
                f" (uniform points anywhere in their texel: {pct(lo['error_anywhere'], 2)}"
                + (f" falling to {pct(hi['error_anywhere'], 2)})" if hi is not lo and hi.get("error_anywhere") is not None else ")"))
             + f"; a test reads {hi['fetches_per_test_layers']:.2f} layer texels uncompressed against "
             f"{hi['fetches_per_test_ranges']:.2f} texels compressed")
        if hi.get("c_ratio") is not None:
            s += f", C_ratio {hi['c_ratio']:.2f}"
            if hi.get("paper_c_ratio") is not None:
                s += f" (the paper's {hi['paper_text']}: {hi['paper_c_ratio']:.2f})"
        out.append(s + ".")
    return out


def headline_ldi(label, rows, reading):
    """The LDI Table 1 reproduction and misclassification, as Markdown."""
    lines = [f"Layered depth images ({label}): Table 1 beside the paper's ratios, and the parity test's misclassification "
             "against the exact reference",
             "",
             "| shape | LDI | vertices | d_min/d_max | M_crop | M_comp | C_ratio | paper | misclassified | anywhere in the texel | fetches/test (layers, ranges) | ms viewpoint/peel/crop/compress |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    ms = lambda r, k: "-" if r.get(k) is None else f"{r[k]:,.1f}"  # noqa: E731
    for r in rows:
        lines.append(f"| {r['shape']} | {r['ldi_size']} | {r['vertices']:,} | {r['d_min']}/{r['d_max']} | {r['m_crop']:,} | "
                     f"{r['m_comp']:,} | {'-' if r.get('c_ratio') is None else format(r['c_ratio'], '.3f')} | "
                     f"{'-' if r.get('paper_c_ratio') is None else format(r['paper_c_ratio'], '.2f')} | "
                     f"{pct(r['error_layers'], 2)} of {r['classified']:,} | "
                     f"{pct(r.get('error_anywhere'), 2)} | "
                     f"{r['fetches_per_test_layers']:.2f}, {r['fetches_per_test_ranges']:.2f} | "
                     f"{ms(r, 'ms_viewpoint')}/{ms(r, 'ms_peel')}/{ms(r, 'ms_crop')}/{ms(r, 'ms_compress')} |")
    return "\n".join(lines + [""] + [f"- {s}" for s in reading])


# ------------------------------------------------------------------------------------ relief textures
RELIEF_METHODS = ["binary", "exact", "robust", "robust_clamp", "nbuffer"]
# relief.json (nbsim relief TRACE... --out; pipeline/techniques/relief/relief_table.h): an object of these lists. Per
# list: the keys each row must hold, those of them that are strings, numbers (null allowed: a ratio over no
# fragment, a paper row we have no rows for) and counts (whole numbers not below 0).
RELIEF_LISTS = {
    "rows": (["trace", "field", "field_size", "frame", "angle", "method", "fragments", "gl_fragments", "lookups",
              "steps", "errors", "reference_hits", "cycles", "pixel_mismatches", "walk_mismatches",
              "lookups_per_fragment", "steps_per_fragment", "error_rate"],
             ["trace", "field", "method"], ["angle", "lookups_per_fragment", "steps_per_fragment", "error_rate"],
             ["field_size", "frame", "fragments", "gl_fragments", "lookups", "steps", "errors", "reference_hits",
              "cycles", "pixel_mismatches", "walk_mismatches"]),
    "ranking": (["method", "fragments", "lookups_per_fragment", "steps_per_fragment", "cycles_per_frame", "errors",
                 "error_rate", "pareto"],
                ["method"], ["lookups_per_fragment", "steps_per_fragment", "cycles_per_frame", "error_rate"],
                ["fragments", "errors"]),
    "nbuffer_vs_exact": (["field", "field_size", "exact_lookups_per_fragment", "nbuffer_lookups_per_fragment",
                          "lookup_ratio", "exact_errors", "nbuffer_errors", "extra_errors"],
                         ["field"], ["exact_lookups_per_fragment", "nbuffer_lookups_per_fragment", "lookup_ratio",
                                     "extra_errors"],
                         ["field_size", "exact_errors", "nbuffer_errors"]),
    "paper": (["method", "field_size", "paper_hz", "cycles_per_frame", "lookups_per_fragment"],
              ["method"], ["paper_hz", "cycles_per_frame", "lookups_per_fragment"], ["field_size"]),
}
# Where the paper's numbers come from (relief_table.cpp holds them): Baboud & Decoret, "Rendering geometry
# with relief textures", Graphics Interface 2006, Table 1, terrain on a GeForce 6800 GT.
RELIEF_PAPER = "Baboud & Décoret 2006, Table 1: the terrain on a GeForce 6800 GT"
# How many places a reading names before it says "and N more" (readability).
RELIEF_NAMED = 6


def load_relief(path):
    """relief.json (nbsim relief TRACE... --out), checked; BadInput naming the file and the row otherwise."""
    doc = load_json(path)
    if not isinstance(doc, dict):
        raise BadInput(f"{path}: expected an object with settings, rows, ranking, nbuffer_vs_exact and paper "
                       "(nbsim relief --out)")
    lacking = [k for k in ["settings"] + list(RELIEF_LISTS) if k not in doc]
    if lacking:
        raise BadInput(f"{path}: lacks {', '.join(lacking)} (nbsim relief --out writes them all)")
    if not isinstance(doc["settings"], list) or not all(isinstance(s, str) for s in doc["settings"]):
        raise BadInput(f"{path}: settings is not a list of strings: {doc['settings']!r}")
    for name, (need, strings, numbers, counts) in RELIEF_LISTS.items():
        t = doc[name]
        if not isinstance(t, list) or (name in ("rows", "ranking") and not t):
            raise BadInput(f"{path}: {name} is not a{' non-empty' if name in ('rows', 'ranking') else ''} list")
        check_rows(path, name, t, need, strings, numbers, counts)
    for i, r in enumerate(doc["rows"]):
        if r["errors"] > r["fragments"] or r["reference_hits"] > r["fragments"]:
            raise BadInput(f"{path}: rows[{i}]: errors and reference_hits must be within [0, fragments]")
    for i, r in enumerate(doc["ranking"]):
        if not isinstance(r["pareto"], bool):
            raise BadInput(f"{path}: ranking[{i}].pareto is not true or false: {r['pareto']!r}")
        if r["cycles_per_frame"] is None or r["error_rate"] is None or r["cycles_per_frame"] < 0 or r["error_rate"] < 0:
            raise BadInput(f"{path}: ranking[{i}]: cycles_per_frame and error_rate must be numbers not below 0")
    for i, r in enumerate(doc["paper"]):
        if r["paper_hz"] is None or r["paper_hz"] <= 0:
            raise BadInput(f"{path}: paper[{i}].paper_hz must be above 0, not {r['paper_hz']!r}")
    return doc


def _named(items):
    """At most RELIEF_NAMED of the items, comma-separated, then how many more."""
    more = len(items) - RELIEF_NAMED
    return ", ".join(items[:RELIEF_NAMED]) + (f" and {more} more" if more > 0 else "")


def _rows(rows):
    return f"{len(rows)} row{'' if len(rows) == 1 else 's'}"


def relief_heightfield(field, size):
    return f"{field} at {size}²"


def relief_ranking(doc):
    """The ranking (cheapest first, as nbsim wrote it), each method with its rows' walks and pixels differing
    from GL's and fragment counts unlike GL's (summed over its rows)."""
    out = []
    for r in doc["ranking"]:
        rr = dict(r)
        mine = [x for x in doc["rows"] if x["method"] == r["method"]]
        rr["walk_mismatches"] = sum(x["walk_mismatches"] for x in mine)
        rr["pixel_mismatches"] = sum(x["pixel_mismatches"] for x in mine)
        rr["fragments_unlike_gl"] = sum(abs(x["fragments"] - x["gl_fragments"]) for x in mine)
        out.append(rr)
    return out


def relief_lookups_by_field(rows):
    """Lookups per fragment per heightfield (field and size, in the order first met) and method, over every view
    angle: {(field, size): {method: lookups per fragment, or None without fragments}}."""
    sums = {}
    for r in rows:
        s = sums.setdefault((r["field"], r["field_size"]), {}).setdefault(r["method"], [0, 0])
        s[0] += r["lookups"]
        s[1] += r["fragments"]
    return {k: {m: (lk / n if n else None) for m, (lk, n) in v.items()} for k, v in sums.items()}


def relief_paper_rows(paper):
    """The paper's rows by size and method, each with its rank among the methods of its size: the paper's by frame
    rate (highest first) and ours by cycles per box draw (fewest first; None where we have no rows)."""
    out = []
    for size in sorted({r["field_size"] for r in paper}):
        g = sorted((dict(r) for r in paper if r["field_size"] == size),
                   key=lambda r: (_order(RELIEF_METHODS, r["method"]), r["method"]))
        for r in g:
            r["paper_rank"] = 1 + sum(1 for o in g if o["paper_hz"] > r["paper_hz"])
            ours = r["cycles_per_frame"]
            r["our_rank"] = None if ours is None else \
                1 + sum(1 for o in g if o["cycles_per_frame"] is not None and o["cycles_per_frame"] < ours)
        out += g
    return out


def _ordered(rows, key, rank, unit, spec):
    """'a, b = c (1, 2, 2 unit)': methods in the order of `rank` (1 first), ties joined by '='."""
    g = sorted(rows, key=lambda r: (r[rank], _order(RELIEF_METHODS, r["method"])))
    names = g[0]["method"]
    for a, b in zip(g, g[1:]):
        names += (" = " if a[rank] == b[rank] else ", ") + b["method"]
    return f"{names} ({', '.join(format(r[key], spec) for r in g)} {unit})"


def relief_reading(doc, ranking, paper_rows):
    """What the relief section shows, as plain sentences computed from relief.json."""
    rows, out = doc["rows"], []
    walks = [r for r in rows if r["walk_mismatches"] > 0]
    pixels = [r for r in rows if r["pixel_mismatches"] > 0]
    frags = [r for r in rows if r["fragments"] != r["gl_fragments"]]
    where = lambda r: f"{trace_name(r['trace'])} frame {r['frame']} {r['method']}"  # noqa: E731
    if walks or pixels or frags:
        parts = []
        if walks:
            parts.append(f"walks differing from GL's in {_rows(walks)} ("
                         + _named([f"{where(r)}: {r['walk_mismatches']:,}" for r in walks]) + ")")
        if pixels:
            parts.append(f"pixels differing from GL's in {_rows(pixels)} ("
                         + _named([f"{where(r)}: {r['pixel_mismatches']:,}" for r in pixels]) + ")")
        if frags:
            parts.append(f"fragment counts unlike GL's in {_rows(frags)} ("
                         + _named([f"{where(r)}: {r['fragments']:,} against {r['gl_fragments']:,}" for r in frags]) + ")")
        out.append("GL AND THE MODEL DISAGREE: " + "; ".join(parts) + ". The model's walk must be the shader's, "
                   "fragment for fragment.")
    else:
        traces = len({r["trace"] for r in rows})
        out.append(f"The model's walks and pixels are GL's in every row ({len(rows)} rows: {traces} traces, "
                   f"{len({r['frame'] for r in rows})} view angles, {len({r['method'] for r in rows})} "
                   "methods): 0 walks and 0 pixels differing, fragment counts equal.")
    front = [r for r in ranking if r["pareto"]]
    cheap = min(ranking, key=lambda r: r["cycles_per_frame"])
    dear = max(ranking, key=lambda r: r["cycles_per_frame"])
    s = "Pareto front of cycles per box draw against hit error: " + ", ".join(
        f"{r['method']} ({r['cycles_per_frame']:,.0f} cycles, {pct(r['error_rate'], 3)} hit errors)" for r in front)
    s += f". Cheapest: {cheap['method']}"
    if dear is not cheap and cheap["cycles_per_frame"] > 0:
        s += (f"; dearest: {dear['method']} ({dear['cycles_per_frame']:,.0f} cycles, "
              f"{dear['cycles_per_frame'] / cheap['cycles_per_frame']:.2f} times)")
    out.append(s + ".")
    least = min(r["error_rate"] for r in ranking)
    best = [r["method"] for r in ranking if r["error_rate"] == least]
    worst = max(ranking, key=lambda r: r["error_rate"])
    out.append(f"Fewest hit errors: {_modes(best)} ({pct(least, 3)} of the fragments)"
               + ("" if worst["error_rate"] == least else f"; most: {worst['method']} ({worst['errors']:,} of "
                  f"{worst['fragments']:,} fragments, {pct(worst['error_rate'], 3)})") + ".")
    lk = [r for r in ranking if r["lookups_per_fragment"] is not None]
    if lk:
        few = min(lk, key=lambda r: r["lookups_per_fragment"])
        if few is not cheap:
            out.append(f"Fewest lookups per fragment: {few['method']} ({few['lookups_per_fragment']:.2f}, "
                       f"{cell(few, 'steps_per_fragment', '.2f')} steps), yet {cheap['method']} costs fewer cycles "
                       f"({cell(cheap, 'lookups_per_fragment', '.2f')} lookups, {cell(cheap, 'steps_per_fragment', '.2f')} "
                       "steps per fragment): lookups alone do not set the cost.")
    nve = [r for r in doc["nbuffer_vs_exact"] if r["lookup_ratio"] is not None]
    if nve:
        fewer = [r for r in nve if r["lookup_ratio"] < 1]
        more = [relief_heightfield(r["field"], r["field_size"]) for r in nve if r["lookup_ratio"] > 1]
        extra = [r for r in nve if (r["extra_errors"] or 0) > 0]
        lo, hi = min(r["lookup_ratio"] for r in nve), max(r["lookup_ratio"] for r in nve)
        s = (f"The N-buffer walk read fewer lookups per fragment than the exact walk on {len(fewer)} of {len(nve)} "
             f"heightfields (N-buffer / exact {lo:.2f} to {hi:.2f}" + (f"; more on {_named(more)}" if more else "")
             + "), with " + (f"extra hit errors on {len(extra)}: " + _named(
                 [f"{relief_heightfield(r['field'], r['field_size'])} (+{r['extra_errors']:,})" for r in extra])
                 if extra else "0 extra hit errors on any of them")
             + f" (N-buffer {sum(r['nbuffer_errors'] for r in nve):,} errors, exact "
             f"{sum(r['exact_errors'] for r in nve):,}).")
        out.append(s)
    if paper_rows:
        orders, without = [], []
        for size in dict.fromkeys(r["field_size"] for r in paper_rows):
            g = [r for r in paper_rows if r["field_size"] == size]
            ours = [r for r in g if r["our_rank"] is not None]
            if len(ours) < 2:
                without.append(f"{size}²")
                continue
            p = _ordered(ours, "paper_hz", "paper_rank", "Hz", ".0f")
            o = _ordered(ours, "cycles_per_frame", "our_rank", "cycles", ",.0f")
            same = [r["paper_rank"] for r in sorted(ours, key=lambda r: r["method"])] == \
                [r["our_rank"] for r in sorted(ours, key=lambda r: r["method"])]
            orders.append(f"At {size}², the paper: {p}; ours: {o}; {'the same order' if same else 'another order'}.")
        s = (f"The paper ranks the methods by frame rate on a 2006 GPU ({RELIEF_PAPER}), fastest first; we rank them "
             "by modelled cycles per box draw of the fbm heightfield (the paper's terrain), fewest first. ")
        s += " ".join(orders) if orders else "We have no fbm rows at the paper's sizes."
        if without and orders:
            s += f" No fbm rows of ours at {_modes(without)}: the paper's alone."
        out.append(s)
    return out


def headline_relief(label, ranking, reading):
    """The relief methods' ranking (cycles against hit error) and its reading, as Markdown."""
    lines = [f"Relief textures ({label}): methods ranked by modelled cycles per box draw against hit error",
             "",
             "| method | cycles/box draw | lookups/fragment | steps/fragment | hit errors | Pareto | walks, pixels differing from GL |",
             "|---|---:|---:|---:|---:|---|---:|"]
    for r in ranking:
        lines.append(f"| {r['method']} | {r['cycles_per_frame']:,.0f} | {cell(r, 'lookups_per_fragment', '.2f')} | "
                     f"{cell(r, 'steps_per_fragment', '.2f')} | {pct(r['error_rate'], 3)} ({r['errors']:,}) | "
                     f"{'yes' if r['pareto'] else 'no'} | {r['walk_mismatches']:,}, {r['pixel_mismatches']:,} |")
    return "\n".join(lines + [""] + [f"- {s}" for s in reading])
