"""The data side of nbsim's exploration report (report.py): reading the CSV/JSON outputs, point labels,
Pareto marks, and the Markdown headline. No plotting here: report_plots.py has that.
"""
import csv
import json
import math
import os

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
# The labels a technique's declared results must give the report (technique_results.json, "report"):
# its axes, columns and words, written by nbsim explore from the technique's declaration.
REPORT_LABELS = ("error_axis", "error_text", "error_column", "fallback_axis", "fallback_text", "fallback_column",
                 "cost_axis", "cost_column", "cost_pareto", "cost_short", "memory_axis", "memory_pareto",
                 "memory_short", "quality_column", "must_be_zero", "alike")


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


# -------------------------------------------------------------------------------------- headline

def cell(r, key, spec):
    """A Markdown table cell: r[key] formatted with `spec`, '-' when absent."""
    v = r.get(key)
    return "-" if v is None else format(v, spec)


def technique_results(d, path):
    """The declared results of the technique of sweep folder d's traces (its technique_results.json,
    the first technique that declares any); BadInput when the folder has no such file (a sweep run before
    nbsim explore wrote it) or when its traces' techniques declare no results (no cost or error axis to plot)."""
    f = os.path.join(d, "technique_results.json")
    if not os.path.exists(f):
        raise BadInput(f"{f}: no such file; nbsim explore writes it beside results.csv (the technique's declared "
                       "results: its cost, error and labels): re-run the sweep")
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
    if not isinstance(t["report"], dict) or any(not isinstance(t["report"].get(k), str) for k in REPORT_LABELS):
        raise BadInput(f"{f}: techniques[0].report needs the labels {', '.join(REPORT_LABELS)}")
    return t


def kib_key(metric):
    """The row key of a memory metric in KiB: nbuffer_memory_bytes -> nbuffer_memory_kib."""
    return (metric[:-len("_bytes")] if metric.endswith("_bytes") else metric) + "_kib"


def headline_sweep(name, rows, traces, err_label, tech):
    """The Pareto-optimal points of a sweep (cycles per frame against its error), as a Markdown table;
    a sweep whose points all have one error (a fidelity sweep) gets its cycle error and host time instead.
    tech: the technique's declared results (technique_results)."""
    lab = tech["report"]
    lines = [f"Sweep {name}: Pareto-optimal points, cycles per frame against {err_label}", "",
             f"| trace | point | cycles per frame | error | {lab['cost_axis']} | {lab['memory_axis']} | host s |",
             "|---|---|---:|---:|---:|---:|---:|"]
    alike = []
    for t in traces:
        ok = [r for r in rows if r["trace"] == t and r["status"] == "ok" and r["role"] == "sweep"]
        errs = {r["error_axis"] for r in ok if r.get("error_axis") is not None}
        if ok and len(errs) <= 1:  # no trade-off against the error here: timing error and speed instead
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


# ------------------------------------------------------------------------- techniques' tables
# Helpers of the techniques' report sections (analysis/techniques/NAME/section.py).


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


def _modes(names):
    """"a, b and c"."""
    return ", ".join(names[:-1]) + " and " + names[-1] if len(names) > 1 else names[0]


def _order(names, v):
    """The index of v in names (after them when absent), for sorting."""
    return names.index(v) if v in names else len(names)
