"""Occlusion culling's results in docs/results.md (the N-buffer paper's walkthrough) and the samples'
summary, the covering's in docs/covering.md (Figure 4, the culling ladder) and the sweeps' in
docs/exploration.md, generated (the protocol: analysis/doc_results.py)."""
import json
import os
import tempfile
from pathlib import Path

import importlib.util
import pathlib

from doc_results import Block, pareto_front, thousands as n

PAGE = "results.md"

# The cross-technique reading of the N-buffer design sweep, shared with the report (pays.py).
_spec = importlib.util.spec_from_file_location("nbsim_occlusion_pays", pathlib.Path(__file__).with_name("pays.py"))
pays = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(pays)
WALK = "traces/samples/city_walk_512.nbt"
SAMPLES = sorted(p.name for p in (Path(__file__).resolve().parents[3] / "traces" / "samples").glob("*.nbt"))
GRAINS = [("nb_hier", "object"), ("nb_hier", "primitive"), ("hiz_tile", "object"), ("hiz_tile", "primitive")]



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
    Block("samples", [["trace", "info", f"traces/samples/{s}", "--json"] for s in SAMPLES] +
          [["compare", f"traces/samples/{s}", "--json"] for s in SAMPLES], render_samples),
]


COVERINGS = {"paper": "paper", "corners": "corners", "one": "one", "rect": "rectangle levels, every one",
             "rect_aspect1": "rectangle levels, sides at most 2x apart"}


def coverage(outputs):
    import plot_coverage  # matplotlib, headless: only when rendering
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "fig4.csv")
        Path(path).write_text(outputs[-1], encoding="utf-8")
        _, _, maps, lookups, cases = plot_coverage.load(path)
    return plot_coverage, maps, lookups, cases


def render_covering_figure4(outputs):
    pc, maps, lookups, cases = coverage(outputs)
    s = pc.summary(maps, lookups)
    lines = ["| covering | mean extra pixels (% of the box) | worst (x the box) | exact for (% of sizes) | lookups a box |",
             "|---|---:|---:|---:|---:|"]
    for key, c in s.items():
        lookups_text = f"{c['mean_lookups']:.2f}" if c["mean_lookups"] is not None else "-"
        lines.append(f"| {COVERINGS.get(key, key)} | {100 * c['mean_extra']:.1f}% | {c['worst_extra']:.0f}x | "
                     f"{100 * c['exact_fraction']:.1f}% | {lookups_text} |")
    shares = pc.case_shares(maps, cases)
    keys = list(s)
    lines += ["", "By the paper's five cases (each case's share of the box sizes, and each covering's mean extra area "
              "in it):", "", "| case | share | " + " | ".join(COVERINGS.get(k, k) for k in keys) + " |",
              "|---|---:|" + "---:|" * len(keys)]
    for c in shares:
        lines.append(f"| `{c['case']}` | {100 * c['share']:.1f}% | " +
                     " | ".join(f"{100 * c['extra'][k]:.1f}%" for k in keys) + " |")
    return "\n".join(lines)


def ladder_label(r):
    if r["cull.mode"] in ("oq", "oq_hier"):
        return f"occlusion queries (`{r['cull.mode']}`, the box itself)"
    if r["nbuffer.levels"] == "rect":
        k = int(r["nbuffer.max_aspect_log2"])
        return "rectangle levels, every one (the ideal rectangle test)" if k < 0 else \
            f"rectangle levels, sides at most {2 ** k}x apart"
    return f"{r['nbuffer.covering']}/{r['nbuffer.align']}"


def render_ladder(outputs):
    import csv
    import io
    rows = [r for r in csv.DictReader(io.StringIO(outputs[-1])) if r["status"] == "ok" and r["role"] == "sweep"]
    out = []
    for trace, scene in (("city_walk_512", "Walkthrough"), ("city_fly_512", "Flyover")):
        for mode, grain in (("nb_hier", "over the BVH"), ("nb", "every object flat")):
            pts = [r for r in rows if trace in r["trace"] and r["cull.mode"] == mode]
            oq = next(r for r in rows if trace in r["trace"] and r["cull.mode"] == f"oq{'_hier' if mode == 'nb_hier' else ''}")
            corners = next(r for r in pts if r["nbuffer.covering"] == "corners" and r["nbuffer.align"] == "bottom")
            ideal = next(r for r in pts if r["nbuffer.levels"] == "rect" and int(r["nbuffer.max_aspect_log2"]) < 0)
            lo, hi = float(corners["culling_efficiency"]), float(ideal["culling_efficiency"])
            out += [f"**{scene}, `{mode}`** ({grain}):", "",
                    "| covering | culling efficiency | gap closed | false culls | query depth tests / frame | "
                    "level update texels / frame | cycles / frame | level memory |", "|---|---:|---:|---:|---:|---:|---:|---:|"]
            for r in pts + [oq]:
                e = float(r["culling_efficiency"])
                gap = f"{100 * (e - lo) / (hi - lo):.0f}%" if r is not oq and hi > lo else ""
                mem = float(r["nbuffer_memory_bytes"] or 0)
                out.append(f"| {ladder_label(r)} | {100 * e:.2f}% | {gap} | {r['false_culls']} | "
                           f"{n(float(r['query_depth_tests_per_frame']))} | {n(float(r['update_texels_per_frame']))} | "
                           f"{n(float(r['cycles_per_frame']))} | {f'{mem / 2**20:,.0f} MiB' if mem else '-'} |")
            out.append("")
    return "\n".join(out)


