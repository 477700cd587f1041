"""The relief textures' results in docs/relief.md, generated (the protocol: analysis/doc_results.py)."""
from collections import defaultdict

from doc_results import Block, thousands as n

PAGE = "relief.md"
MODELS = "/usr/share/assimp/models"
METHODS = ("binary", "exact", "robust_clamp", "robust", "nbuffer")
FRESH = [
    (["--field-mesh", f"{MODELS}/Collada/duck.dae", "--field-size", "120"], "duck.dae, 120 texels"),
    (["--field-mesh", f"{MODELS}/BLEND/HUMAN.blend", "--field-size", "150"], "HUMAN.blend, 150 texels"),
    (["--field", "fbm", "--field-size", "200", "--seed", "11"], "fbm, 200 texels (not a power of two)"),
    (["--field", "walls", "--field-param", "7", "--field-size", "100", "--seed", "2"], "walls every 7 texels, 100 texels"),
    (["--field-file", "checker.exr"], "a 9x9 checker image, 72 texels"),
    (["--field-mesh", f"{MODELS}/Collada/duck.dae", "--field-size", "120", "--frustum", "1", "--angles", "15,65,120"],
     "duck.dae in a reverse-perspective frustum, the last view from below"),
]
FIELDS = ("fbm", "saddle", "spikes", "step", "walls")
SIZES = (32, 64, 128, 256)



def fresh_capture(i, args):
    angles = [] if "--angles" in args else ["--angles", "15,65,86"]
    return ["capture", "relief", "--size", "160x160", "--frames", "3",
            *angles, *args, "-o", f"t{i}.nbt"]


def per_trace(rows):
    """{trace: {method: totals}} from `nbsim relief --json`'s rows."""
    out = defaultdict(lambda: defaultdict(lambda: defaultdict(int)))
    for r in rows:
        t = out[r["trace"]][r["method"]]
        for k in ("fragments", "gl_fragments", "lookups", "steps", "errors", "cycles", "pixel_mismatches", "walk_mismatches"):
            t[k] += r[k]
    return out


def render_fresh(outputs):
    table = per_trace(outputs[-1]["rows"])
    lines = ["| heightfield | fragments a method | lookups/fragment: exact, nbuffer, robust | "
             "hit errors: " + ", ".join(METHODS) + " |", "|---|---:|---|---|"]
    differ = 0
    for i, (_, label) in enumerate(FRESH):
        m = table[f"t{i}.nbt"]
        differ += sum(m[k]["pixel_mismatches"] + m[k]["walk_mismatches"] + (m[k]["fragments"] != m[k]["gl_fragments"])
                      for k in METHODS)
        lpf = ", ".join(f"{m[k]['lookups'] / m[k]['fragments']:.1f}" for k in ("exact", "nbuffer", "robust"))
        errors = ", ".join(f"{m[k]['errors']:,}" for k in METHODS)
        lines.append(f"| {label} | {m['exact']['fragments']:,} | {lpf} | {errors} |")
    verdict = ("every method's fragments and hits equal GL's, 0 walks and 0 pixels differing" if differ == 0
               else f"{differ} methods with fragments, walks or pixels unlike GL's")
    return "\n".join(lines) + f"\n\nIn every capture, {verdict}."


def reference_captures(extra=(), prefix=""):
    return [["capture", "relief", "--size", "128x128", "--frames", "4",
             "--seed", "5", "--field", f, "--field-size", str(s), *extra, "-o", f"{prefix}{f}_{s}.nbt"]
            for f in FIELDS for s in SIZES]


def all_traces(prefix=""):
    return [f"{prefix}{f}_{s}.nbt" for f in FIELDS for s in SIZES]


