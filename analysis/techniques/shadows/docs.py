"""The shadow volumes' results in docs/shadows.md, generated (the protocol: analysis/doc_results.py)."""
import csv
import io

from doc_results import Block, pareto_front, thousands as n

PAGE = "shadows.md"
SCENES = ("boxes", "terrain", "city")
MODES = ("infinite", "culled", "clamped")
PAPER = {"boxes": "~20 %", "terrain": "2.5 %", "city": "2.5 % (20 M -> 512 K)"}
LOSSY = [("f32, divisor 1, every level (reference)", []),
         ("u16", ["--set", "litmap_min.format=u16", "--set", "litmap_max.format=u16"]),
         ("divisor 2", ["--set", "litmap_min.resolution_divisor=2", "--set", "litmap_max.resolution_divisor=2"]),
         ("level cap 4", ["--set", "litmap_min.level_cap=4", "--set", "litmap_max.level_cap=4"])]



def caster_count(v):
    return n(v, 0) if float(v).is_integer() else f"{v:,.2f}".rstrip("0")


def mib(b):
    return f"{b / 2**20:,.0f} MiB" if b >= 2**20 and b % 2**20 == 0 else f"{b / 1024:,.0f} KiB"


def conservative(r):
    return r["not_conservative"] == 0 and r["unsafe_culls"] == 0 and r["mask_diff"] == 0 and r["mask_diff_infinite"] == 0


