"""The report's occlusion culling sections, from `nbsim table2 TRACE --out DIR/table2`: Table 2 (table2.json,
every culling mode's depth tests per frame beside the paper's) and the walkthrough (each mode's run.json, its
depth tests frame by frame).

Inputs: DIR/table2/table2.json (nbsim table2 TRACE --out DIR/table2) and DIR/table2/MODE/run.json (the same
command, one folder per culling mode); the walkthrough is drawn from the run.json files alone when table2.json
is missing.

Loaded by analysis/report.py with every analysis/techniques/<name>/section.py (NAME, ORDER and, as this module
has two sections, SECTIONS instead of TITLE and section(rep): each section's build(rep) returns its HTML or raises
report_data.Missing / BadInput); report.py puts analysis/ on the import path first.
"""
import csv
import html

from report_plots import FIGSIZE, THOUSANDS, spans_decades  # first: it selects the headless backend
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.ticker import MaxNLocator
from report_data import BadInput, Missing, load_json, pct, read_csv, trace_name
import importlib.util
import pathlib

# The cross-technique reading of the N-buffer design sweep, shared with docs/exploration.md (pays.py).
_spec = importlib.util.spec_from_file_location("nbsim_occlusion_pays", pathlib.Path(__file__).with_name("pays.py"))
pays = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(pays)

NAME = "occlusion"
ORDER = 0  # the sections' order on the page and in headline.md: first, right after Table 1 and Figure 4

MODE_ORDER = ["oq_hier", "oq", "nb_hier", "nb", "hiz_tile", "hiz_pyramid"]
MODE_STYLE = {  # colour, line style, marker: a hierarchical mode is the darker, solid one of its pair
    "oq_hier": ("#1f4e96", "-", "s"), "oq": ("#6fa8dc", "--", "s"),
    "nb_hier": ("#b2182b", "-", "o"), "nb": ("#f4a582", "--", "o"),
    "hiz_tile": ("#1b7837", "-", "^"), "hiz_pyramid": ("#a6dba0", "--", "v"),
}
# The paper's ratios of depth tests per frame (Table 2: 200 000 / 500 and 1 100 000 / 350).
RATIO_PAIRS = [("oq", "nb"), ("oq_hier", "nb_hier")]


def sorted_modes(modes):
    return sorted(modes, key=lambda m: (MODE_ORDER.index(m) if m in MODE_ORDER else len(MODE_ORDER), m))


def mode_style(mode):
    return MODE_STYLE.get(mode, ("#555555", "-", "x"))


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


# ------------------------------------------------------------------------------ Table 2
def load_table2(rep):
    """(DIR/table2/table2.json, its content checked), or (that path, None) when it is absent."""
    path = rep.root / "table2" / "table2.json"
    if not path.exists():
        return path, None
    t = load_json(path)
    if not isinstance(t, dict) or not isinstance(t.get("rows"), list) or not t["rows"]:
        raise BadInput(f"{path}: expected an object with a non-empty \"rows\" list (nbsim table2 --out)")
    need = ["mode", "query_depth_tests_per_frame", "total_depth_tests_per_frame", "cycles_per_frame",
            "false_culls", "culling_efficiency"]
    for i, r in enumerate(t["rows"]):
        if not isinstance(r, dict):
            raise BadInput(f"{path}: rows[{i}] is not an object")
        lacking = [k for k in need if k not in r]
        if lacking:
            raise BadInput(f"{path}: rows[{i}] lacks {', '.join(lacking)}")
        for k in need[1:] + ["paper_depth_tests_per_frame", "update_texels_per_frame", "undrawable"]:
            if r.get(k) is not None and not isinstance(r[k], (int, float)):
                raise BadInput(f"{path}: rows[{i}].{k} is not a number: {r[k]!r}")
    return path, t


