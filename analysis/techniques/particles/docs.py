"""The particles' results in docs/particles.md, generated (the protocol: analysis/doc_results.py)."""
from doc_results import Block, pareto_front, thousands as n

PAGE = "particles.md"
MODES = ("none", "center", "nb", "hiz")


def capture(mode, out, extra=()):
    return ["capture", "particles", "--scene", "city", "--path", "walk", "--size", "512x512", "--frames", "10",
            "--particles", "10000", "--sprite", "16", "--mode", mode, *extra, "-o", out]



def render_modes(outputs):
    table, batched, lazy = outputs[-3:]
    rows = {r["mode"]: r for r in table}
    (b,), (z,) = batched, lazy
    lines = ["| mode | paper (256 N / N) | culled / frame | query | raster | N-buffer / Hi-Z build | total depth tests / frame "
             "| cycles / frame | popping | false culls |", "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]

    def line(label, r):
        paper = r["paper_depth_tests_per_frame"]
        return (f"| {label} | {n(paper) if paper is not None else '-'} | {n(r['culled_per_frame'])} | "
                f"{n(r['query_depth_tests_per_frame'])} | {n(r['raster_depth_tests_per_frame'])} | "
                f"{n(r['build_texels_per_frame'])} | {n(r['total_depth_tests_per_frame'])} | {n(r['cycles_per_frame'])} | "
                f"{r['popping']:,} | {r['false_culls']:,} |")
    for m in MODES:
        lines.append(line("nb, eager updates" if m == "nb" else m, rows[m]))
        if m == "nb":
            lines += [line("nb, batched updates", b), line("nb, lazy updates", z)]
    nb, hiz, center, none = rows["nb"], rows["hiz"], rows["center"], rows["none"]
    mismatches = sum(r["decision_mismatches"] for r in table)
    reading = (
        f"The N-buffer's queries read {n(nb['query_depth_tests_per_frame'])} texels a frame for "
        f"{n(nb['particles_per_frame'])} sprites, {none['raster_depth_tests_per_frame'] / nb['query_depth_tests_per_frame']:.0f} "
        f"times fewer than rasterizing them all ({none['raster_depth_tests_per_frame'] / 1e6:.2f} M; the paper's 256 N assumes "
        f"every sprite covers 16x16 pixels, while many here are off-screen or clipped), and it pops on "
        f"{nb['popping']:,} sprite-frames; the centre test pops on {center['popping']:,}. Keeping the N-buffer current as "
        f"the scene is drawn costs {n(nb['build_texels_per_frame'])} texels a frame with eager updates, "
        f"{n(b['build_texels_per_frame'])} batched and {n(z['build_texels_per_frame'])} lazy: only lazy updates bring the "
        f"total ({n(z['total_depth_tests_per_frame'])}) below drawing every sprite ({n(none['total_depth_tests_per_frame'])}). "
        f"Hi-Z culls {n(hiz['culled_per_frame'])} sprites a frame against the N-buffer's {n(nb['culled_per_frame'])}, with a "
        f"build of {n(hiz['build_texels_per_frame'])} texels. The model's decisions differ from GL's on {mismatches} sprites.")
    return "\n".join(lines) + "\n\n" + reading


FRESH = ("nb", "hiz", "center")


def fresh_capture(mode):
    return ["capture", "particles", "--scene", "city", "--seed", "7", "--objects", "2500", "--path", "fly", "--size", "300x220",
            "--frames", "6", "--particles", "14000", "--sprite", "atten", "--level-cap", "4", "--reversed-z", "--mode", mode,
            "-o", f"fresh_{mode}.nbt"]


def render_fresh(outputs):
    compares = outputs[len(FRESH):2 * len(FRESH)]
    table = {r["mode"]: r for r in outputs[-1]}
    lines = ["The flyover, reversed Z, attenuated sprites and a level cap of 4, one capture per mode:", "",
             "| mode | draws exact | passed samples | culled / frame | popping | false culls | decisions unlike GL's |",
             "|---|---:|---|---:|---:|---:|---:|"]
    for m, c in zip(FRESH, compares):
        r = table[m]
        lines.append(f"| {m} | {c['draws_exact']:,} of {c['draws']:,} | "
                     f"{'equal to GL' + chr(39) + 's' if c['passed_model'] == c['passed_gl'] else 'unlike GL' + chr(39) + 's'} | "
                     f"{n(r['culled_per_frame'])} of {n(r['particles_per_frame'])} | {r['popping']:,} | {r['false_culls']:,} | "
                     f"{r['decision_mismatches']:,} |")
    return "\n".join(lines)


def every_mode(mode):
    return ["particles", "walk_none.nbt", "--set", f"particles.mode={mode}", "--json"]


def render_every_mode(outputs):
    none_capture = outputs[1:5]
    sample = {r["mode"]: r for r in outputs[5]}
    rows = ["| mode | replayed from | culled / frame | query | raster | build | popping |", "|---|---|---:|---:|---:|---:|---:|"]
    for m, (r,) in zip(MODES, none_capture):
        rows.append(f"| {m} | the `none` capture | {n(r['culled_per_frame'])} | {n(r['query_depth_tests_per_frame'])} | "
                    f"{n(r['raster_depth_tests_per_frame'])} | {n(r['build_texels_per_frame'])} | {r['popping']:,} |")
    r = sample["nb"]
    rows.append(f"| nb | the `nb` sample, as captured | {n(r['culled_per_frame'])} | {n(r['query_depth_tests_per_frame'])} | "
                f"{n(r['raster_depth_tests_per_frame'])} | {n(r['build_texels_per_frame'])} | {r['popping']:,} |")
    return "\n".join(rows)


BLOCKS = [
    Block("modes", [capture(m, f"t_{m}.nbt") for m in MODES] + [
        ["particles", *[f"t_{m}.nbt" for m in MODES], "--json"],
        ["particles", "t_nb.nbt", "--set", "nbuffer.update_policy=batched", "--json"],
        ["particles", "t_nb.nbt", "--set", "nbuffer.update_policy=lazy", "--json"]], render_modes),
    Block("fresh", [fresh_capture(m) for m in FRESH] + [["compare", f"fresh_{m}.nbt", "--json"] for m in FRESH] +
          [["particles", *[f"fresh_{m}.nbt" for m in FRESH], "--json"]], render_fresh),
    Block("every-mode", [["capture", "particles", "--scene", "city", "--size", "256x256", "--frames", "16", "--path", "walk",
                          "--seed", "1", "--particles", "10000", "--sprite", "16", "--mode", "none", "-o", "walk_none.nbt"]] +
          [every_mode(m) for m in MODES] + [["particles", "traces/samples/particles_walk_256.nbt", "--json"]], render_every_mode),
]


def render_sweep(outputs):
    import csv
    import io
    rows = [r for r in csv.DictReader(io.StringIO(outputs[-1])) if r["status"] == "ok"]
    f = lambda r, k: float(r[k])  # noqa: E731
    front = pareto_front(rows, "cycles_per_frame", "culled_below_exact_fraction")

    def label(r):
        cap = int(r["nbuffer.level_cap"])
        return (f"{'capture' + chr(39) + 's levels' if cap < 0 else f'cap {cap}'}, divisor {r['nbuffer.resolution_divisor']}, "
                f"{r['nbuffer.format']}, {r['nbuffer.update_policy']}")
    lines = [f"{len(rows)} points. The Pareto front of cycles per frame against hidden sprites kept (the sprites the exact "
             "sprite test culls that the design keeps):", "",
             "| point | cycles / frame | hidden sprites kept | total depth tests / frame | N-buffer memory |",
             "|---|---:|---:|---:|---:|"]
    lines += [f"| {label(r)} | {n(f(r, 'cycles_per_frame'))} | {100 * f(r, 'culled_below_exact_fraction'):.2f} % | "
              f"{n(f(r, 'total_depth_tests_per_frame'))} | {f(r, 'nbuffer_memory_bytes') / 1024:,.0f} KiB |" for r in front]

    def pick(cap, div, fmt, policy):
        return next(r for r in rows if int(r["nbuffer.level_cap"]) == cap and r["nbuffer.resolution_divisor"] == str(div)
                    and r["nbuffer.format"] == fmt and r["nbuffer.update_policy"] == policy)
    eager, lazy = pick(-1, 1, "f32", "eager"), pick(-1, 1, "f32", "lazy")
    lazy_wins = all(f(pick(int(r["nbuffer.level_cap"]), r["nbuffer.resolution_divisor"], r["nbuffer.format"], "lazy"),
                      "cycles_per_frame") <= f(r, "cycles_per_frame") for r in rows if r["nbuffer.update_policy"] == "eager")
    caps = sorted({int(r["nbuffer.level_cap"]) for r in rows if int(r["nbuffer.level_cap"]) >= 0})
    low = pick(caps[0], 1, "f32", "lazy") if caps else None
    bad = sum(int(r["popping"]) + int(r["false_culls"]) for r in rows)
    lines += ["", (f"{'No point pops or culls falsely' if bad == 0 else f'{bad} popping or false culls over the points'}. "
                   f"Lazy updates {'beat eager ones at every point' if lazy_wins else 'do not beat eager ones everywhere'} "
                   f"({n(f(eager, 'build_texels_per_frame'))} build texels a frame eager at full resolution, "
                   f"{n(f(lazy, 'build_texels_per_frame'))} lazy)" +
                   (f"; cap {caps[0]} culls {n(f(low, 'culled_per_frame'))} sprites a frame "
                    f"({n(f(low, 'total_depth_tests_per_frame'))} depth tests a frame)." if low else "."))]
    return "\n".join(lines)


BLOCKS.append(Block("sweep", [["explore", "pipeline/sweeps/particles.json", "--out", "sweep", "--jobs", "2"]], render_sweep,
                    files=("sweep/results.csv",)))
