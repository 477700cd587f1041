"""Occlusion culling's rows of README.md's headline table: Table 2 and the culling ladder, on the walkthrough sample.

The module protocol (ORDER, collect, rows) is in analysis/readme_headline.py.
"""

ORDER = 0
WALK = "traces/samples/city_walk_512.nbt"
# The culling ladder: nb_hier on the walkthrough with each covering (the sample's own is the paper's).
LADDER = [("corners", ["--set", "nbuffer.covering=corners", "--set", "nbuffer.align=bottom"]),
          ("rect", ["--set", "nbuffer.levels=rect"])]


def collect(run):
    return {"viewport": run("trace", "info", WALK, "--json")["properties"]["viewport"],
            "table2": run("table2", WALK, "--json"),
            "ladder": {name: run("compare", WALK, "--json", "--set", "cull.mode=nb_hier", *sets)["cull"]
                       for name, sets in LADDER}}


def rows(d):
    t2 = {r["mode"]: r for r in d["table2"]}
    oq, nb, nbh = t2["oq"], t2["nb"], t2["nb_hier"]
    ratio = oq["query_depth_tests_per_frame"] / nb["query_depth_tests_per_frame"]
    paper_ratio = oq["paper_depth_tests_per_frame"] / nb["paper_depth_tests_per_frame"]
    false_culls = sum(int(r["false_culls"]) for r in d["table2"])
    ladder = d["ladder"]
    return [
        (f"Table 2, the city walkthrough ({d['viewport']}, {d['table2'][0]['frames']} frames)",
         f"N-buffer queries take {ratio:,.0f}x fewer depth tests than occlusion queries (the paper: {paper_ratio:,.0f}x), "
         f"{false_culls} false culls; but eager level updates cost {nbh['update_texels_per_frame'] / 1e6:.1f} M texels a "
         f"frame (`nb_hier`), against {nbh['query_depth_tests_per_frame']:,.0f} query depth tests",
         f"`nbsim table2 {WALK}`", "[results](docs/results.md)"),
        ("The culling ladder (walkthrough, `nb_hier`)",
         f"culling efficiency with the corner covering {100 * ladder['corners']['culling_efficiency']:.1f}%, the "
         f"paper's {100 * nbh['culling_efficiency']:.1f}%, rectangle levels (the ideal rectangle test) "
         f"{100 * ladder['rect']['culling_efficiency']:.1f}%, occlusion queries {100 * oq['culling_efficiency']:.1f}%",
         f"`nbsim compare {WALK} --set cull.mode=nb_hier --set nbuffer.levels=rect` (or `nbuffer.covering=corners`)",
         "[covering](docs/covering.md)"),
    ]