def table2(rep):
    path, t = load_table2(rep)
    if t is None:
        raise Missing(["table2/table2.json"])
    rep.used(path, "Table 2")
    if t.get("nbsim_version"):
        rep.versions.add(str(t["nbsim_version"]))
    rows = []
    for r in t["rows"]:
        rr = dict(r)
        p = r.get("paper_depth_tests_per_frame")
        rr["ours_over_paper"] = r["query_depth_tests_per_frame"] / p if p else None
        rows.append(rr)
    cols = [("mode", "mode", None), ("paper row", "paper", lambda v: v or "-"),
            ("paper depth tests/frame", "paper_depth_tests_per_frame", None),
            ("query depth tests/frame", "query_depth_tests_per_frame", None),
            ("ours / paper", "ours_over_paper", lambda v: "-" if v is None else f"{v:.3g}"),
            ("update texels/frame", "update_texels_per_frame", None),
            ("total depth tests/frame", "total_depth_tests_per_frame", None),
            ("cycles/frame", "cycles_per_frame", None), ("false culls", "false_culls", None),
            ("culling efficiency", "culling_efficiency", pct), ("undrawable", "undrawable", None)]
    tab = rep.table("table2", cols, rows, row_class=lambda r: "bad" if r.get("false_culls") else "")
    ratios = table2_ratios(t["rows"])
    rtab = rep.table("table2_ratios", [("ratio of query depth tests", "ratio", None),
                                       ("ours", "ours", lambda v: "-" if v is None else f"{v:,.0f}x"),
                                       ("paper", "paper", lambda v: "-" if v is None else f"{v:,.0f}x")], ratios)
    settings = t.get("settings") or []
    sets = ", ".join(f"<code>{html.escape(str(s))}</code>" for s in settings) or "none (the defaults)"
    cfg = f", config file <code>{html.escape(str(t['config_file']))}</code>" if t.get("config_file") else ""
    crc = f" (CRC-32 {html.escape(str(t['trace_crc32']))})" if t.get("trace_crc32") else ""
    # the paper against ours, per mode
    modes = [r["mode"] for r in rows]
    fig, ax = plt.subplots(figsize=FIGSIZE, constrained_layout=True)
    x = np.arange(len(rows))
    wd = 0.27
    ax.bar(x - wd, [r.get("paper_depth_tests_per_frame") or np.nan for r in rows], wd,
           label="paper (512x512 city)", color="#999999", hatch="//", edgecolor="white")
    ax.bar(x, [r["query_depth_tests_per_frame"] for r in rows], wd, label="ours: query depth tests", color="#b2182b")
    ax.bar(x + wd, [r["total_depth_tests_per_frame"] for r in rows], wd,
           label="ours: total (+ updates + drawing)", color="#6fa8dc")
    for i, r in enumerate(rows):
        if not r.get("paper_depth_tests_per_frame"):
            ax.annotate("no paper row", (x[i] - wd, 0), xycoords=("data", "axes fraction"), xytext=(0, 4),
                        textcoords="offset points", rotation=90, ha="center", va="bottom", fontsize=7, color="#777")
    ax.set_yscale("log")
    tallest = max(max(r["total_depth_tests_per_frame"], r["query_depth_tests_per_frame"],
                      r.get("paper_depth_tests_per_frame") or 0) for r in rows)
    ax.set_ylim(top=tallest * 30)  # headroom: the legend sits above the bars
    ax.set_xticks(x, modes)
    ax.set_xlabel("culling mode")
    ax.set_ylabel("depth tests per frame (log scale)")
    ax.set_title(f"Depth tests per frame: paper vs nbsim ({trace_name(str(t.get('trace', '?')))})")
    ax.grid(axis="y", which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="upper right", ncols=3)
    img = rep.save(fig, "table2.png")
    rt = "; ".join(f"{r['ratio']}: {'-' if r['ours'] is None else format(r['ours'], ',.0f')}x "
                   f"(paper {'-' if r['paper'] is None else format(r['paper'], ',.0f')}x)" for r in ratios)
    fc = sum(int(r.get("false_culls") or 0) for r in rows)
    rep.headline.append(headline_table2(t, rows, ratios))
    return (f"<p>Trace <code>{html.escape(str(t.get('trace', '?')))}</code>{crc}, settings: {sets}{cfg}; "
            f"from <code>{rep.rel(path)}</code>. Query depth tests are the paper's count; the total adds the "
            "N-buffer/Hi-Z update texels and the drawn objects' depth tests. "
            f"{'<b class=bad>' + str(fc) + ' false culls.</b>' if fc else 'No false culls.'} "
            f"Ratios: {html.escape(rt) or 'none (a mode of each pair is missing)'}.</p>" + tab +
            "<h3>Occlusion queries over N-buffer</h3>" + rtab +
            rep.figure(img, "Per culling mode, log scale: the paper's depth tests per frame (grey), ours for "
                       "the queries alone (red, the paper's count) and in total (blue). Read off: the "
                       "N-buffer modes' query cost is orders of magnitude below the occlusion queries', as in the "
                       "paper, while their total is dominated by keeping the levels up to date."))


