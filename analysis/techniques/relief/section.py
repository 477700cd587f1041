"""The report's relief section, from the relief table (`nbsim relief TRACE... --out DIR/relief`).

It shows each method's cost against hit error, the ranking, the N-buffer walk, the paper's Table 1.

Loaded by analysis/report.py with every analysis/techniques/<name>/section.py (NAME, TITLE, ORDER
and section(rep), which returns the section's HTML or raises report_data.Missing / BadInput); report.py
puts analysis/ on the import path first.
"""
import csv
import html

from report_plots import (THOUSANDS, freeze_layout, place_labels)  # first: it selects the headless backend
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.ticker import MaxNLocator
from report_data import (BadInput, Missing, _modes, _order, cell, check_rows, load_json, pct, trace_name)

NAME = "relief"
TITLE = "Relief textures: the methods' cost against hit error, the N-buffer walk, the paper's Table 1"
ORDER = 4  # the sections' order on the page and in headline.md


RELIEF_METHODS = ["binary", "exact", "robust", "robust_clamp", "nbuffer"]
RELIEF_STYLE = {  # colour, marker per relief method: the N-buffer walk red as the N-buffer modes, the others apart
    "binary": ("#7f7f7f", "v"), "exact": ("#1f4e96", "s"), "robust": ("#1b7837", "^"),
    "robust_clamp": ("#a6dba0", "D"), "nbuffer": ("#b2182b", "o"),
}


def relief_style(method):
    return RELIEF_STYLE.get(method, ("#555555", "x"))


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
        rr.setdefault("storage_bytes_per_texel", None)  # nbsim relief before it reported storage
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


