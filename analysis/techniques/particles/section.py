"""The report's particles section, from the particles table (`nbsim particles TRACE... --out DIR/particles`).

It shows per mode the paper's claim beside the model's depth tests, popping and false culls.

Loaded by analysis/report.py with every analysis/techniques/<name>/section.py (NAME, TITLE, ORDER
and section(rep), which returns the section's HTML or raises report_data.Missing / BadInput); report.py
puts analysis/ on the import path first.
"""
import html

from report_plots import (FIGSIZE, THOUSANDS)  # first: it selects the headless backend
import matplotlib.pyplot as plt
import numpy as np
from report_data import (BadInput, Missing, _modes, cell, load_rows, trace_name)

NAME = "particles"
TITLE = "Particles: depth tests per frame beside the paper's claim"
ORDER = 1  # the sections' order on the page and in headline.md


PARTICLE_MODES = ["none", "center", "nb", "hiz"]


# What a row of particles.json (nbsim particles --out) must hold for the report's table and reading.
PARTICLE_NEED = ["mode", "particles_per_frame", "culled_per_frame", "query_depth_tests_per_frame",
                 "raster_depth_tests_per_frame", "build_texels_per_frame", "total_depth_tests_per_frame",
                 "cycles_per_frame", "popping", "false_culls"]


# The paper's claim (Décoret 2005, 3.2 and 4.3) for 16 px sprites: rasterizing them costs 256 N depth
# tests, the N-buffer N (one lookup each); nbsim particles writes it as paper_depth_tests_per_frame.
PAPER_RASTER_PER_SPRITE = 256


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


def section(rep):
    path = rep.technique_table_path(NAME)
    if path is None:
        raise Missing(["particles/particles.json"])
    rows = particles_rows(load_particles(path))
    rep.used(path, "particles")
    for r in rows:
        r["trace_name"] = trace_name(str(r.get("trace", "?")))
    cols = [("mode", "mode", None), ("sprite (px)", "sprite", None), ("trace", "trace_name", None),
            ("sprites/frame", "particles_per_frame", None),
            ("paper depth tests/frame", "paper_depth_tests_per_frame", None),
            ("ours / paper", "ours_over_paper", lambda v: "-" if v is None else f"{v:.3g}"),
            ("culled/frame", "culled_per_frame", None),
            ("query depth tests/frame", "query_depth_tests_per_frame", None),
            ("raster depth tests/frame", "raster_depth_tests_per_frame", None),
            ("build texels/frame", "build_texels_per_frame", None),
            ("total depth tests/frame", "total_depth_tests_per_frame", None),
            ("cycles/frame", "cycles_per_frame", None), ("popping", "popping", None),
            ("false culls", "false_culls", None), ("decisions unlike GL's", "decision_mismatches", None)]
    tab = rep.table("particles", cols, rows,
                     row_class=lambda r: "bad" if r["popping"] or r["false_culls"] else "")
    reading = particles_reading(rows)
    traces = ", ".join(dict.fromkeys(r["trace_name"] for r in rows))
    rep.headline_last.append(headline_particles(traces, rows, reading))

    # per mode: the paper's claim beside ours, split into queries, sprite fragments and build
    fig, ax = plt.subplots(figsize=FIGSIZE, constrained_layout=True)
    x = np.arange(len(rows))
    wd = 0.38
    paper = [r.get("paper_depth_tests_per_frame") or np.nan for r in rows]
    ax.bar(x - wd / 2, paper, wd, label="paper's claim (16 px: 256 N none, N nb)", color="#999999", hatch="//",
           edgecolor="white")
    bottom = np.zeros(len(rows))
    for key, label, colour in (("query_depth_tests_per_frame", "ours: queries", "#b2182b"),
                               ("raster_depth_tests_per_frame", "ours: sprite fragments", "#6fa8dc"),
                               ("build_texels_per_frame", "ours: N-buffer / Hi-Z build", "#fdb863")):
        v = np.array([float(r[key]) for r in rows])
        ax.bar(x + wd / 2, v, wd, bottom=bottom, label=label, color=colour)
        bottom += v
    for i, r in enumerate(rows):  # the queries and the paper's N are too small to see: their numbers
        note = f"queries {r['query_depth_tests_per_frame']:,.0f}"
        if r["popping"]:
            note += f"\npops {r['popping']:,.0f}"
        ax.annotate(note, (x[i] + wd / 2, bottom[i]), xytext=(0, 3), textcoords="offset points", ha="center",
                    va="bottom", fontsize=7, color="#a00" if r["popping"] else "#222")
        if not np.isnan(paper[i]):
            ax.annotate(f"{paper[i]:,.0f}", (x[i] - wd / 2, paper[i]), xytext=(0, 3), textcoords="offset points",
                        ha="center", va="bottom", fontsize=7, color="#555")
    tallest = max([b for b in bottom] + [p for p in paper if not np.isnan(p)] + [1])
    ax.set_ylim(0, tallest * 1.35)  # headroom: the legend sits above the bars
    ax.yaxis.set_major_formatter(THOUSANDS)
    ax.set_xticks(x, [f"{r['mode']}\n{r.get('sprite') or ''} px" if str(r.get("sprite", "")).isdigit()
                      else f"{r['mode']}\n{r.get('sprite') or ''}" for r in rows])
    ax.set_xlabel("vertex-stage culling mode")
    ax.set_ylabel("depth tests per frame")
    ax.set_title(f"Particles: depth tests per frame, paper vs nbsim ({traces})", fontsize=10)
    ax.grid(axis="y", alpha=0.3)
    ax.legend(fontsize=7, loc="upper left", ncols=2)
    img = rep.save(fig, "particles.png")
    settings = sorted({s for r in rows for s in (r.get("settings") or [])})
    other_mode = [f"{r['trace_name']} captured in {r['capture_mode']}" for r in rows
                  if r.get("capture_mode") and r["capture_mode"] != r["mode"]]
    setting_text = ("settings: <code>" + html.escape(" ".join(f"--set {s}" if not s.startswith("--") else s
                                                               for s in settings)) + "</code>") if settings else \
        ("the model's default settings" if all("settings" in r for r in rows) else "their settings are not recorded there")
    mode_text = ("each in the culling mode it was captured in on Mesa" if not other_mode else
                 "in the mode of the row (particles.mode; " + html.escape(", ".join(other_mode)) + ")")
    return (f"<p>From <code>{rep.rel(path)}</code> (<code>nbsim particles TRACE... --out</code>: one replay per "
            f"trace, {mode_text}; traces {html.escape(traces)}; {setting_text}). "
            "The paper's claim (Décoret 2005, 3.2 and 4.3) is for 16 px sprites: rasterizing N sprites costs "
            "256 N depth tests, the N-buffer N. Ours / paper compares nb's query depth tests and none's total "
            "with it. Query: texels the culling test reads; raster: depth tests of GL's sprite fragments (its "
            "draws replayed); build: N-buffer or Hi-Z texels written; total: their sum. Popping and false "
            "culls are counted over every frame; rows with any are red (center pops by design).</p>" + tab +
            "<p><b>What it shows</b> (computed from the table):</p><ul>" +
            "".join(f"<li>{html.escape(s)}</li>" for s in reading) + "</ul>" +
            rep.figure(img, "Per mode: the paper's claim (grey, 16 px sprites only) and ours, stacked: the "
                        "culling test's queries (red), the sprite fragments GL drew (blue) and the N-buffer or "
                        "Hi-Z build (orange). Read off: how small the N-buffer's queries are against "
                        "rasterizing every sprite, and whether the build eats what culling saves."))