# ------------------------------------------------------------------------------ walkthrough
def walkthrough(rep):
    _, t = load_table2(rep) if (rep.root / "table2" / "table2.json").exists() else (None, None)
    base = rep.root / "table2"
    if t is not None:
        modes = [r["mode"] for r in t["rows"]]
    elif base.is_dir():
        modes = sorted_modes(d.name for d in base.iterdir() if (d / "run.json").exists())
    else:
        modes = []
    present = [m for m in modes if (base / m / "run.json").exists()]
    if not present:
        raise Missing([f"table2/{m}/run.json" for m in modes] or ["table2/MODE/run.json"])
    series = {}
    for m in present:
        p = base / m / "run.json"
        run = load_json(p)
        frames = run.get("frames") if isinstance(run, dict) else None
        if not isinstance(frames, list) or not frames:
            raise BadInput(f"{p}: no \"frames\" list (nbsim replay's run.json)")
        for i, f in enumerate(frames):
            if not isinstance(f, dict) or not all(isinstance(f.get(k), (int, float))
                                                  for k in ("frame", "query_depth_tests", "total_depth_tests")):
                raise BadInput(f"{p}: frames[{i}] lacks a number for frame, query_depth_tests or total_depth_tests")
        if isinstance(run.get("nbsim_version"), str):
            rep.versions.add(run["nbsim_version"])
        rep.used(p, "walkthrough")
        series[m] = frames
    with open(rep.out / "walkthrough.csv", "w", newline="") as f:
        keys = ["frame", "query_depth_tests", "total_depth_tests", "depth_tests", "update_texels", "cycles"]
        w = csv.writer(f)
        w.writerow(["mode"] + keys)
        for m, frames in series.items():
            for fr in frames:
                w.writerow([m] + [fr.get(k, "") for k in keys])
    fig, axes = plt.subplots(2, 1, figsize=(8.5, 7), sharex=True, constrained_layout=True)
    zeros = []
    for m, frames in series.items():
        c, ls, mk = mode_style(m)
        fx = [f["frame"] for f in frames]
        q = [f["query_depth_tests"] for f in frames]
        if any(v <= 0 for v in q):
            zeros.append(m)
        axes[0].plot(fx, [v if v > 0 else np.nan for v in q], color=c, ls=ls, marker=mk, ms=4, label=m)
        axes[1].plot(fx, [f["total_depth_tests"] for f in frames], color=c, ls=ls, marker=mk, ms=4, label=m)
    axes[0].set_yscale("log")
    axes[0].set_ylabel("query depth tests (log scale)")
    axes[0].set_title("Visibility queries: the paper's count per frame")
    if spans_decades([f["total_depth_tests"] for fr in series.values() for f in fr]):
        axes[1].set_yscale("log")
        axes[1].set_ylabel("total depth tests (log scale)")
    else:
        axes[1].set_ylabel("total depth tests")
        axes[1].yaxis.set_major_formatter(THOUSANDS)
    axes[1].set_title("Total: queries + N-buffer/Hi-Z updates + drawn objects")
    axes[1].set_xlabel("frame of the walkthrough")
    for ax in axes:
        ax.grid(which="both", alpha=0.3)
    axes[0].xaxis.set_major_locator(MaxNLocator(integer=True))
    axes[0].legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1), title="culling mode", title_fontsize=8)
    fig.suptitle("Depth tests per frame along the walkthrough, per culling mode")
    img = rep.save(fig, "walkthrough.png")
    absent = [m for m in modes if m not in present]
    note = (f" Missing: {', '.join(f'table2/{m}/run.json' for m in absent)}." if absent else "")
    note += (f" Frames with no query depth test ({', '.join(zeros)}) are gaps on the log scale." if zeros else "")
    return (f"<p>Per frame, from <code>table2/MODE/run.json</code> ({len(present)} modes).{html.escape(note)} "
            'The plotted values are in <a href="walkthrough.csv">walkthrough.csv</a>.</p>' +
            rep.figure(img, "Top: query depth tests per frame (log scale), one line per culling mode; bottom: "
                       "total depth tests per frame. Read off: the gap between the occlusion-query modes "
                       "(blue) and the N-buffer modes (red) frame by frame, and which frames of the walk "
                       "cost the most."))