def section(rep):
    path = rep.technique_table_path(NAME)
    if path is None:
        raise Missing(["relief/relief.json"])
    doc = load_relief(path)
    rep.used(path, "relief")
    rows = doc["rows"]
    ranking = relief_ranking(doc)
    paper = relief_paper_rows(doc["paper"])
    reading = relief_reading(doc, ranking, paper)
    fields = list(dict.fromkeys(r["field"] for r in rows))
    sizes = sorted({r["field_size"] for r in rows})
    at = [f"{n}²" for n in sizes]
    label = (f"{len({r['trace'] for r in rows})} traces: {len(fields)} heightfields at "
             f"{' and '.join([', '.join(at[:-1]), at[-1]] if len(at) > 1 else at)}, "
             f"{len({r['frame'] for r in rows})} view angles each")
    rep.headline_last.append(headline_relief(label, ranking, reading))
    with open(rep.out / "relief_rows.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(RELIEF_LISTS["rows"][0]), extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    num = lambda d: (lambda v: "-" if v is None else f"{v:,.{d}f}")  # noqa: E731
    mismatched = lambda r: r["walk_mismatches"] or r["pixel_mismatches"] or r["fragments_unlike_gl"]  # noqa: E731
    for r in ranking:
        r["pareto_mark"] = "yes (front)" if r["pareto"] else "no"
    rank_tab = rep.table(
        "relief_ranking",
        [("method", "method", None), ("cycles/box draw (mean)", "cycles_per_frame", num(0)),
         ("lookups/fragment", "lookups_per_fragment", num(2)), ("steps/fragment", "steps_per_fragment", num(2)),
         ("fragments", "fragments", None), ("hit errors", "errors", None),
         ("hit error", "error_rate", lambda v: pct(v, 3)), ("Pareto", "pareto_mark", None),
         ("storage (bytes/texel)", "storage_bytes_per_texel", lambda v: "-" if v is None else f"{v:g}"),
         ("walks differing from GL's", "walk_mismatches", None),
         ("pixels differing from GL's", "pixel_mismatches", None),
         ("fragments unlike GL's count", "fragments_unlike_gl", None)],
        ranking, row_class=lambda r: "bad" if mismatched(r) else "pareto" if r["pareto"] else "")
    nve = doc["nbuffer_vs_exact"]
    nve_tab = rep.table(
        "relief_nbuffer_vs_exact",
        [("heightfield", "field", None), ("size", "field_size", None),
         ("exact: lookups/fragment", "exact_lookups_per_fragment", num(2)),
         ("N-buffer: lookups/fragment", "nbuffer_lookups_per_fragment", num(2)),
         ("N-buffer / exact", "lookup_ratio", num(3)), ("exact: hit errors", "exact_errors", None),
         ("N-buffer: hit errors", "nbuffer_errors", None), ("extra errors", "extra_errors", None)],
        nve, row_class=lambda r: "bad" if (r["extra_errors"] or 0) > 0 else "") if nve else \
        "<p>No heightfield has both an exact and an N-buffer walk.</p>"
    paper_tab = rep.table(
        "relief_paper",
        [("size", "field_size", None), ("method", "method", None), ("paper (Hz)", "paper_hz", num(0)),
         ("paper's rank (fastest first)", "paper_rank", None),
         ("ours: cycles/box draw (fbm)", "cycles_per_frame", num(0)),
         ("ours: lookups/fragment (fbm)", "lookups_per_fragment", num(2)),
         ("our rank (fewest cycles first)", "our_rank", None)], paper) if paper else \
        "<p>relief.json holds no paper rows.</p>"
    nve_reading = [s for s in reading if s.startswith("The N-buffer walk")]
    paper_reading = [s for s in reading if s.startswith("The paper ranks")]
    lead = [s for s in reading if s not in nve_reading + paper_reading]

    # left: cost against error, one point per method (the ranking), the Pareto front as a step line;
    # right: lookups per fragment per heightfield (field and size) and method, over every view angle
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(12, 4.8), constrained_layout=True,
                                 gridspec_kw={"width_ratios": [2, 3]})
    for r in ranking:
        c, mk = relief_style(r["method"])
        ax.scatter([r["cycles_per_frame"]], [100 * r["error_rate"]], s=60, marker=mk, color=c,
                   edgecolors="black" if r["pareto"] else c, linewidths=1.2 if r["pareto"] else 0.5, zorder=3)
    front = sorted((r for r in ranking if r["pareto"]), key=lambda r: r["cycles_per_frame"])
    if front:  # the step line runs on to the dearest method: what lies on or above it is dominated
        dearest = max(r["cycles_per_frame"] for r in ranking)
        ax.plot([r["cycles_per_frame"] for r in front] + [dearest],
                [100 * r["error_rate"] for r in front] + [100 * front[-1]["error_rate"]],
                drawstyle="steps-post", color="#b2182b", lw=1.2, alpha=0.7, zorder=1,
                label=f"Pareto front ({', '.join(r['method'] for r in front)})")
    bad = [r for r in ranking if mismatched(r)]
    if bad:
        ax.scatter([r["cycles_per_frame"] for r in bad], [100 * r["error_rate"] for r in bad], s=140, marker="x",
                   color="red", zorder=4, label="walks or pixels unlike GL's")
    ax.xaxis.set_major_formatter(THOUSANDS)
    ax.xaxis.set_major_locator(MaxNLocator(nbins=5))
    ax.set_xlabel("modelled cycles per box draw (mean over the frames)")
    ax.set_ylabel("hit error (% of fragments, against the exact reference)")
    ax.set_title("Cost against hit error, per method", fontsize=10)
    ax.grid(alpha=0.3)
    ax.margins(x=0.2, y=0.15)
    if front or bad:
        ax.legend(fontsize=7, loc="upper left")
    lookups = relief_lookups_by_field(rows)
    methods = [r["method"] for r in ranking]
    x = np.arange(len(lookups))
    wd = 0.8 / max(len(methods), 1)
    for j, m in enumerate(methods):
        c, _ = relief_style(m)
        bx.bar(x - 0.4 + wd * (j + 0.5), [v.get(m) or np.nan for v in lookups.values()], wd, color=c, label=m)
    # The generator's name alone ("fbm:0 seed 5" -> "fbm"), its size under it: the full description is in the table.
    bx.set_xticks(x, [f"{f.split(':')[0].split(' ')[0]}\n{n}²" for f, n in lookups], fontsize=7)
    bx.set_xlabel("heightfield and size")
    bx.set_ylabel("lookups per fragment")
    bx.set_title("Lookups per fragment, per heightfield and method", fontsize=10)
    bx.grid(axis="y", alpha=0.3)
    bx.legend(fontsize=7, ncols=len(methods), loc="upper left", title="method, cheapest first", title_fontsize=7)
    bx.set_ylim(0, max([v for d in lookups.values() for v in d.values() if v is not None] + [1]) * 1.2)
    fig.suptitle("Relief textures: the walks' cost and hit error")
    freeze_layout(fig)
    place_labels(ax, [r["cycles_per_frame"] for r in ranking], [100 * r["error_rate"] for r in ranking],
                 methods, [relief_style(m)[0] for m in methods], fontsize=8)
    img = rep.save(fig, "relief.png")
    settings = doc["settings"]
    setting_text = ("settings: <code>" + html.escape(" ".join(settings)) + "</code>") if settings else \
        "the model's default settings"
    loud = lambda s: (f'<b class="bad">{html.escape(s)}</b>' if s.startswith("GL AND THE MODEL DISAGREE")  # noqa: E731
                      else html.escape(s))
    items = lambda ss: "<ul>" + "".join(f"<li>{loud(s)}</li>" for s in ss) + "</ul>"  # noqa: E731
    return (f"<p>From <code>{rep.rel(path)}</code> (<code>nbsim relief TRACE... --out</code>: each relief trace, one "
            "heightfield at one size with a frame per view angle and a box draw per method, replayed in the model "
            f"with {setting_text}). Cycles: a method's box draw in the model, the mean over the frames; lookups and "
            "steps: heightfield texels read and walk steps per fragment; hit errors: fragments whose hit or miss "
            "differs from the exact reference beyond <code>relief.hit_tolerance_texels</code>. Walks and pixels "
            "differing: the model's against GL's; any is a bug (rows in red). Every row (trace, view angle, "
            'method) is in <a href="relief_rows.csv">relief_rows.csv</a>.</p>'
            "<p><b>What it shows</b> (computed from relief.json):</p>" + items(lead) +
            rep.figure(img, "Left: one point per method, x = modelled cycles per box draw, y = hit error; the "
                        "Pareto-optimal methods (no other is as cheap and as accurate, and better in one) are "
                        "outlined and joined by the front; red crosses would mark methods whose walks or pixels are "
                        "not GL's. Right: lookups per fragment per heightfield and size, one bar per method. Read "
                        "off: the cheapest method for an accepted hit error, and on which heightfields the N-buffer "
                        "walk saves lookups over the exact walk.") +
            "<h3>Ranking: cycles against hit error</h3>" + rank_tab +
            "<h3>The N-buffer walk against the exact walk, per heightfield</h3>" + items(nve_reading) + nve_tab +
            "<h3>The paper's Table 1 beside ours</h3>" + items(paper_reading) + paper_tab + figure12(rep))


