"""The report's shadows section, from the shadows table (`nbsim shadows TRACE... --out DIR/shadows`).

It shows fill per scene and mode against the infinite volumes and the paper's ratios, the mask against GL's.

Loaded by analysis/report.py with every analysis/techniques/<name>/section.py (NAME, TITLE, ORDER
and section(rep), which returns the section's HTML or raises report_data.Missing / BadInput); report.py
puts analysis/ on the import path first.
"""
import html

from report_plots import FIGSIZE  # first: it selects the headless backend
import matplotlib.pyplot as plt
from report_data import (BadInput, Missing, _order, load_rows, pct, trace_name)

NAME = "shadows"
TITLE = "Shadows: fill per frame beside the paper's ratios"
ORDER = 2  # the sections' order on the page and in headline.md


SHADOW_SCENES = ["boxes", "terrain", "city"]


SHADOW_MODES = ["infinite", "culled", "clamped"]


# The camera paths: the flyover first, then the paper's observer on the ground.
SHADOW_PATHS = ["fly", "ground", "walk"]


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


def shadows_rows(rows):
    """The rows by scene (boxes, terrain, city, then others), mode (infinite, culled, clamped) and litmap size, each
    with casters_culled_per_frame (GL's culls, outside the light's frustum included), ratio (fill over GL's
    infinite fill of the same frames: the row's ratio_to_infinite, else fill / reference_fill) and the paper's
    ratio for clamped rows."""
    out = []
    for r in sorted(rows, key=lambda r: (_order(SHADOW_SCENES, r["scene"]), r["scene"], _order(SHADOW_PATHS, r.get("path", "")),
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
        rr["path"] = r.get("path") or ""
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
    several_paths = {sc for sc in (r["scene"] for r in rows) if len({r["path"] for r in rows if r["scene"] == sc}) > 1}
    for scene, path in dict.fromkeys((r["scene"], r["path"]) for r in rows):
        g = [r for r in rows if r["scene"] == scene and r["path"] == path]
        if scene in several_paths:
            scene = f"{scene} ({path} path)"
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
             "| scene | path | mode | litmap | fill | ratio | paper | casters culled | build | lookups | cycles | mask px differing |",
             "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(f"| {r['scene']} | {r['path'] or '-'} | {r['shadow_mode']} | {r.get('litmap_size') or '-'} | {r['fill_per_frame']:,.0f} | "
                     f"{pct(r['ratio'])} | {r['paper_text'] or '-'} | "
                     f"{r['casters_culled_per_frame']:,.1f} of {r['casters_per_frame']:,.0f} | "
                     f"{r['build_texels_per_frame']:,.0f} | {r['lookups_per_frame']:,.0f} | {r['cycles_per_frame']:,.0f} | "
                     f"{r['mask_diff']:,}, {r['mask_diff_infinite']:,} |")
    return "\n".join(lines + [""] + [f"- {s}" for s in reading])


def section(rep):
    path = rep.technique_table_path(NAME)
    if path is None:
        raise Missing(["shadows/shadows.json"])
    rows = shadows_rows(load_shadows(path))
    rep.used(path, "shadows")
    for r in rows:
        r["trace_name"] = trace_name(str(r.get("trace", "?")))
    ratio = lambda v: "-" if v is None else f"{100 * v:.1f}%"  # noqa: E731
    cols = [("scene", "scene", None), ("path", "path", None), ("mode", "shadow_mode", None), ("litmap (lexels)", "litmap_size", None),
            ("trace", "trace_name", None), ("frames", "frames", None),
            ("fill/frame", "fill_per_frame", None), ("ratio to infinite", "ratio", ratio),
            ("paper", "paper_text", lambda v: v or "-"),
            ("casters/frame", "casters_per_frame", None), ("casters culled/frame", "casters_culled_per_frame", None),
            ("N-buffer build texels/frame", "build_texels_per_frame", None),
            ("N-buffer lookups/frame", "lookups_per_frame", None), ("cycles/frame", "cycles_per_frame", None),
            ("mask px differing (GL's)", "mask_diff", None),
            ("mask px differing (infinite)", "mask_diff_infinite", None)]
    tab = rep.table("shadows", cols, rows, row_class=lambda r: "bad" if r["mask_pixels_differing"] else "")
    reading = shadows_reading(rows)
    traces = ", ".join(dict.fromkeys(r["trace_name"] for r in rows))
    label = (traces if len(rows) <= 3 else
             f"{len(rows)} traces of {', '.join(dict.fromkeys(r['scene'] for r in rows))}")
    rep.headline_last.append(headline_shadows(label, rows, reading))

    # per scene: one bar per mode (and litmap size), log scale; the paper's clamped ratio marked on the
    # clamped bars as the fill it would give (paper ratio x the trace's infinite reference fill)
    fig, ax = plt.subplots(figsize=FIGSIZE, constrained_layout=True)
    colours = {"infinite": "#999999", "culled": "#6fa8dc", "clamped": "#b2182b"}
    groups = list(dict.fromkeys((r["scene"], r["path"]) for r in rows))
    several = len({p for _, p in groups}) > 1
    x, ticks, labels = 0.0, [], []
    marked = False
    for scene, camera in groups:
        g = [r for r in rows if r["scene"] == scene and r["path"] == camera]
        start = x
        for r in g:
            v = max(float(r["fill_per_frame"]), 1.0)  # log scale: an empty fill sits on the floor
            ax.bar(x, v, 0.8, color=colours.get(r["shadow_mode"], "#555555"),
                   label=r["shadow_mode"] if r["shadow_mode"] not in ax.get_legend_handles_labels()[1] else None)
            text = ratio(r["ratio"]) + (f"\n{r['litmap_size']}" if len(g) > len({x["shadow_mode"] for x in g}) else "")
            ax.annotate(text, (x, v), xytext=(0, 2), textcoords="offset points", ha="center", va="bottom", fontsize=7)
            ref = r.get("reference_fill_per_frame")
            if r["paper_ratio"] is not None and ref:
                ax.plot([x - 0.45, x + 0.45], [r["paper_ratio"] * ref] * 2, color="black", lw=2, ls="--",
                        label=None if marked else "paper's clamped / infinite ratio x our infinite fill")
                marked = True
            x += 1
        ticks.append((start + x - 1) / 2)
        labels.append(f"{scene}\n{camera}" if several else scene)
        x += 0.8
    ax.set_yscale("log")
    ax.set_ylim(top=ax.get_ylim()[1] * 4)  # headroom for the labels and the legend
    ax.set_xticks(ticks, labels)
    ax.set_xlabel("scene (and camera path)" if several else "scene")
    ax.set_ylabel("shadow-volume fill per frame (fragments, log scale)")
    ax.set_title(f"Shadows: fill per frame by mode, beside the paper's ratio ({len(rows)} traces)", fontsize=10)
    ax.grid(axis="y", alpha=0.3, which="both")
    ax.legend(fontsize=7, loc="upper left", ncols=2)
    img = rep.save(fig, "shadows.png")
    settings = sorted({s for r in rows for s in (r.get("settings") or [])})
    setting_text = ("settings: <code>" + html.escape(" ".join(f"--set {s}" for s in settings)) + "</code>") if settings \
        else ("the model's default settings" if all("settings" in r for r in rows) else "their settings are not recorded there")
    return (f"<p>From <code>{rep.rel(path)}</code> (<code>nbsim shadows TRACE... --out</code>: one replay per trace, "
            f"traces {html.escape(traces)}, each in the shadow mode it was captured in on Mesa; {setting_text}). Fill: rasterized fragments of "
            "the shadow-volume draws; ratio: the fill over GL's infinite volumes of the same frames (every capture "
            "also draws them as a reference). Path: fly, the camera about 130 m up, above the birds; ground, the paper's "
            "set-up, an observer at eye height with the birds above the view and their shadows in it. The paper (Décoret 2005, 4.4, 640x480) gives clamped / infinite: "
            "2.5% in its city (20 M -> 512 K pixels) and on its terrain, about 20% on simpler scenes. Casters "
            "culled: by GL, outside the light's frustum included. N-buffer build and lookups: texels of both "
            "litmap N-buffers (min and max) built and read per frame. Mask pixels differing: the model's shadow "
            "mask against GL's and against GL's infinite reference, over every frame; rows with any are red."
            "</p>" + tab +
            "<p><b>What it shows</b> (computed from the table):</p><ul>" +
            "".join(f"<li>{html.escape(s)}</li>" for s in reading) + "</ul>" +
            rep.figure(img, "Per scene: the fill per frame of each mode (log scale: grey infinite, blue culled, red "
                        "clamped; the number on a bar is its ratio to infinite) and, dashed, the fill the paper's "
                        "ratio would give on our infinite volumes. Read off: how far clamping goes toward the "
                        "paper's figure in each scene."))
