"""Occlusion culling's results in docs/results.md (the N-buffer paper's walkthrough, Figure 4) and the
samples' summary, generated (the protocol: analysis/doc_results.py)."""
import json
import os
import tempfile
from pathlib import Path

from doc_results import Block

PAGE = "results.md"
WALK = "traces/samples/city_walk_512.nbt"
SAMPLES = sorted(p.name for p in (Path(__file__).resolve().parents[3] / "traces" / "samples").glob("*.nbt"))
GRAINS = [("nb_hier", "object"), ("nb_hier", "primitive"), ("hiz_tile", "object"), ("hiz_tile", "primitive")]


def n(v, digits=0):
    return f"{v:,.{digits}f}"


def signed(v, digits=0):
    return f"{v:+,.{digits}f}"


def render_primitive(outputs):
    runs = {g: json.loads(text)["summary"]["cull"] for g, text in zip(GRAINS, outputs[len(GRAINS):])}
    lines = ["| mode | triangles tested / frame | culled | lookups | drawn depth tests | query depth tests | "
             "total depth tests | cycles | false culls (objects, triangles) |", "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for mode in ("nb_hier", "hiz_tile"):
        o, p = runs[(mode, "object")], runs[(mode, "primitive")]
        lines.append(f"| {mode}, object | | | | {n(o['drawn_depth_tests_per_frame'])} | {n(o['query_depth_tests_per_frame'])} | "
                     f"{n(o['total_depth_tests_per_frame'])} | {n(o['cycles_per_frame'])} | {o['false_culls']} |")
        lines.append(f"| {mode}, primitive | {n(p['primitive_tests_per_frame'])} | {n(p['primitives_culled_per_frame'])} | "
                     f"{n(p['primitive_lookups_per_frame'])} | {n(p['drawn_depth_tests_per_frame'])} "
                     f"({signed(p['drawn_depth_tests_per_frame'] - o['drawn_depth_tests_per_frame'])}) | "
                     f"{n(p['query_depth_tests_per_frame'])} | {n(p['total_depth_tests_per_frame'])} "
                     f"({signed(100 * (p['total_depth_tests_per_frame'] / o['total_depth_tests_per_frame'] - 1), 2)}%) | "
                     f"{n(p['cycles_per_frame'])} ({signed(100 * (p['cycles_per_frame'] / o['cycles_per_frame'] - 1), 2)}%) | "
                     f"{p['false_culls']}, {p['primitive_false_culls']} |")
    return "\n".join(lines)


def render_figure4(outputs):
    import plot_coverage  # matplotlib, headless: only when rendering this block
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "fig4.csv")
        Path(path).write_text(outputs[-1], encoding="utf-8")
        _, _, maps, lookups, _ = plot_coverage.load(path)
    s = plot_coverage.summary(maps, lookups)
    names = {"paper": "the paper's covering (Figure 3)", "corners": "nbsim's earlier corner covering", "one": "one square",
             "rect": "the rectangle levels"}
    lines = ["| covering | mean extra pixels | worst (x the box) | exact sizes | mean lookups |", "|---|---:|---:|---:|---:|"]
    for key, label in names.items():
        if key in s:
            c = s[key]
            lookups_text = f"{c['mean_lookups']:.2f}" if c["mean_lookups"] is not None else "-"
            lines.append(f"| {label} | {100 * c['mean_extra']:.1f}% | {c['worst_extra']:.0f} | "
                         f"{100 * c['exact_fraction']:.1f}% | {lookups_text} |")
    return "Over every box size from 1x1 to 256x256:\n\n" + "\n".join(lines)


def draws(c):
    """GL's draws replayed exactly; a program that runs its own passes (no recorded draw replayed as
    such) compares its own results with GL's, which the thresholds include."""
    return f"{c['draws_exact']:,} of {c['draws']:,}" if c["draws"] else "(its program's own passes)"


def render_samples(outputs):
    infos, compares = outputs[:len(SAMPLES)], outputs[len(SAMPLES):]
    lines = ["| sample | technique | viewport | frames | MB | draws exact (`nbsim compare`) | within the thresholds |",
             "|---|---|---|---:|---:|---:|---|"]
    for name, info, c in zip(SAMPLES, infos, compares):
        p = info["properties"]
        lines.append(f"| `{name}` | {p.get('technique', '')} | {p.get('viewport', '')} | {info['frames'] if isinstance(info['frames'], int) else len(info['frames'])} | "
                     f"{info['bytes'] / 1e6:.1f} | {draws(c)} | {'yes' if c['within_thresholds'] else 'NO'} |")
    total = sum(i["bytes"] for i in infos)
    return "\n".join(lines) + f"\n\n{len(SAMPLES)} samples, {total / 1e6:.1f} MB in all."


BLOCKS = [
    Block("primitive", [["replay", WALK, "--set", f"cull.mode={m}", "--set", f"cull.granularity={g}", "--out", f"{m}_{g}"]
                        for m, g in GRAINS], render_primitive, files=tuple(f"{m}_{g}/run.json" for m, g in GRAINS)),
    Block("figure4", [["nbuffer", "coverage", "--size", "256x256", "--out", "fig4.png"]], render_figure4, files=("fig4.csv",)),
    Block("samples", [["trace", "info", f"traces/samples/{s}", "--json"] for s in SAMPLES] +
          [["compare", f"traces/samples/{s}", "--json"] for s in SAMPLES], render_samples),
]
