"""The report's real-application section: a recorded program's draw calls culled in every cull mode
(`nbsim table2 APPS_TRACE --out DIR/apps`), beside the city walkthrough's Table 2 (DIR/table2/table2.json,
the occlusion culling section's input) when the report has it.

Per cull mode and program: query depth tests, the query structure's upkeep, the drawn depth tests, their
total, cycles, culling efficiency and false culls, all per frame.

Loaded by analysis/report.py with every analysis/techniques/<name>/section.py (NAME, TITLE, ORDER and
section(rep), which returns the section's HTML or raises report_data.Missing / BadInput); report.py puts
analysis/ on the import path first.
"""
import html

from report_plots import FIGSIZE, THOUSANDS  # first: it selects the headless backend
import matplotlib.pyplot as plt
import numpy as np
from report_data import BadInput, Missing, check_rows, load_json, pct, trace_name

NAME = "apps"
TITLE = "A real program: its draw calls culled in every mode, beside the city walkthrough"
ORDER = 5
INPUTS = ["apps/table2.json"]

MODES = ["none", "oq_hier", "oq", "nb_hier", "nb", "hiz_tile", "hiz_pyramid"]
NEED = ["mode", "query_depth_tests_per_frame", "total_depth_tests_per_frame", "cycles_per_frame", "false_culls",
        "culling_efficiency"]
NUMBERS = NEED[1:] + ["update_texels_per_frame", "drawn_depth_tests_per_frame", "culled_per_frame", "draws_per_frame"]


def load_table(path, what):
    """A `nbsim table2 --out` table (an object with a non-empty rows list), its rows checked; BadInput otherwise."""
    t = load_json(path)
    if not isinstance(t, dict) or not isinstance(t.get("rows"), list) or not t["rows"]:
        raise BadInput(f"{path}: expected an object with a non-empty \"rows\" list ({what})")
    check_rows(path, "rows", t["rows"], NEED, ["mode"], NUMBERS, counts=["false_culls"])
    return t


def ordered(rows):
    return sorted(rows, key=lambda r: MODES.index(r["mode"]) if r["mode"] in MODES else len(MODES))


def reading(program, rows):
    """What one program's rows show, as sentences computed from them."""
    by = {r["mode"]: r for r in rows}
    out = []
    culling = [r for r in rows if r["mode"] != "none"]
    if not culling:
        return out
    best = min(culling, key=lambda r: r["total_depth_tests_per_frame"])
    out.append(f"{program}: fewest depth tests in total (queries, upkeep and drawing) with {best['mode']} "
               f"({best['total_depth_tests_per_frame']:,.0f} a frame)"
               + (f", against {by['none']['total_depth_tests_per_frame']:,.0f} drawing every draw call (none)"
                  if "none" in by else "") + ".")
    fastest = min(culling, key=lambda r: r["cycles_per_frame"])
    out.append(f"{program}: fewest cycles with {fastest['mode']} ({fastest['cycles_per_frame']:,.0f} a frame"
               + (f"; none {by['none']['cycles_per_frame']:,.0f}" if "none" in by else "") + ").")
    if "oq" in by and "nb" in by and by["nb"]["query_depth_tests_per_frame"]:
        out.append(f"{program}: occlusion queries read {by['oq']['query_depth_tests_per_frame'] / by['nb']['query_depth_tests_per_frame']:,.0f} "
                   "times the depth values the N-buffer's queries read.")
    for m in ("nb", "nb_hier", "hiz_tile", "hiz_pyramid"):
        r = by.get(m)
        if r and r.get("update_texels_per_frame") and r.get("drawn_depth_tests_per_frame"):
            out.append(f"{program}: {m} keeps its structure current with {r['update_texels_per_frame']:,.0f} texels a frame, "
                       f"{r['update_texels_per_frame'] / r['drawn_depth_tests_per_frame']:.2f} times the depth tests it draws.")
    eff = [f"{r['mode']} {100 * r['culling_efficiency']:.1f}%" for r in culling if r.get("culling_efficiency") is not None]
    if eff:
        out.append(f"{program}: culling efficiency " + ", ".join(eff) + ".")
    bad = [r["mode"] for r in rows if r.get("false_culls")]
    out.append(f"{program}: FALSE CULLS in {', '.join(bad)}." if bad else f"{program}: no mode culls a draw that GL drew.")
    return out


