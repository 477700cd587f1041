"""The layered depth images' results in docs/ldi.md, generated (the protocol: analysis/doc_results.py)."""
import json

from doc_results import Block, thousands as n

PAGE = "ldi.md"
MODELS = "/usr/share/assimp/models"
FRESH = [("duck.dae", ["--mesh", f"{MODELS}/Collada/duck.dae"]),
         ("HUMAN.blend", ["--mesh", f"{MODELS}/BLEND/HUMAN.blend"]),
         ("knot", ["--shape", "knot"]),
         ("coil, 7 turns", ["--shape", "coil", "--shape-param", "7"])]



def fresh_capture(i, shape):
    return ["capture", "ldi", "--size", "8x8", "--frames", "3", "--seed", "7",
            *shape, "--ldi-size", "200", "--points", "5000", "-o", f"f{i}.nbt"]


def equal_or_both(model, gl):
    return n(model) if model == gl else f"model {n(model)}, GL {n(gl)}"


def render_fresh(outputs):
    lines = ["| capture | peel passes | fragments, model = GL | samples passed, model = GL | layer texels, crops, compressed "
             "values differing | parity answers differing (layers / ranges / every layer) | misclassified against the exact reference |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    for (label, _), c in zip(FRESH, outputs[len(FRESH):]):
        s = c["ldi"]
        lines.append(f"| {label} | {s['peel_passes']} | {equal_or_both(s['peel_fragments'], s['gl_peel_fragments'])} | "
                     f"{equal_or_both(s['peel_samples'], s['gl_peel_samples'])} | {s['layer_texel_mismatches']}, "
                     f"{s['crop_mismatch']}, {s['compressed_mismatches']} | {s['parity_mismatches_layers']} / "
                     f"{s['parity_mismatches_ranges']} / {s['parity_mismatches_all']} | {s['misclassified_layers']} of "
                     f"{n(s['classified_points'])} |")
    within = sum(1 for c in outputs[len(FRESH):] if c["within_thresholds"])
    return "\n".join(lines) + f"\n\n{within} of the {len(FRESH)} captures replay within `nbsim compare`'s thresholds."


def render_sample(outputs):
    (c,) = outputs
    s = c["ldi"]
    return (f"The sample replays the same way: {s['peel_passes']} peel passes, {n(s['peel_fragments'])} fragments and "
            f"{n(s['peel_samples'])} samples ({'equal to' if (s['peel_fragments'], s['peel_samples']) == (s['gl_peel_fragments'], s['gl_peel_samples']) else 'unlike'} "
            f"GL's), {s['layer_texel_mismatches']} layer texels differing, {s['parity_mismatches_layers'] + s['parity_mismatches_ranges']} "
            f"of {n(2 * s['test_points'])} parity answers (both readers) differing from GL's; C_ratio {s['c_ratio']:.3f}.")


def render_table1(outputs):
    (rows,) = outputs
    lines = ["| the paper's shape | our shape: why | vertices, paper / ours | d_min / d_max, paper / ours | d | M_crop | M_comp | "
             "C_ratio, paper / ours |",
             "|---|---|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        if r.get("paper_c_ratio") is not None:
            lines.append(f"| {r['paper_row']} | {r['shape']}: {r['paper_stand_in']} | {n(r['paper_vertices'])} / {n(r['vertices'])} | "
                         f"{r['paper_d_min']} / {r['paper_d_max']}, {r['d_min']} / {r['d_max']} | {r['layers']} | {n(r['m_crop'])} | "
                         f"{n(r['m_comp'])} | {r['paper_c_ratio']:.2f} / {r['c_ratio']:.3f} |")
        else:
            lines.append(f"| - | {r['shape']} | {n(r['vertices'])} | {r['d_min']} / {r['d_max']} | {r['layers']} | {n(r['m_crop'])} | "
                         f"{n(r['m_comp'])} | {r['c_ratio']:.3f} |")
    paper = [r for r in rows if r.get("paper_c_ratio") is not None]
    same_d = sum(1 for r in paper if (r["d_min"], r["d_max"]) == (r["paper_d_min"], r["paper_d_max"]))
    worst = max(paper, key=lambda r: abs(r["c_ratio"] - r["paper_c_ratio"]))
    mismatches = sum(r["gl_parity_mismatches"] + r["readers_disagree"] for r in rows)
    return ("\n".join(lines) + f"\n\nOf the paper's {len(paper)} rows, {same_d} stand-ins have the paper's d_min and "
            f"d_max; the compression ratio is farthest from the paper's for {worst['shape']} ({worst['c_ratio']:.3f} against "
            f"{worst['paper_c_ratio']:.2f}, {worst['paper_row']}). Over the rows, {mismatches} parity answers differ between the "
            "model and GL or between the readers.")


def render_sizes(outputs):
    (rows,) = outputs
    sizes = sorted({r["ldi_size"] for r in rows})
    shapes = list(dict.fromkeys(r["shape"] for r in rows))
    at = {(r["shape"], r["ldi_size"]): r for r in rows}
    lines = ["Points uniform in the cube misclassified by their texel (4,096 a row), and GL's misclassified points "
             "against the exact reference (of about 3,072 farther than epsilon from a surface), by LDI side:", "",
             "| shape | " + " | ".join(f"{s}: uniform / GL" for s in sizes) + " | texels a test reads, layers / ranges (largest side) |",
             "|---|" + "---:|" * (len(sizes) + 1)]
    for sh in shapes:
        big = at[(sh, sizes[-1])]
        lines.append(f"| {sh} | " + " | ".join(f"{at[(sh, s)]['misclassified_anywhere']} / {at[(sh, s)]['misclassified_layers']}"
                                            for s in sizes) +
                     f" | {big['fetches_anywhere_layers']:.2f} / {big['fetches_anywhere_ranges']:.2f} |")
    disagree = sum(r["readers_disagree"] + r["gl_parity_mismatches"] for r in rows)
    fl = [r["fetches_anywhere_layers"] for r in rows]
    fr = [r["fetches_anywhere_ranges"] for r in rows]
    agree = "on every point" if disagree == 0 else f"on every point but {disagree}"
    lines += ["", f"All three readers, and the model's parity test on GL's LDI, give GL's answers {agree}. "
              f"A test reads {min(fl):.2f} to {max(fl):.2f} layer texels uncompressed against {min(fr):.2f} to {max(fr):.2f} "
              "compressed texels (RG32UI, 8 bytes each) for uniform points."]
    return "\n".join(lines)


# The paper's reader (every layer) beside the early-exit and compressed ones, on shells of growing
# depth complexity: Trapp & Doellner's O(d) against O(d/2).
READER_SHELLS = (1, 2, 4, 8, 16)


def render_readers(outputs):
    (rows,) = outputs
    lines = ["| shape | d | every layer (the paper's) | early exit | compressed | compressed at most (1 + d/2) | answers differing |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        d = r["layers"]
        lines.append(f"| {r['shape']} | {d} | {r['fetches_anywhere_all']:.2f} | {r['fetches_anywhere_layers']:.2f} | "
                     f"{r['fetches_anywhere_ranges']:.2f} | {1 + (d + 1) // 2} | {r['readers_differ'] + r['gl_parity_mismatches']} |")
    first, last = rows[0], rows[-1]
    grow = lambda k: last[k] / first[k]
    return ("\n".join(lines) + f"\n\nFrom d = {first['layers']} to d = {last['layers']} the paper's reader's fetches grow "
            f"{grow('fetches_anywhere_all'):.1f}x (O(d)), the compressed reader's {grow('fetches_anywhere_ranges'):.1f}x and the "
            f"early exit's {grow('fetches_anywhere_layers'):.1f}x.")


# The applications in a scene (traces/capture/ldi/clip.h): fresh captures on paths, seeds and
# volumes no test uses, and the paper's viewport for its render-speed claims.
CLIP = [("clip, 3 ducks (duck.dae), walk, seed 11", ["--application", "clip", "--path", "walk", "--seed", "11", "--mesh",
                                                   f"{MODELS}/Collada/duck.dae"]),
        ("lens, 3 nested:2, walk, seed 5, reader ranges", ["--application", "lens", "--path", "walk", "--seed", "5", "--shape", "nested",
                                                          "--shape-param", "2", "--reader", "ranges"])]
READERS = ("all", "layers", "ranges")
CLOCK_GHZ = 1.0


def clip_capture(i, args):
    return ["capture", "ldi", "--size", "640x480", "--frames", "3", "--ldi-size", "128", *args, "-o", f"c{i}.nbt"]


def clip_row(label, s):
    tested = s["clip_fragments"]
    return (f"| {label} | {n(tested)} | {n(s['clip_discarded'])} ({100 * s['clip_discarded'] / tested:.2f} %) | "
            f"{equal_or_both(s['clip_samples'], s['gl_clip_samples'])} | {s['clip_draw_mismatches']}, {s['clip_decision_mismatches']}, "
            f"{s['clip_depth_mismatches']} | {n(s['clip_misclassified'])} of {n(s['clip_classified'])} ({n(s['clip_near_surface'])} near) |")


def render_clip(outputs):
    lines = ["| capture (640x480, 3 frames) | fragments tested | discarded (depth tests saved) | samples passed, model = GL | draws, "
             "discard sets, final depth buffers unlike GL's | misclassified against the exact reference |",
             "|---|---:|---:|---:|---:|---:|"]
    compares = outputs[len(CLIP):2 * len(CLIP)]
    for (label, _), c in zip(CLIP, compares):
        lines.append(clip_row(label, c["ldi"]))
    run = json.loads(outputs[-1])
    per_frame = ", ".join(f"{f['clip_misclassified']} of {n(f['clip_classified'])}" for f in run["frames"])
    within = sum(1 for c in compares if c["within_thresholds"])
    return ("\n".join(lines) + f"\n\n{within} of the {len(CLIP)} captures replay within `nbsim compare`'s thresholds. Misclassified "
            f"fragments frame by frame (the first capture, `run.json` frames): {per_frame}.")


def render_clip_speed(outputs):
    lines = ["| reader | fetches a test: the reader's | every layer / early exit / compressed | volume tests a fragment | cache misses | "
             "cycles a frame | frames a second at 1 GHz | draws unlike GL's |",
             "|---|---:|---:|---:|---:|---:|---:|---:|"]
    cycles = {}
    for reader, c in zip(READERS, outputs[len(READERS):]):
        s = c["ldi"]
        t = s["clip_fragments"]
        cycles[reader] = s["clip_cycles_per_frame"]
        lines.append(f"| {reader} | {s['clip_fetches'] / t:.3f} | {s['clip_fetches_per_test_all']:.3f} / {s['clip_fetches_per_test_layers']:.3f} / "
                     f"{s['clip_fetches_per_test_ranges']:.3f} | {s['clip_volume_tests'] / t:.2f} | {n(s['clip_cache_misses'])} | "
                     f"{n(round(cycles[reader]))} | {CLOCK_GHZ * 1e9 / cycles[reader]:.0f} | {s['clip_draw_mismatches']} |")
    slower = "slower" if cycles["ranges"] > cycles["all"] else "faster"
    return ("\n".join(lines) + f"\n\nWith the default costs the compressed reader's frame is {slower} than the paper's uncompressed one "
            f"({cycles['ranges'] / cycles['all']:.3f}x its cycles), and the early exit's {cycles['layers'] / cycles['all']:.3f}x.")


BLOCKS = [
    Block("fresh", [fresh_capture(i, s) for i, (_, s) in enumerate(FRESH)] +
          [["compare", f"f{i}.nbt", "--json"] for i in range(len(FRESH))], render_fresh),
    Block("sample", [["compare", "traces/samples/ldi_nested_128.nbt", "--json"]], render_sample),
    Block("table1", [["ldi", "table1", "--mesh", f"{MODELS}/Collada/duck.dae", "--json"]], render_table1),
    Block("sizes", [["ldi", "table1", "--shapes", "sphere,knot,nested:3,nested:9,coil:4,coil:9", "--sizes", "64,128,256,512,1024",
                     "--json"]], render_sizes),
    Block("readers", [["ldi", "table1", "--shapes", ",".join(f"nested:{k}" for k in READER_SHELLS), "--sizes", "256", "--json"]],
          render_readers),
    Block("clip", [clip_capture(i, a) for i, (_, a) in enumerate(CLIP)] + [["compare", f"c{i}.nbt", "--json"] for i in range(len(CLIP))] +
          [["replay", "c0.nbt", "--out", "r0"]], render_clip, files=("r0/run.json",)),
    Block("clip_speed", [["capture", "ldi", "--application", "clip", "--size", "1600x1200", "--frames", "1", "--shape", "knot", "--ldi-size",
                          "256", "--reader", r, "-o", f"s_{r}.nbt"] for r in READERS] +
          [["compare", f"s_{r}.nbt", "--json"] for r in READERS], render_clip_speed),
]