def render_reference(outputs):
    d = outputs[len(FIELDS) * len(SIZES)]
    fragments = sum(r["fragments"] for r in d["rows"] if r["method"] == "exact")
    lines = [f"{fragments:,} fragments a method in all.", "",
             "| method | cycles per box draw | lookups/fragment | steps/fragment | hit errors | hit error | Pareto |",
             "|---|---:|---:|---:|---:|---:|---|"]
    for r in d["ranking"]:
        lines.append(f"| {r['method']} | {n(r['cycles_per_frame'])} | {r['lookups_per_fragment']:.1f} | "
                     f"{r['steps_per_fragment']:.2f} | {r['errors']:,} | {100 * r['error_rate']:.3f}% | "
                     f"{'yes' if r['pareto'] else ''} |")
    lines += ["", "The N-buffer walk against the exact walk, lookups per fragment (same runs):", "",
              "| heightfield | " + " | ".join(str(s) for s in SIZES) + " | extra errors |", "|---|" + "---|" * (len(SIZES) + 1)]
    by_field = defaultdict(dict)
    for r in d["nbuffer_vs_exact"]:
        by_field[r["field"].split(":")[0]][r["field_size"]] = r
    fewer, more = [], []
    for f in FIELDS:
        cells = []
        for s in SIZES:
            r = by_field[f][s]
            cells.append(f"{r['exact_lookups_per_fragment']:.1f} → {r['nbuffer_lookups_per_fragment']:.1f} ({r['lookup_ratio']:.2f})")
        extra = sum(max(0, by_field[f][s]["extra_errors"]) for s in SIZES)
        exact_errors = sum(by_field[f][s]["exact_errors"] for s in SIZES)
        lines.append(f"| {f} | " + " | ".join(cells) + f" | {extra} (exact: {exact_errors}) |")
        (fewer if all(by_field[f][s]["lookup_ratio"] < 1 for s in SIZES) else more).append(f)
    ratios = [r["lookup_ratio"] for r in d["nbuffer_vs_exact"] if r["field"].split(":")[0] in fewer]
    lines += ["", f"Fewer lookups than the exact walk at every size on {', '.join(fewer)} "
              f"({min(ratios):.2f} to {max(ratios):.2f} of its lookups)" +
              (f"; more on {', '.join(more)}." if more else ".")]
    lines += ["", "Beside the paper's Table 1 (terrain, frames per second on a GeForce 6800 GT; ours: the fbm rows, cycles "
              "per box draw, lookups per fragment):", "", "| method | " + " | ".join(str(s) for s in SIZES) + " |",
              "|---|" + "---|" * len(SIZES)]
    paper = defaultdict(dict)
    for r in d["paper"]:
        paper[r["method"]][r["field_size"]] = r
    for m in sorted(paper):
        lines.append(f"| {m} | " + " | ".join(f"{paper[m][s]['paper_hz']:.0f} Hz; {n(paper[m][s]['cycles_per_frame'])} cycles, "
                                             f"{paper[m][s]['lookups_per_fragment']:.1f}" for s in SIZES) + " |")
    lines += ["", render_covering(d, outputs[-1])]
    return "\n".join(lines)


def render_covering(paper_run, corners_run):
    (paper,) = [r for r in paper_run["ranking"] if r["method"] == "nbuffer"]
    (nb,) = [r for r in corners_run["ranking"] if r["method"] == "nbuffer"]
    differ = sum(r["walk_mismatches"] for r in corners_run["rows"])

    def change(a, b):
        return f"{100 * (a / b - 1):+.0f}%"
    return (f"With nbsim's earlier corner covering (`--covering corners --align bottom`, the same captures otherwise) "
            f"the N-buffer walk reads {nb['lookups_per_fragment']:.1f} texels and takes "
            f"{nb['steps_per_fragment']:.2f} steps a fragment for {n(nb['cycles_per_frame'])} cycles a box draw, with "
            f"{nb['errors']} hit errors and {differ} walks differing from GL's. The paper's covering, against it: "
            f"{change(paper['steps_per_fragment'], nb['steps_per_fragment'])} steps, "
            f"{change(paper['lookups_per_fragment'], nb['lookups_per_fragment'])} texels read, "
            f"{change(paper['cycles_per_frame'], nb['cycles_per_frame'])} cycles.")


def render_city(outputs):
    compare = outputs[1]
    r = compare["relief"]
    m = r["methods"]
    walks = sum(m[k]["walk_mismatches"] + m[k]["pixel_mismatches"] for k in METHODS)
    same = all(m[k]["fragments"] == m[k]["gl_fragments"] for k in METHODS)
    errors = ", ".join(f"{k} {m[k]['errors']:,}" for k in METHODS)
    return (f"{r['scene_draws']:,} scene draws; per method {m['exact']['rasterized']:,} box fragments rasterized, "
            f"{m['exact']['fragments']:,} passing the early depth test in the model "
            f"({'as in GL' if same else 'unlike GL'}); {walks} walks or pixels differing from GL's; hit errors {errors}; "
            f"{'within' if compare['within_thresholds'] else 'OUTSIDE'} `nbsim compare`'s thresholds.")


# The relief paper's section 4.4 in the city: the same walk with each of the box's depth outputs.
ZBUFFER_MODES = ("none", "box", "exact")