def figure12_points(doc):
    """Per safety radius of the Figure 12 traces (strict; paper min / max at each epsilon): the robust
    search's cycles per box draw (mean over the frames), its hit error and the mean radius, and the
    same for robust_clamp, in epsilon order."""
    pts = {}
    for r in doc["rows"]:
        if r["method"] not in ("robust", "robust_clamp"):
            continue
        key = (r.get("radius") or "strict", r.get("radius_combine") or "", float(r.get("radius_epsilon") or 0.0))
        p = pts.setdefault(key, {"radius_mean": r.get("radius_mean")})
        m = p.setdefault(r["method"], [0.0, 0, 0, 0])  # cycles, rows, errors, fragments
        m[0] += r["cycles"]
        m[1] += 1
        m[2] += r["errors"]
        m[3] += r["fragments"]
    out = []
    for (kind, combine, eps), p in sorted(pts.items(), key=lambda kv: (kv[0][0] != "strict", kv[0][1], kv[0][2])):
        e = {"radius": kind, "combine": combine, "epsilon": eps, "radius_mean": p["radius_mean"]}
        for m in ("robust", "robust_clamp"):
            c = p.get(m)
            e[f"{m}_cycles"] = c[0] / c[1] if c and c[1] else None
            e[f"{m}_error"] = c[2] / c[3] if c and c[3] else None
        out.append(e)
    return out


