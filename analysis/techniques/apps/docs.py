"""The apps technique's results in docs/apps.md, generated (the protocol: analysis/doc_results.py):
a recorded program's draw calls culled in every cull mode, on the committed samples."""
from doc_results import Block, thousands as n

PAGE = "apps.md"
OPENARENA = "traces/samples/apps_openarena_320.nbt"
IDEAS = "traces/samples/apps_glmark2_ideas_160.nbt"


def table(rows, extra=()):
    lines = ["| mode | draws / frame | culled / frame | query tests | upkeep texels | drawn tests | total tests | cycles "
             "| culling efficiency | false culls | differing draws |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for label, r in [(r["mode"], r) for r in rows] + list(extra):
        e = r["culling_efficiency"]
        lines.append(f"| {label} | {n(r['draws_per_frame'], 1)} | {n(r['culled_per_frame'], 1)} | "
                     f"{n(r['query_depth_tests_per_frame'])} | {n(r['update_texels_per_frame'])} | "
                     f"{n(r['drawn_depth_tests_per_frame'])} | {n(r['total_depth_tests_per_frame'])} | {n(r['cycles_per_frame'])} | "
                     f"{'-' if e is None else f'{100 * e:.1f} %'} | {r['false_culls']} | {r['mismatched']} |")
    return "\n".join(lines)


def reading(rows, label):
    by = {r["mode"]: r for r in rows}
    none, oq, nb, tile = by["none"], by["oq"], by["nb"], by["hiz_tile"]
    culling = [r for r in rows if r["mode"] != "none"]
    best = min(culling, key=lambda r: r["total_depth_tests_per_frame"])
    fastest = min(culling, key=lambda r: r["cycles_per_frame"])
    false_culls = sum(r["false_culls"] for r in rows)
    return (f"{label}: {none['gl_hidden']:,} of its {n(none['draws_per_frame'] * none['frames'])} draw calls pass no sample in GL; "
            f"{nb['tested']:,} are tested (drawn into the frame's main target by a draw the model replays, with a depth test "
            f"that fails behind), {nb['tested_hidden']:,} of them hidden. An occlusion query per draw call culls "
            f"{100 * oq['culling_efficiency']:.1f} % of those, the N-buffer {100 * nb['culling_efficiency']:.1f} % with "
            f"{oq['query_depth_tests_per_frame'] / max(nb['query_depth_tests_per_frame'], 1):,.0f} times fewer query depth "
            f"tests; tile Hi-Z {100 * tile['culling_efficiency']:.1f} %. Keeping the N-buffer current with eager updates costs "
            f"{n(nb['update_texels_per_frame'])} texels a frame, {nb['update_texels_per_frame'] / max(none['drawn_depth_tests_per_frame'], 1):.1f} "
            f"times the depth tests of drawing every draw call ({n(none['drawn_depth_tests_per_frame'])}). The draw calls an occlusion "
            f"query culls would have cost {n(none['drawn_depth_tests_per_frame'] - oq['drawn_depth_tests_per_frame'])} depth tests a "
            f"frame ({100 * (none['drawn_depth_tests_per_frame'] - oq['drawn_depth_tests_per_frame']) / max(none['drawn_depth_tests_per_frame'], 1):.1f} % "
            f"of drawing them all): the hidden draw calls are small. Fewest depth tests in total: {best['mode']} "
            f"({n(best['total_depth_tests_per_frame'])} a frame, "
            + ("below" if best['total_depth_tests_per_frame'] < none['total_depth_tests_per_frame'] else "above")
            + f" the {n(none['total_depth_tests_per_frame'])} of drawing every draw call); fewest cycles: {fastest['mode']} "
            f"({n(fastest['cycles_per_frame'])}, none {n(none['cycles_per_frame'])}; a culled draw call still costs its launch). "
            f"{'No mode culls a draw GL drew' if false_culls == 0 else f'{false_culls} FALSE CULLS'}, and every draw the model "
            "draws still passes GL's samples exactly.")


def render_culling(outputs):
    oa, oa_prim, oa_demand, ideas = outputs
    prim = {r["mode"]: r for r in oa_prim}
    demand = {r["mode"]: r for r in oa_demand}
    return ("OpenArena (frames 1000 to 1004 of the demo, 320x240, GLSL renderer):\n\n" +
            table(oa, [("nb, per-primitive", prim["nb"]), ("hiz_tile, per-primitive", prim["hiz_tile"]),
                       ("nb, on-demand levels", demand["nb"])]) + "\n\n" + reading(oa, "OpenArena") +
            f" Testing every triangle of the visible draw calls too (per-primitive) brings the N-buffer's drawn depth tests "
            f"from {n({r['mode']: r for r in oa}['nb']['drawn_depth_tests_per_frame'])} to {n(prim['nb']['drawn_depth_tests_per_frame'])} "
            f"a frame; on-demand levels bring its upkeep to {n(demand['nb']['update_texels_per_frame'])} texels a frame.\n\n"
            "glmark2's ideas scene (frames 2 to 21, 160x120):\n\n" + table(ideas) + "\n\n" + reading(ideas, "glmark2 ideas"))


BLOCKS = [
    Block("culling", [["table2", OPENARENA, "--json"],
                      ["table2", OPENARENA, "--json", "--set", "cull.granularity=primitive"],
                      ["table2", OPENARENA, "--json", "--set", "nbuffer.update_policy=on_demand"],
                      ["table2", IDEAS, "--json"]], render_culling),
]