def render_lazy(outputs):
    runs = [json.loads(t)["summary"]["cull"] for t in outputs[len(LAZY):]]
    return "\n".join(["| levels | level update texels / frame | cycles / frame | culling efficiency |", "|---|---:|---:|---:|"] +
                     [f"| {label} | {n(r['update_texels_per_frame'])} | {n(r['cycles_per_frame'])} | "
                      f"{100 * r['culling_efficiency']:.2f}% |" for (label, _), r in zip(LAZY, runs)])


def render_memory(outputs):
    lines = ["| viewport | square levels | rectangle levels (every one) | rectangle, sides at most 2x apart | "
             "rectangle, at most 4x |", "|---|---:|---:|---:|---:|"]
    per = len(MEMORY_KINDS)
    for i, size in enumerate(MEMORY_SIZES):
        cells = []
        for o in outputs[i * per:(i + 1) * per]:
            cells.append(f"{o['level_count']} levels, {o['memory_bytes'] / 2**20:,.1f} MiB")
        lines.append(f"| {size} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


LAZY = [("square levels", []), ("rectangle levels, sides at most 2x apart",
                                ["--set", "nbuffer.levels=rect", "--set", "nbuffer.max_aspect_log2=1"]),
        ("rectangle levels, every one", ["--set", "nbuffer.levels=rect", "--set", "nbuffer.max_aspect_log2=-1"])]
MEMORY_SIZES = ("256x256", "512x512", "640x480", "1024x1024")
MEMORY_KINDS = ([], ["--levels", "rect"], ["--levels", "rect", "--max-aspect-log2", "1"],
                ["--levels", "rect", "--max-aspect-log2", "2"])

BLOCKS += [
    Block("covering-figure4", [["nbuffer", "coverage", "--size", "256x256", "--out", "fig4.png"]], render_covering_figure4,
          files=("fig4.csv",), page="covering.md"),
    Block("ladder", [["explore", "pipeline/sweeps/nbuffer_covering.json", "--out", "ladder", "--jobs", "2"]], render_ladder,
          files=("ladder/results.csv",), page="covering.md"),
    Block("lazy", [["replay", WALK, "--set", "cull.mode=nb_hier", "--set", "nbuffer.update_policy=lazy", *sets, "--out", f"lazy{i}"]
                   for i, (_, sets) in enumerate(LAZY)], render_lazy, files=tuple(f"lazy{i}/run.json" for i in range(len(LAZY))),
          page="covering.md"),
    Block("memory", [["nbuffer", "memory", "--size", s, *k] for s in MEMORY_SIZES for k in MEMORY_KINDS], render_memory,
          page="covering.md"),
]


def sweep_rows(text):
    import csv
    import io
    return [r for r in csv.DictReader(io.StringIO(text)) if r["status"] == "ok" and r["role"] == "sweep"]


def render_design(outputs):
    rows = sweep_rows(outputs[-1])

    def label(r):
        return f"div={r['nbuffer.resolution_divisor']} {r['nbuffer.format']} {r['nbuffer.update_policy']}"

    def line(r, note=""):
        return (f"| {note or label(r)} | {n(float(r['cycles_per_frame']))} | {100 * float(r['efficiency_lost']):.2f} | "
                f"{n(float(r['total_depth_tests_per_frame']))} | {n(float(r['nbuffer_memory_bytes']) / 1024)} |")
    best = pareto_front(rows, "cycles_per_frame", "efficiency_lost")
    lines = [f"{len(rows)} points. The Pareto front of cycles per frame against culling efficiency lost:", "",
             "| point | cycles per frame | efficiency lost (points of %) | total depth tests per frame | N-buffer memory (KiB) |",
             "|---|---:|---:|---:|---:|"] + [line(r) for r in best]
    full = {r["nbuffer.update_policy"]: r for r in rows if r["nbuffer.resolution_divisor"] == "1" and r["nbuffer.format"] == "f32"}
    for policy in ("batched", "eager"):
        if full[policy] not in best:
            lines.append(line(full[policy], f"({label(full[policy])}{', the default' if policy == 'eager' else ''}, dominated)"))
    false_culls = sum(int(r["false_culls"]) for r in rows)
    upd = {p: float(full[p]["update_texels_per_frame"]) / 1e6 for p in full}
    lost = {d: min(float(r["efficiency_lost"]) for r in rows if r["nbuffer.resolution_divisor"] == d) for d in ("2", "4", "8")}
    lines += ["", f"At full resolution, eager updates (every occluder's changes at once) cost {upd['eager']:.1f} M level texels a "
              f"frame, batched (once per pass) {upd['batched']:.1f} M and lazy (when a query reads the levels) {upd['lazy']:.1f} M, "
              f"for the same culling. The least a resolution divisor loses: 2, {100 * lost['2']:.2f} points; 4, "
              f"{100 * lost['4']:.2f}; 8, {100 * lost['8']:.2f}. False culls over every point: {false_culls}."]
    return "\n".join(lines)


def render_hiz(outputs):
    rows = sweep_rows(outputs[-1])
    lines = ["| trace | mode | Hi-Z tile, format | culling efficiency | efficiency lost (points of %) | cycles per frame | false culls |",
             "|---|---|---|---:|---:|---:|---:|"]
    for r in rows:
        hiz = f"{r['hiz.tile_px']} px, {r['hiz.format']}" if r["cull.mode"] == "hiz_tile" else \
            (r["hiz.format"] if r["cull.mode"] == "hiz_pyramid" else "")
        lines.append(f"| {r['trace'].rsplit('/', 1)[-1]} | {r['cull.mode']} | {hiz} | {100 * float(r['culling_efficiency']):.1f}% | "
                     f"{100 * float(r['efficiency_lost']):.2f} | {n(float(r['cycles_per_frame']))} | {r['false_culls']} |")
    return "\n".join(lines)


def render_fidelity(outputs):
    rows = sweep_rows(outputs[-1])
    out = []
    for trace in dict.fromkeys(r["trace"] for r in rows):
        pts = [r for r in rows if r["trace"] == trace]
        worst = max(pts, key=lambda r: abs(float(r["cycle_error"])))
        quantum = [r for r in pts if r["gpu.quantum_cycles"] == "0"]
        others = max(abs(float(r["cycle_error"])) for r in quantum)
        same = len({r["culling_efficiency"] for r in pts}) == 1
        out.append(f"`{trace.rsplit('/', 1)[-1]}`: {'every point culls alike' if same else 'the points cull differently'}; "
                   f"the largest cycle error {100 * abs(float(worst['cycle_error'])):.3f}% "
                   f"(`gpu.quantum_cycles={worst['gpu.quantum_cycles']}`); the batch size and the FMA switches change cycles by "
                   f"at most {100 * others:.4f}%.")
    return "\n\n".join(out)


def upkeep_label(r):
    clear = "fast clear" if r["nbuffer.fast_clear"] == "true" else "clear writes"
    return f"{r['nbuffer.update_policy']}, {clear}, level 0 {r['nbuffer.level0']}"


def refused_rows(text):
    """The points of a sweep's results.csv that were refused (status failed)."""
    import csv
    import io
    return [r for r in csv.DictReader(io.StringIO(text)) if r["status"] == "failed"]


def grouped(rows, key, column):
    """Rows grouped by key(row), in key order: each group maps its rows' values of `column` to them."""
    by = {}
    for r in rows:
        by.setdefault(key(r), {})[r[column]] = r
    return [by[k] for k in sorted(by)]


def side_by_side(group, values, col, scale=1.0, fmt=None, missing="-"):
    """One cell: `col` of the group's row for each of `values`, " / " between them."""
    return " / ".join((fmt or n)(float(group[v][col]) * scale) if v in group else missing for v in values)


def render_upkeep(outputs):
    text = outputs[-1]
    rows = sweep_rows(text)
    refused = refused_rows(text)
    lines = ["| design (divisor 1 / 4) | upkeep texels a frame | total depth tests a frame | cycles a frame | efficiency lost (points of %) |",
             "|---|---:|---:|---:|---:|"]
    key = lambda r: (["eager", "batched", "lazy", "on_demand"].index(r["nbuffer.update_policy"]), r["nbuffer.fast_clear"], r["nbuffer.level0"])
    for d in grouped(rows, key, "nbuffer.resolution_divisor"):
        def both(col, scale=1.0, fmt=None):
            return side_by_side(d, ("1", "4"), col, scale, fmt, "refused")
        lines.append(f"| {upkeep_label(next(iter(d.values())))} | {both('update_texels_per_frame')} | "
                     f"{both('total_depth_tests_per_frame')} | {both('cycles_per_frame')} | "
                     f"{both('efficiency_lost', 100.0, lambda v: f'{v:.2f}')} |")
    full = {(r["nbuffer.update_policy"], r["nbuffer.fast_clear"], r["nbuffer.level0"]): r for r in rows if r["nbuffer.resolution_divisor"] == "1"}
    upd = lambda p: float(full[(p, "false", "copy")]["update_texels_per_frame"])
    best = min(rows, key=lambda r: float(r["cycles_per_frame"]))
    lines += ["", f"At full resolution with the clear writing every level and level 0 a copy, on-demand levels compute "
              f"{n(upd('on_demand'))} texels a frame against eager's {n(upd('eager'))} ({upd('eager') / upd('on_demand'):.1f}x), "
              f"batched's {n(upd('batched'))} and lazy's {n(upd('lazy'))}, for the same culling. The cheapest point: "
              f"{upkeep_label(best)}, divisor {best['nbuffer.resolution_divisor']}, {n(float(best['cycles_per_frame']))} cycles a "
              f"frame. {len(refused)} points (level 0 shared at divisor 4) were refused by name and recorded as failed. "
              f"False culls over every point: {sum(int(r['false_culls']) for r in rows)}."]
    return "\n".join(lines)


def tracking_label(r):
    tile = "per texel" if r["nbuffer.dirty_tile"] == "1" else f"per {r['nbuffer.dirty_tile']}x{r['nbuffer.dirty_tile']} tile"
    demand = "levels the last frame needed" if r["nbuffer.demand_levels"] == "true" else "every level"
    tracked = "" if r["nbuffer.update_policy"] == "eager" else f", {tile}"
    return f"{r['nbuffer.update_policy']}{tracked}, {demand}"


def render_tracking(outputs):
    rows = sweep_rows(outputs[-1])
    refused = refused_rows(outputs[-1])
    lines = ["| design (nb / nb_hier) | upkeep texels a frame | cycles a frame | efficiency lost (points of %) |",
             "|---|---:|---:|---:|"]
    policies = ["eager", "batched", "lazy"]
    key = lambda r: (policies.index(r["nbuffer.update_policy"]), int(r["nbuffer.dirty_tile"]), r["nbuffer.demand_levels"])
    for d in grouped(rows, key, "cull.mode"):
        def both(col, scale=1.0, fmt=None):
            return side_by_side(d, ("nb", "nb_hier"), col, scale, fmt)
        lines.append(f"| {tracking_label(next(iter(d.values())))} | {both('update_texels_per_frame')} | {both('cycles_per_frame')} | "
                     f"{both('efficiency_lost', 100.0, lambda v: f'{v:.2f}')} |")
    pick = lambda mode, policy, tile, demand: next(r for r in rows if r["cull.mode"] == mode and r["nbuffer.update_policy"] == policy
                                                  and r["nbuffer.dirty_tile"] == tile and r["nbuffer.demand_levels"] == demand)
    lazy1, lazy8 = pick("nb", "lazy", "1", "false"), pick("nb", "lazy", "8", "false")
    eager, eager_d = pick("nb", "eager", "1", "false"), pick("nb", "eager", "1", "true")
    hier, hier_d = pick("nb_hier", "eager", "1", "false"), pick("nb_hier", "eager", "1", "true")
    u = lambda r: float(r["update_texels_per_frame"])
    lost = lambda r: float(r["efficiency_lost"]) * 100.0
    lines += ["", f"Per 8x8 tile, lazy updates on `nb` recompute {n(u(lazy8))} texels a frame against {n(u(lazy1))} per texel "
              f"({u(lazy8) / u(lazy1):.3f}x), with 1/64 of the pending flags. Levels capped by the last frame's demand take eager "
              f"`nb` from {n(u(eager))} to {n(u(eager_d))} upkeep texels ({u(eager_d) / u(eager):.3f}x; efficiency lost "
              f"{lost(eager):.2f} and {lost(eager_d):.2f} points) and `nb_hier` from {n(u(hier))} to {n(u(hier_d))}. "
              f"{len(refused)} points (a tracking tile beside eager updates, which keep nothing pending) were refused by name "
              f"and recorded as failed. False culls over every point: {sum(int(r['false_culls']) for r in rows)}."]
    return "\n".join(lines)


def pays_label(r):
    if r["cull.mode"] == "hiz_tile":
        return f"tile Hi-Z {r['hiz.tile_px']}x{r['hiz.tile_px']}"
    shared = ", level 0 shared" if r["nbuffer.level0"] == "depth" else ""
    return (f"N-buffer div {r['nbuffer.resolution_divisor']}, {r['nbuffer.format']}, {int(r['nbuffer.cache_size_bytes']) // 1024} KiB "
            f"cache{shared}")


def render_pays(outputs):
    rows = sweep_rows(outputs[-1])
    front = pareto_front(rows, "cycles_per_frame", "efficiency_lost")
    lines = ["| design (N-buffers: on demand, fast clears) | cycles a frame | culling efficiency | efficiency lost (points of %) |",
             "|---|---:|---:|---:|"]
    for r in front:
        lines.append(f"| {pays_label(r)} | {n(float(r['cycles_per_frame']))} | {100 * float(r['culling_efficiency']):.2f}% | "
                     f"{100 * float(r['efficiency_lost']):.2f} |")
    lines.append("")
    nb = [r for r in rows if r["cull.mode"] == "nb_hier"]
    for h in sorted((r for r in rows if r["cull.mode"] == "hiz_tile"), key=lambda r: int(r["hiz.tile_px"])):
        lost, cyc = float(h["efficiency_lost"]), float(h["cycles_per_frame"])
        ok = [r for r in nb if float(r["efficiency_lost"]) <= lost]
        if not ok:
            lines.append(f"Against {pays_label(h)}: no N-buffer design loses as little culling.")
            continue
        b = min(ok, key=lambda r: float(r["cycles_per_frame"]))
        c = float(b["cycles_per_frame"])
        verdict = "beats it" if c < cyc else "does not beat it"
        lines.append(f"Against {pays_label(h)} ({n(cyc)} cycles, {100 * lost:.2f} points lost): the cheapest N-buffer design that "
                     f"loses no more culling is {pays_label(b)}, {n(c)} cycles ({c / cyc:.3f}x), {100 * float(b['efficiency_lost']):.2f} "
                     f"points lost: it {verdict} in this space.")
        lines.append("")
    return "\n".join(lines)


def render_techniques(outputs):
    rows = sweep_rows(outputs[-1])
    per, overall = pays.summarize(rows)
    lines = ["| technique | the best N-buffer design (cycles a frame, error) | the default design (eager, clear writes, div 1, f32) | "
             "the others (cycles a frame, error) |", "|---|---|---|---|"]
    cell = lambda c, e: f"{n(c)}, {100 * e:.2f}"
    for t in per:
        lines.append(f"| {t['technique']} | {t['best']}: {cell(t['best_cycles'], t['best_error'])} | "
                     f"{cell(t['default_cycles'], t['default_error'])} | "
                     f"{'; '.join(f'{o}: {cell(c, e)}' for o, c, e in t['others']) or '-'} |")
    return "\n".join(lines) + "\n\n" + overall


BLOCKS += [
    Block("techniques", [["explore", "pipeline/sweeps/nbuffer_techniques.json", "--out", "techniques", "--jobs", "2"]], render_techniques,
          files=("techniques/results.csv",), page="exploration.md"),
    Block("upkeep", [["explore", "pipeline/sweeps/nbuffer_upkeep.json", "--out", "upkeep", "--jobs", "2"]], render_upkeep,
          files=("upkeep/results.csv",), page="exploration.md"),
    Block("tracking", [["explore", "pipeline/sweeps/nbuffer_tracking.json", "--out", "tracking", "--jobs", "2"]], render_tracking,
          files=("tracking/results.csv",), page="exploration.md"),
    Block("pays", [["explore", "pipeline/sweeps/nbuffer_pays.json", "--out", "pays", "--jobs", "2"]], render_pays,
          files=("pays/results.csv",), page="exploration.md"),
    Block("design", [["explore", "pipeline/sweeps/nbuffer_design.json", "--out", "design", "--jobs", "2"]], render_design,
          files=("design/results.csv",), page="exploration.md"),
    Block("hiz", [["explore", "pipeline/sweeps/hiz_baselines.json", "--out", "hiz", "--jobs", "2"]], render_hiz,
          files=("hiz/results.csv",), page="exploration.md"),
    Block("fidelity", [["explore", "pipeline/sweeps/fidelity.json", "--out", "fidelity", "--jobs", "2"]], render_fidelity,
          files=("fidelity/results.csv",), page="exploration.md"),
]