def section(rep):
    path = rep.root / "apps" / "table2.json"
    if not path.exists():
        raise Missing(["apps/table2.json"])
    t = load_table(path, "nbsim table2 APPS_TRACE --out DIR/apps")
    rep.used(path, "apps")
    if t.get("nbsim_version"):
        rep.versions.add(str(t["nbsim_version"]))
    program = trace_name(str(t.get("trace", "?")))
    rows = []
    for r in ordered(t["rows"]):
        rows.append(dict(r, program=program))
    city_path = rep.root / "table2" / "table2.json"
    city = None
    if city_path.exists():
        try:
            city = load_table(city_path, "nbsim table2 --out DIR/table2")
            rep.used(city_path, "apps")
        except BadInput:
            city = None  # the occlusion culling section names the problem
    city_name = trace_name(str(city.get("trace", "?"))) if city else None
    city_rows = [dict(r, program=city_name) for r in ordered(city["rows"])] if city else []
    cols = [("program", "program", None), ("mode", "mode", None),
            ("query depth tests/frame", "query_depth_tests_per_frame", None),
            ("upkeep texels/frame", "update_texels_per_frame", None),
            ("drawn depth tests/frame", "drawn_depth_tests_per_frame", None),
            ("total depth tests/frame", "total_depth_tests_per_frame", None),
            ("cycles/frame", "cycles_per_frame", None),
            ("culled/frame", "culled_per_frame", None),
            ("culling efficiency", "culling_efficiency", pct), ("false culls", "false_culls", None)]
    tab = rep.table("apps", cols, rows + city_rows, row_class=lambda r: "bad" if r.get("false_culls") else "")
    sentences = reading(program, rows) + (reading(city_name, city_rows) if city_rows else [])
    lines = [f"Culling a real program's draw calls ({program}) beside the city walkthrough"
             + (f" ({city_name})" if city_name else " (not in this report)") + ": depth tests per frame", "",
             "| program | mode | query | upkeep | total | cycles | culling efficiency | false culls |",
             "|---|---|---:|---:|---:|---:|---:|---:|"]
    for r in rows + city_rows:
        e = r.get("culling_efficiency")
        lines.append(f"| {r['program']} | {r['mode']} | {r['query_depth_tests_per_frame']:,.0f} | "
                     f"{(r.get('update_texels_per_frame') or 0):,.0f} | {r['total_depth_tests_per_frame']:,.0f} | "
                     f"{r['cycles_per_frame']:,.0f} | {'-' if e is None else f'{100 * e:.1f}%'} | {int(r.get('false_culls') or 0)} |")
    rep.headline_last.append("\n".join(lines + [""] + [f"- {s}" for s in sentences]))

    # Per program and mode: the total depth tests split into queries, upkeep and drawing, relative to
    # the program's cheapest mode (programs differ by orders of magnitude).
    fig, axes = plt.subplots(1, 2 if city_rows else 1, figsize=(FIGSIZE[0] * (1.6 if city_rows else 1), FIGSIZE[1]),
                             constrained_layout=True, squeeze=False)
    for ax, (name, rr) in zip(axes[0], [(program, rows)] + ([(city_name, city_rows)] if city_rows else [])):
        x = np.arange(len(rr))
        bottom = np.zeros(len(rr))
        for key, label, colour in (("query_depth_tests_per_frame", "queries", "#b2182b"),
                                   ("update_texels_per_frame", "structure upkeep", "#fdb863"),
                                   ("drawn_depth_tests_per_frame", "drawing", "#6fa8dc")):
            v = np.array([float(r.get(key) or 0) for r in rr])
            if key == "drawn_depth_tests_per_frame" and not any(v):  # a table without the split: the rest of the total
                v = np.array([float(r["total_depth_tests_per_frame"]) for r in rr]) - bottom
            ax.bar(x, v, 0.6, bottom=bottom, label=label, color=colour)
            bottom += v
        for i, r in enumerate(rr):
            e = r.get("culling_efficiency")
            ax.annotate("-" if e is None else f"{100 * e:.0f}%", (x[i], bottom[i]), xytext=(0, 3), textcoords="offset points",
                        ha="center", va="bottom", fontsize=7, color="#a00" if r.get("false_culls") else "#222")
        ax.set_xticks(x, [r["mode"] for r in rr], rotation=20)
        ax.set_ylim(0, max(bottom.max(), 1) * 1.2)
        ax.yaxis.set_major_formatter(THOUSANDS)
        ax.set_ylabel("depth tests per frame")
        ax.set_title(name, fontsize=9)
        ax.grid(axis="y", alpha=0.3)
        ax.legend(fontsize=7, loc="upper left")
    img = rep.save(fig, "apps.png")
    settings = ", ".join(f"<code>{html.escape(str(s))}</code>" for s in (t.get("settings") or [])) or "the defaults"
    return (f"<p>From <code>{rep.rel(path)}</code> (<code>nbsim table2 {html.escape(str(t.get('trace', '?')))} --out</code>, "
            f"settings: {settings})"
            + (f" and <code>{rep.rel(city_path)}</code> (the walkthrough's Table 2)" if city_rows else
               " (the walkthrough's Table 2, DIR/table2/table2.json, is not in this report)")
            + ". The program never asked for culling: each of its draw calls is an object, tested in submission "
            "order against the depth its render target holds then (its bounds from its clip positions after setup), "
            "and its ground truth is GL's samples passed. Culling efficiency is the share of the tested draws GL "
            "passed no sample of that the mode culled; a false cull is a culled draw GL drew samples of. Upkeep: "
            "texels the N-buffer or Hi-Z recomputed to stay current.</p>" + tab +
            "<p><b>What it shows</b> (computed from the table):</p><ul>" +
            "".join(f"<li>{html.escape(s)}</li>" for s in sentences) + "</ul>" +
            rep.figure(img, "Per cull mode, the depth tests of a frame: queries (red), the structure's upkeep "
                            "(orange) and drawing (blue), with the culling efficiency above each bar; the real "
                            "program on the left, the city walkthrough on the right."))