def nbuffer_pays(rep):
    path = rep.root / "sweeps" / "nbuffer_techniques" / "results.csv"
    if not path.exists():
        raise Missing(["sweeps/nbuffer_techniques/results.csv"])
    rep.used(path, "the N-buffer unit that pays")
    _, rows = read_csv(path, ["trace", "status", "role", "cycles_per_frame", "efficiency_lost"])
    per, sentence = pays.summarize([r for r in rows if r["status"] == "ok" and r["role"] == "sweep"])
    if not per:
        raise BadInput(f"{path}: no technique with an N-buffer unit ran its default design")
    cell = lambda c, e: f"{c:,.0f} ({100 * e:.2f})"
    table = rep.table("nbuffer_pays",
                      [("technique", "technique", None), ("the best N-buffer design", "best", None),
                       ("cycles a frame (error, points of %)", "best_cell", None), ("the default design", "default_cell", None),
                       ("the other culling: cycles a frame (error)", "others_cell", None)],
                      [{"technique": t["technique"], "best": t["best"], "best_cell": cell(t["best_cycles"], t["best_error"]),
                        "default_cell": cell(t["default_cycles"], t["default_error"]),
                        "others_cell": "; ".join(f"{o}: {cell(c, e)}" for o, c, e in t["others"]) or "-"} for t in per])
    return (f"<p>One N-buffer unit design (update policy, clear, resolution divisor, storage format) replayed on every technique "
            f"that has an N-buffer unit, every update, clear and query counted in the cycles; per technique the cheapest design that "
            f"loses no more than the default unit, beside its other culling. {html.escape(sentence)}</p>" + table)


# Sections before Table 1 (report.py): the headline question, whether an N-buffer unit pays.
LEADING = [("nbuffer-pays", "The N-buffer unit that pays: the best design per technique, upkeep counted", nbuffer_pays,
            "sweeps/nbuffer_techniques/results.csv")]

# (anchor, title, build(rep), main input relative to DIR): the page's sections in this order.
SECTIONS = [
    ("table2", "Table 2: depth tests per frame in the walkthrough", table2, "table2/table2.json"),
    ("walkthrough", "Depth tests per frame along the walkthrough", walkthrough, "table2"),
]
# What these sections look for, for report.py's "nothing usable" message.
INPUTS = ["table2/table2.json", "table2/MODE/run.json"]