def figure12(rep):
    """The paper's Figure 12 from DIR/relief_figure12/relief.json (the demo's epsilon series), or nothing."""
    path = rep.root / "relief_figure12" / "relief.json"
    if not path.is_file():
        return ""
    doc = load_relief(path)
    rep.used(path, "relief Figure 12")
    pts = figure12_points(doc)
    strict = next((p for p in pts if p["radius"] == "strict"), None)
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(12, 4.2), constrained_layout=True)
    for combine, colour in (("min", "#2166ac"), ("max", "#b2182b")):
        g = [p for p in pts if p["radius"] == "paper" and p["combine"] == combine]
        if not g:
            continue
        label = f"paper radius, {'maximum' if combine == 'max' else 'minimum'} over directions"
        ax.plot([p["epsilon"] for p in g], [p["robust_cycles"] for p in g], marker="o", color=colour, label=label)
        bx.plot([p["epsilon"] for p in g], [100 * p["robust_error"] for p in g], marker="o", color=colour, label=label)
    if strict:
        ax.axhline(strict["robust_cycles"], color="grey", ls="--", label="strict radius")
        bx.axhline(100 * strict["robust_error"], color="grey", ls="--", label="strict radius")
    ax.set_xlabel("allowed error epsilon (box heights)")
    ax.set_ylabel("robust search: cycles per box draw")
    ax.yaxis.set_major_formatter(THOUSANDS)
    bx.set_xlabel("allowed error epsilon (box heights)")
    bx.set_ylabel("robust search: hit error (% of fragments)")
    for a in (ax, bx):
        a.grid(alpha=0.3)
        a.legend(fontsize=7)
    fig.suptitle("The paper's Figure 12: the safety radius's allowed error against cost and hit error")
    img = rep.save(fig, "relief_figure12.png")
    tab = rep.table(
        "relief_figure12",
        [("radius", "radius", None), ("over directions", "combine", lambda v: v or "-"), ("epsilon", "epsilon", lambda v: f"{v:g}"),
         ("mean radius (texels)", "radius_mean", lambda v: "-" if v is None else f"{v:.2f}"),
         ("robust: cycles/box draw", "robust_cycles", lambda v: "-" if v is None else f"{v:,.0f}"),
         ("robust: hit error", "robust_error", lambda v: pct(v, 3)),
         ("robust_clamp: cycles/box draw", "robust_clamp_cycles", lambda v: "-" if v is None else f"{v:,.0f}"),
         ("robust_clamp: hit error", "robust_clamp_error", lambda v: pct(v, 3))], pts)
    return ("<h3>The paper's Figure 12: the safety radius's allowed error</h3>"
            f"<p>From <code>{rep.rel(path)}</code>: one fbm terrain captured with the strict safety radius and with the "
            "paper's (unblocked rays only, an allowed error epsilon: how far a ray may pass under the surface unnoticed), "
            "its texel radius the minimum or, as the paper's text says, the maximum over directions.</p>" +
            rep.figure(img, "Left: the robust search's cycles per box draw against epsilon; right: its hit error against "
                        "the exact reference. Read off: a larger epsilon buys speed with hit error, and the maximum "
                        "over directions errs even at epsilon 0, where the minimum stays exact.") + tab)
