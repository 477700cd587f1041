"""The apps technique's row of README.md's headline table: OpenArena's draw calls culled in every mode.

The module protocol (ORDER, collect, rows) is in analysis/readme_headline.py.
"""

ORDER = 5
TRACE = "traces/samples/apps_openarena_320.nbt"


def collect(run):
    return {"viewport": run("trace", "info", TRACE, "--json")["properties"]["viewport"],
            "table": run("table2", TRACE, "--json")}


def rows(d):
    t = {r["mode"]: r for r in d["table"]}
    none, oq, nb, tile = t["none"], t["oq"], t["nb"], t["hiz_tile"]
    false_culls = sum(int(r["false_culls"]) for r in d["table"])
    saved = none["drawn_depth_tests_per_frame"] - oq["drawn_depth_tests_per_frame"]
    spent = min(r["query_depth_tests_per_frame"] + r["update_texels_per_frame"] for m, r in t.items() if m != "none")
    than = "less" if saved < spent else "more"
    return [(f"A real program: OpenArena's draw calls culled ({d['viewport']}, {none['frames']} frames, "
             f"{none['draws_per_frame']:,.0f} draw calls a frame)",
             f"occlusion queries cull {100 * oq['culling_efficiency']:.1f}% of the hidden draw calls, the N-buffer "
             f"{100 * nb['culling_efficiency']:.1f}% with {oq['query_depth_tests_per_frame'] / nb['query_depth_tests_per_frame']:,.0f}x "
             f"fewer query depth tests, tile Hi-Z {100 * tile['culling_efficiency']:.1f}%; {false_culls} false culls; the culled "
             f"draw calls would have cost {100 * saved / none['drawn_depth_tests_per_frame']:.1f}% of the frame's depth tests, "
             f"{than} than the cheapest mode spends on its queries and upkeep",
             f"`nbsim table2 {TRACE}`", "[apps](docs/apps.md)")]