def zbuffer_commands():
    caps = [["capture", "relief", "--scene", "city", "--objects", "2000", "--path", "walk", "--size", "320x240", "--frames", "8",
             "--seed", "4", "--placement", "city", "--field", "walls", "--field-size", "64", "--box-depth", mode, "-o", f"z_{mode}.nbt"]
            for mode in ZBUFFER_MODES]
    return caps + [["compare", f"z_{mode}.nbt", "--json"] for mode in ZBUFFER_MODES]


def render_zbuffer(outputs):
    lines = ["| box depth | box fragments | walks run | walks saved by the early test | depth written | scene fragments after the box | "
             "hidden by the box | robust cycles / frame | nbuffer cycles / frame | unlike GL (walks, pixels, depth, scene draws) |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for mode, out in zip(ZBUFFER_MODES, outputs[-len(ZBUFFER_MODES):]):
        r = out["relief"]
        m = r["methods"]
        nb = m["nbuffer"]
        unlike = sum(x["walk_mismatches"] + x["pixel_mismatches"] + x["depth_mismatches"] for x in m.values()) + r["scene_mismatches"]
        saved = nb["rasterized"] - nb["fragments"]
        lines.append(f"| {mode} | {nb['rasterized']:,} | {nb['fragments']:,} | {saved:,} ({100 * saved / nb['rasterized']:.1f} %) | "
                     f"{nb['depth_written']:,} | {nb['scene_after_samples']:,} | {nb['scene_hidden']:,} | "
                     f"{n(m['robust']['cycles_per_frame'])} | {n(nb['cycles_per_frame'])} | {unlike} |")
    return "\n".join(lines)


BLOCKS = [
    Block("fresh", [["oiiotool", "--pattern", "checker:width=9:height=9:color1=0.15:color2=0.85", "72x72", "1", "-d", "float",
                     "-o", "checker.exr"]] + [fresh_capture(i, a) for i, (a, _) in enumerate(FRESH)] +
          [["relief", *[f"t{i}.nbt" for i in range(len(FRESH))], "--json"]], render_fresh),
    Block("reference", reference_captures() + [["relief", *all_traces(), "--json"]] +
          reference_captures(("--covering", "corners", "--align", "bottom"), "corners_") +
          [["relief", *all_traces("corners_"), "--json"]], render_reference),
    Block("city", [["capture", "relief", "--scene", "city", "--objects", "2000", "--path", "walk", "--size", "320x240", "--frames",
                    "8", "--seed", "4", "--placement", "city", "--field", "walls", "--field-size", "64", "-o", "c.nbt"],
                   ["compare", "c.nbt", "--json"]], render_city),
    Block("zbuffer", zbuffer_commands(), render_zbuffer),
]


# The paper's Figure 12: the allowed error epsilon against the safety radius (mean, share at 0), the
# robust searches' cost and their hit error, on a terrain and on a heightfield baked from a mesh, with
# the strict radius and the paper's (the maximum over directions, as its text says, and the
# minimum, which bounds every ray).
FIG12_FIELDS = {"terrain": ["--field", "fbm", "--field-size", "64", "--seed", "21"],
                "knot": ["--field-mesh", "shape:knot", "--field-size", "64"]}
FIG12_EPSILONS = ("0", "0.005", "0.01", "0.02", "0.05", "0.1")
FIG12_RADII = [("strict", ["--radius", "strict"])] + [(f"paper {c}, {e}", ["--radius", "paper", "--radius-combine", c, "--radius-epsilon", e])
                                  for c in ("min", "max") for e in FIG12_EPSILONS]


def fig12_commands():
    caps, runs = [], []
    for f, args in FIG12_FIELDS.items():
        for k, (_, radius) in enumerate(FIG12_RADII):
            caps.append(["capture", "relief", "--size", "256x256", "--frames", "4",
                         *args, "--methods", "exact,robust,robust_clamp", *radius, "-o", f"f12_{f}_{k}.nbt"])
            runs.append(["replay", f"f12_{f}_{k}.nbt", "--out", f"f12_{f}_{k}"])
    return caps + runs


def fig12_files():
    return tuple(f"f12_{f}_{k}/run.json" for f in FIG12_FIELDS for k in range(len(FIG12_RADII)))


def render_fig12(outputs):
    import json
    files = [json.loads(t) for t in outputs[-len(fig12_files()):]]
    lines = ["| heightfield | radius | mean radius (texels) | radius 0 | robust: cycles / frame | lookups / fragment | hit errors | "
             "robust_clamp: cycles / frame | hit errors | walks unlike GL's |", "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    k = 0
    for f in FIG12_FIELDS:
        for label, _ in FIG12_RADII:
            s = files[k]["summary"]["relief"]
            k += 1
            r, c = s["methods"]["robust"], s["methods"]["robust_clamp"]
            mism = sum(m["walk_mismatches"] + m["pixel_mismatches"] for m in s["methods"].values())
            lines.append(f"| {f} | {label} | {s['radius_mean']:.2f} | {100 * s['radius_zero_fraction']:.1f} % | {n(r['cycles_per_frame'])} | "
                         f"{r['lookups_per_fragment']:.1f} | {r['errors']:,} ({100 * r['error_rate']:.2f} %) | {n(c['cycles_per_frame'])} | "
                         f"{c['errors']:,} ({100 * c['error_rate']:.2f} %) | {mism} |")
    return "\n".join(lines)


BLOCKS.append(Block("figure12", fig12_commands(), render_fig12, files=fig12_files()))


# The paper's Table 1 as it set it up: the box seen at 45 degrees, covering about 800 x 600 pixels
# (1600 x 1200 viewport: 524,383 fragments a draw), terrains of 32² to 256² with the strict radius
# and the paper's (its maximum over directions, epsilon 0), and two stand-ins for its other
# heightfields at 128²: walls (a grid) and a torus knot baked from above (an object).
T1_SIZES = (32, 64, 128, 256)
T1_COMMON = ["capture", "relief", "--size", "1600x1200", "--frames", "1",
             "--angles", "45", "--methods", "binary,exact,robust"]
T1_CASES = [(f"terrain {n}²", "terrain", n, r, ["--field", "fbm", "--field-size", str(n), "--seed", "3", *a])
            for n in T1_SIZES for r, a in (("strict", ["--radius", "strict"]), ("paper", ["--radius", "paper"]))] + \
           [("walls (grid) 128²", "walls", 128, "paper", ["--field", "walls", "--field-size", "128", "--radius", "paper"]),
            ("knot (object) 128²", "knot", 128, "paper", ["--field-mesh", "shape:knot", "--field-size", "128", "--radius", "paper"])]
T1_PAPER_HZ = {"binary": (109, 109, 110, 108), "exact": (115, 87, 58, 36), "robust": (116, 105, 97, 96)}  # Table 1, terrain


def table1_commands():
    caps = [[*T1_COMMON, *args, "-o", f"t1_{k}.nbt"] for k, (_, _, _, _, args) in enumerate(T1_CASES)]
    return caps + [["replay", f"t1_{k}.nbt", "--out", f"t1_{k}"] for k in range(len(T1_CASES))]


def render_table1(outputs):
    import json
    files = [json.loads(t) for t in outputs[-len(T1_CASES):]]
    lines = ["| heightfield | radius | mean radius | robust: cycles / box draw | lookups / fragment | hit errors | exact: cycles | "
             "lookups / fragment | binary: cycles | lookups / fragment | paper, Hz (binary, exact, robust) |",
             "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---|"]
    robust = {}
    for (label, kind, size, radius, _), f in zip(T1_CASES, files):
        s = f["summary"]["relief"]
        m = s["methods"]
        paper = ", ".join(str(T1_PAPER_HZ[x][T1_SIZES.index(size)]) for x in ("binary", "exact", "robust")) if kind == "terrain" else "-"
        lines.append(f"| {label} | {radius} | {s['radius_mean']:.2f} | {n(m['robust']['cycles_per_frame'])} | "
                     f"{m['robust']['lookups_per_fragment']:.1f} | {m['robust']['errors']:,} | {n(m['exact']['cycles_per_frame'])} | "
                     f"{m['exact']['lookups_per_fragment']:.1f} | {n(m['binary']['cycles_per_frame'])} | "
                     f"{m['binary']['lookups_per_fragment']:.1f} | {paper} |")
        if kind == "terrain":
            robust[(radius, size)] = m["robust"]
    def growth(radius, key):
        a, b = robust[(radius, T1_SIZES[0])][key], robust[(radius, T1_SIZES[-1])][key]
        return b / a
    lines += ["", f"From 32² to 256² on the terrain the paper's robust search loses 17 % of its frame rate (116 -> 96 Hz). Ours, "
              f"with the paper's radius: lookups per fragment x {growth('paper', 'lookups_per_fragment'):.2f}, cycles x "
              f"{growth('paper', 'cycles_per_frame'):.2f}; with the strict radius: lookups x "
              f"{growth('strict', 'lookups_per_fragment'):.2f}, cycles x {growth('strict', 'cycles_per_frame'):.2f}."]
    return "\n".join(lines)


BLOCKS.append(Block("table1_setup", table1_commands(), render_table1, files=tuple(f"t1_{k}/run.json" for k in range(len(T1_CASES)))))