def render_modes(outputs):
    rows = outputs[len(SCENES) * len(MODES)]
    lossy = outputs[len(SCENES) * len(MODES) + 1:]
    lines = ["| scene | mode | fill / frame | ratio to infinite | paper | casters culled by GL / frame (incl. outside) | "
             "build texels / frame | lookups / frame | cycles / frame | mask pixels differing (GL's, infinite) |",
             "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        paper = PAPER[r["scene"]] if r["shadow_mode"] == "clamped" else ""
        lines.append(f"| {r['scene']} | {r['shadow_mode']} | {n(r['fill_per_frame'])} | {100 * r['ratio_to_infinite']:.1f} % | "
                     f"{paper} | {caster_count(r['gl_culled_per_frame'] + r['outside_per_frame'])} of {n(r['casters_per_frame'])} | "
                     f"{n(r['build_texels_per_frame'])} | {n(r['lookups_per_frame'])} | {n(r['cycles_per_frame'])} | "
                     f"{r['mask_diff']}, {r['mask_diff_infinite']} |")
    exact = all(r["draws_exact"] == r["draws"] and r["stencil_pixels_matching"] == r["stencil_pixels"] for r in rows)
    mism = sum(r["zmin_mismatches"] + r["zmax_mismatches"] + r["decision_mismatches"] for r in rows)
    by = {(r["scene"], r["shadow_mode"]): r for r in rows}
    city_inf, city_cl = by[("city", "infinite")], by[("city", "clamped")]
    lines += ["", (f"{'Every draw of every trace replays exact and every stencil buffer equals GL' + chr(39) + 's' if exact else 'Some draws or stencil pixels differ from GL' + chr(39) + 's'} "
                   f"({', '.join(n(r['draws']) for r in rows)} draws); {mism} z_min/z_max and decision mismatches. "
                   f"Clamping cuts the city's cycles a frame {city_inf['cycles_per_frame'] / city_cl['cycles_per_frame']:.1f}x. "
                   "The cull rule recomputed on the litmaps alone (the model's check of GL's decisions) culls: " +
                   "; ".join(f"{s} {caster_count(by[(s, 'clamped')]['culled_per_frame'])} casters a frame against GL's "
                             f"{caster_count(by[(s, 'clamped')]['gl_culled_per_frame'])}" for s in SCENES) + ".")]
    lines += ["", "Lossy designs of both N-buffers on the city's clamped trace:", "",
              "| design (both units) | casters culled by the rule / frame | build texels / frame | lookups / frame | "
              "cycles / frame | memory | conservative |", "|---|---:|---:|---:|---:|---:|---|"]
    for (label, _), (r,) in zip(LOSSY, lossy):
        lines.append(f"| {label} | {caster_count(r['culled_per_frame'])} | {n(r['build_texels_per_frame'])} | "
                     f"{n(r['lookups_per_frame'])} | {n(r['cycles_per_frame'])} | {mib(r['nbuffer_memory_bytes'])} | "
                     f"{'yes' if conservative(r) else 'NO'} |")
    return "\n".join(lines)


def modes_commands():
    caps = [["capture", "shadows", "--scene", s, "--path", "fly", "--size", "640x480", "--frames", "4", "--shadow-mode", m,
             "-o", f"{s}_{m}.nbt"] for s in SCENES for m in MODES]
    return caps + [["shadows", *[f"{s}_{m}.nbt" for s in SCENES for m in MODES], "--json"]] + \
        [["shadows", "city_clamped.nbt", *sets, "--json"] for _, sets in LOSSY]


def render_street(outputs):
    (r,) = outputs[-1]
    return (f"At street level, the camera often inside volumes: fill {n(r['fill_per_frame'])} a frame against GL's infinite "
            f"volumes' {n(r['reference_fill_per_frame'])}, a ratio of {100 * r['ratio_to_infinite']:.1f} %, with "
            f"{r['mask_diff']} and {r['mask_diff_infinite']} mask pixels differing from GL's mask and from the infinite one.")


FRESH = [["--scene", "city", "--seed", "7", "--objects", "2500", "--path", "fly", "--size", "300x220", "--frames", "3", "--litmap", "256",
          "--light-fov", "75", "--shadow-mode", "infinite", "-o", "fresh_infinite.nbt"],
         ["--scene", "city", "--seed", "7", "--objects", "2500", "--path", "fly", "--size", "300x220", "--frames", "3", "--litmap", "256",
          "--light-fov", "75", "--shadow-mode", "clamped", "-o", "fresh_clamped.nbt"],
         ["--scene", "terrain", "--seed", "11", "--towers", "25", "--birds", "600", "--path", "fly", "--size", "200x150", "--frames", "3",
          "--litmap", "128", "--light-fov", "50", "--shadow-mode", "culled", "-o", "fresh_terrain.nbt"],
         ["--scene", "boxes", "--seed", "5", "--path", "fly", "--size", "160x120", "--frames", "5", "--litmap", "300", "--light-fov", "40",
          "--levels-every", "2", "--shadow-mode", "clamped", "-o", "fresh_boxes.nbt"]]


def render_table(rows):
    lines = ["| trace | scene | mode | litmap | ratio to infinite | draws exact | stencil equal | mask pixels differing | "
             "z, decision and unsafe-cull mismatches |", "|---|---|---|---:|---:|---:|---|---:|---:|"]
    for r in rows:
        mism = r["zmin_mismatches"] + r["zmax_mismatches"] + r["decision_mismatches"] + r["unsafe_culls"]
        lines.append(f"| {r['trace']} | {r['scene']} | {r['shadow_mode']} | {r['litmap_size']} | {100 * r['ratio_to_infinite']:.1f} % | "
                     f"{r['draws_exact']:,} of {r['draws']:,} | {'yes' if r['stencil_pixels_matching'] == r['stencil_pixels'] else 'NO'} | "
                     f"{r['mask_diff']}, {r['mask_diff_infinite']} | {mism} |")
    return "\n".join(lines)


def render_fresh(outputs):
    return render_table(outputs[-1])


def render_samples(outputs):
    (rows,) = outputs
    lines = [render_table(rows), ""]
    lines.append("; ".join(f"litmap {r['litmap_size']}: fill {n(r['fill_per_frame'])} a frame against "
                           f"{n(r['reference_fill_per_frame'])} infinite, GL culled {caster_count(r['gl_culled_per_frame'])} "
                           f"of {n(r['casters_per_frame'])} casters a frame (and {caster_count(r['outside_per_frame'])} "
                           f"outside the light), the rule {caster_count(r['culled_per_frame'])}" for r in rows) + ".")
    return "\n".join(lines)


def render_sweep(outputs):
    rows = [r for r in csv.DictReader(io.StringIO(outputs[-1])) if r["status"] == "ok"]

    def f(r, k):
        return float(r[k])

    def label(r):
        cap = int(r["litmap_min.level_cap"])
        return (f"litmaps {r['shadows.litmap_size']}, divisor {r['litmap_min.resolution_divisor']}, {r['litmap_min.format']}, "
                f"{'every level' if cap < 0 else f'cap {cap}'}")

    def is_ref(r):
        return r["litmap_min.resolution_divisor"] == "1" and r["litmap_min.format"] == "f32" and int(r["litmap_min.level_cap"]) < 0

    bad = sum(int(r["unsafe_culls"]) + int(r["mask_errors"]) + int(r["not_conservative"]) for r in rows)
    front = pareto_front(rows, "cycles_per_frame", "fill_per_frame")
    shown = front + [r for r in rows if is_ref(r) and r not in front]
    shown.sort(key=lambda r: f(r, "cycles_per_frame"))
    lines = [f"{len(rows)} points on the model's own litmaps and volumes (the fill follows the design). The Pareto front of "
             "cycles against fill per frame, and the full-resolution f32 design at each litmap size (*):", "",
             "| design (both units) | cycles / frame | fill / frame | casters culled by the rule / frame | culls lost (at that size) | "
             "build texels / frame | lookups / frame | memory | mask pixels unlike GL's captured mask |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in shown:
        lost = f(r, "culled_lost_fraction")
        lines.append(f"| {label(r)}{' (*)' if is_ref(r) else ''} | {n(f(r, 'cycles_per_frame'))} | {n(f(r, 'fill_per_frame'))} | "
                     f"{caster_count(f(r, 'culled_per_frame'))} | {'0' if lost == 0 else f'{100 * lost:.2f} %'} | "
                     f"{n(f(r, 'build_texels_per_frame'))} | {caster_count(f(r, 'lookups_per_frame'))} | "
                     f"{mib(f(r, 'nbuffer_memory_bytes'))} | {r['mask_diff']} |")
    lines += ["", f"Unsafe culls, non-conservative ranges and mask errors (pixels unlike the model's own infinite volumes at the "
              f"same planes), over every point: {bad}. The last column counts pixels where the volumes, cut at the design's own "
              "planes, rasterize unlike GL's clamped capture at 256 lexels (the cuts' rounding, not shadow lost)."]
    return "\n".join(lines)


BLOCKS = [
    Block("modes", modes_commands(), render_modes),
    Block("street", [["capture", "shadows", "--scene", "city", "--path", "walk", "--size", "640x480", "--frames", "8", "-o", "walk.nbt"],
                     ["shadows", "walk.nbt", "--json"]], render_street),
    Block("fresh", [["capture", "shadows", *a] for a in FRESH] +
          [["shadows", "fresh_infinite.nbt", "fresh_clamped.nbt", "fresh_terrain.nbt", "fresh_boxes.nbt", "--json"]], render_fresh),
    Block("samples", [["shadows", "traces/samples/shadows_city_fly_320_litmap256.nbt",
                       "traces/samples/shadows_city_fly_320_litmap128.nbt", "--json"]], render_samples),
    Block("sweep", [["explore", "pipeline/sweeps/shadows.json", "--out", "sweep", "--jobs", "2"]], render_sweep,
          files=("sweep/results.csv",)),
]


GROUND_SCENES = ("terrain", "city", "boxes")
PATHS = ("ground", "fly")
RULES = ("edge", "caster")
MARGINS = (("0.001,0.01", "margin_small"), ("0,0", "margin_none"))


def experiment_commands():
    caps = [["capture", "shadows", "--scene", s, "--path", p, "--size", "640x480", "--frames", "10", "--shadow-mode", "clamped",
             "--clamp-rule", r, "-o", f"{s}_{p}_{r}.nbt"] for s in GROUND_SCENES for p in PATHS for r in RULES]
    caps += [["capture", "shadows", "--scene", "terrain", "--path", "ground", "--size", "640x480", "--frames", "10",
              "--shadow-mode", "clamped", "--clamp-margin", m, "-o", f"terrain_{name}.nbt"] for m, name in MARGINS]
    traces = [f"{s}_{p}_{r}.nbt" for s in GROUND_SCENES for p in PATHS for r in RULES]
    return caps + [["shadows", *traces, "--json"], ["shadows", *[f"terrain_{name}.nbt" for _, name in MARGINS], "--json"]]


def render_experiment(outputs):
    rows, margins = outputs[-2], outputs[-1]
    lines = ["| scene | path | clamp rule | fill / frame | infinite volumes' fill / frame | ratio to infinite | paper | "
             "casters culled by GL / frame (incl. outside) | draws exact | mask pixels differing (GL's, infinite) |",
             "|---|---|---|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(f"| {r['scene']} | {r['path']} | {r['clamp_rule']} | {n(r['fill_per_frame'])} | {n(r['reference_fill_per_frame'])} | "
                     f"{100 * r['ratio_to_infinite']:.1f} % | {PAPER[r['scene']]} | "
                     f"{caster_count(r['gl_culled_per_frame'] + r['outside_per_frame'])} of {n(r['casters_per_frame'])} | "
                     f"{r['draws_exact']:,} of {r['draws']:,} | {r['mask_diff']}, {r['mask_diff_infinite']} |")
    lines += ["", "Where the fill goes with the paper's rule along the ground path: per caster class and the reason a culled "
              "or clamped capture keeps the caster (SHDC `kept`: `receivers`, a visible receiver in its slab; `seen_caster`, the "
              "observer sees the caster itself; `dropped`, culled or outside the light), per frame:", "",
              "| scene | class | kept | casters / frame | fill / frame | its infinite volumes' fill / frame | share of the clamped fill |",
              "|---|---|---|---:|---:|---:|---:|"]
    for r in rows:
        if r["path"] != "ground" or r["clamp_rule"] != "edge":
            continue
        total = sum(b["fill_per_frame"] for b in r["fill_breakdown"]) or 1.0
        for b in r["fill_breakdown"]:
            lines.append(f"| {r['scene']} | {b['class']} | {b['kept']} | {caster_count(round(b['casters_per_frame'], 2))} | "
                         f"{n(b['fill_per_frame'])} | {n(b['fill_infinite_per_frame'])} | {100 * b['fill_per_frame'] / total:.1f} % |")
    by = {r["trace"]: r for r in margins}
    lines += ["", "Smaller clamp margins on the terrain's ground path (rule `edge`): " + "; ".join(
        f"`--clamp-margin {m}`: {100 * by[f'terrain_{name}.nbt']['ratio_to_infinite']:.1f} %, "
        f"{by[f'terrain_{name}.nbt']['mask_diff_infinite']} mask pixels differing from the infinite mask" for m, name in MARGINS) + "."]
    return "\n".join(lines)


BLOCKS.append(Block("experiment", experiment_commands(), render_experiment))


MODEL_SCENES = ("boxes", "terrain", "city")


def model_volumes_commands():
    caps = [["capture", "shadows", "--scene", s, "--path", "fly", "--size", "640x480", "--frames", "4", "--shadow-mode", m,
             "-o", f"{s}_{m}.nbt"] for s in MODEL_SCENES for m in ("infinite", "clamped")]
    runs = [["replay", f"{s}_clamped.nbt", "--out", f"{s}_gl"] for s in MODEL_SCENES]
    runs += [["replay", f"{s}_infinite.nbt", "--out", f"{s}_model", "--set", "shadows.volumes=clamped"] for s in MODEL_SCENES]
    sample = "traces/samples/shadows_city_fly_320_litmap256.nbt"
    lossy = [["shadows", sample, "--set", f"shadows.volumes={v}", *sets, "--json"] for _, sets in LOSSY for v in ("clamped", "infinite")]
    return caps + lossy + runs


def render_model_volumes(outputs):
    import json
    files = [json.loads(t) for t in outputs[-2 * len(MODEL_SCENES):]]
    gl, model = files[:len(MODEL_SCENES)], files[len(MODEL_SCENES):]
    lossy = [o for o in outputs if isinstance(o, list)]
    lines = ["| scene | GL: clamped capture, fill / frame | model: infinite capture as clamped, fill / frame | volumes (GL, model) | "
             "stencil buffer equal to GL's clamped one, frames | mask pixels differing (GL's, infinite) |", "|---|---:|---:|---:|---:|---:|"]
    for s, g, m in zip(MODEL_SCENES, gl, model):
        gs, ms = g["summary"]["shadows"], m["summary"]["shadows"]
        # The model's stencil on the clamped trace is GL's pixel for pixel; the infinite trace's as clamped has its CRC.
        same = sum(a["stencil_checksum"] == b["stencil_checksum"] and a["stencil_pixels_matching"] == a["stencil_pixels"]
                   for a, b in zip(g["frames"], m["frames"]))
        lines.append(f"| {s} | {n(gs['gl_fill_per_frame'])} | {n(ms['fill_per_frame'])} | {n(gs['volume_draws'])}, {n(ms['model_volumes'])} | "
                     f"{same} of {len(g['frames'])} | {ms['mask_diff']}, {ms['mask_diff_infinite']} |")
    same_counts = all(lossy[k][0]["mask_diff_infinite"] == lossy[k + 1][0]["mask_diff_infinite"] for k in range(0, len(lossy), 2))
    own_zero = all(o[0]["own_mask_diff"] == 0 for o in lossy)
    reading = ("the model's infinite volumes cut at the same planes differ from GL's infinite mask in exactly as many pixels, "
               if same_counts else "the model's infinite volumes cut at the same planes do NOT differ from it in as many pixels, ") + \
              ("and the mask equals the model's own reference (its infinite volumes at its planes, drawn off the clock: "
               "`own_mask_diff`) on every design, so these are the cuts' rounding, not shadow lost" if own_zero else
               "and the mask differs from the model's own reference on some design: shadow lost")
    lines += ["", "The model's own volumes under the lossy designs of both N-buffers (the city sample, litmaps of 256): their looser "
              "slabs move the planes, so the volumes are cut elsewhere than GL's infinite reference, and a few boundary pixels "
              f"rasterize otherwise; {reading}:",
              "", "| design (both units) | clamped fill / frame | ratio to GL's infinite | mask pixels unlike GL's infinite: clamped, "
              "the model's infinite at the same planes | mask pixels unlike the model's own reference |", "|---|---:|---:|---:|---:|"]
    for (label, _), k in zip(LOSSY, range(0, len(lossy), 2)):
        (c,), (i,) = lossy[k], lossy[k + 1]
        lines.append(f"| {label} | {n(c['fill_per_frame'])} | {100 * c['ratio_to_infinite']:.1f} % | {c['mask_diff_infinite']}, "
                     f"{i['mask_diff_infinite']} | {c['own_mask_diff']} |")
    return "\n".join(lines)


BLOCKS.append(Block("model_volumes", model_volumes_commands(), render_model_volumes,
                    files=tuple(f"{s}_{k}/run.json" for k in ("gl", "model") for s in MODEL_SCENES)))


# The model's own litmaps: fresh captures with arguments no test uses (viewport, seeds, litmap sides
# that are not powers of two); an infinite capture replayed with the model's litmaps at its own
# size (every texel against GL's) and, as clamped, at a smaller and a larger side against GL's
# clamped captures at those sides.
LITMAP_SCENES = {"boxes": ["--scene", "boxes", "--seed", "9"],
                 "terrain": ["--scene", "terrain", "--seed", "3", "--towers", "20", "--birds", "500"],
                 "city": ["--scene", "city", "--seed", "4", "--objects", "1800"]}
LITMAP_SIDES = (200, 96, 384)  # captured, then the two others
# The other designs beside the sides: (label, capture arguments, replay settings).
LITMAP_DESIGNS = [(str(side), ["--litmap", str(side)], ["--set", f"shadows.litmap_size={side}"]) for side in LITMAP_SIDES[1:]] + \
    [(f"{LITMAP_SIDES[0]}, corners covering", ["--litmap", str(LITMAP_SIDES[0]), "--covering", "corners"],
      ["--set", "litmap_min.covering=corners", "--set", "litmap_max.covering=corners"])]


def model_litmaps_commands():
    cmds = []
    for s, args in LITMAP_SCENES.items():
        common = ["capture", "shadows", *args, "--path", "fly", "--size", "400x300", "--frames", "3"]
        cmds.append([*common, "--litmap", str(LITMAP_SIDES[0]), "--shadow-mode", "infinite", "-o", f"lm_{s}_inf.nbt"])
        for k, (_, capture, _) in enumerate(LITMAP_DESIGNS):
            cmds.append([*common, *capture, "--shadow-mode", "clamped", "-o", f"lm_{s}_c{k}.nbt"])
    for s in LITMAP_SCENES:
        cmds.append(["replay", f"lm_{s}_inf.nbt", "--out", f"lm_{s}_same", "--set", "shadows.litmaps=model"])
        for k, (_, _, sets) in enumerate(LITMAP_DESIGNS):
            cmds.append(["replay", f"lm_{s}_c{k}.nbt", "--out", f"lm_{s}_gl{k}"])
            cmds.append(["replay", f"lm_{s}_inf.nbt", "--out", f"lm_{s}_m{k}", "--set", "shadows.litmaps=model",
                         "--set", "shadows.volumes=clamped", *sets])
    return cmds


def model_litmaps_files():
    files = []
    for s in LITMAP_SCENES:
        files.append(f"lm_{s}_same/run.json")
        for k in range(len(LITMAP_DESIGNS)):
            files += [f"lm_{s}_gl{k}/run.json", f"lm_{s}_m{k}/run.json"]
    return tuple(files)


def render_model_litmaps(outputs):
    import json
    files = [json.loads(t) for t in outputs[-len(model_litmaps_files()):]]
    lines = [f"| scene | litmaps of {LITMAP_SIDES[0]} (captured): texels unlike GL's, draws with other fragment counts | fragments "
             "reprojected / frame (discarded) | litmap side (design) | GL: clamped capture, fill / frame | model: infinite capture as clamped, fill / "
             "frame | stencil buffer equal to GL's, frames | mask pixels (GL, model) |",
             "|---|---:|---:|---:|---:|---:|---:|---:|"]
    k = 0
    for s in LITMAP_SCENES:
        same = files[k]["summary"]["shadows"]
        k += 1
        frames = max(1, same["frames"])
        for j, (side, _, _) in enumerate(LITMAP_DESIGNS):
            g, m = files[k], files[k + 1]
            k += 2
            gs, ms = g["summary"]["shadows"], m["summary"]["shadows"]
            equal = sum(a["stencil_checksum"] == b["stencil_checksum"] for a, b in zip(g["frames"], m["frames"]))
            head = (f"| {s} | {same['litmap_texel_diff']}, {same['litmap_fragment_diff']} | "
                    f"{n(same['litmap_reprojections'] / frames)} ({n(same['litmap_discarded'] / frames)}) |") if j == 0 else "| | | |"
            lines.append(f"{head} {side} | {n(gs['gl_fill_per_frame'])} | {n(ms['fill_per_frame'])} | {equal} of {len(g['frames'])} | "
                         f"{n(gs['gl_mask_pixels'])}, {n(ms['mask_pixels'])} |")
    return "\n".join(lines)


BLOCKS.append(Block("model_litmaps", model_litmaps_commands(), render_model_litmaps, files=model_litmaps_files()))
