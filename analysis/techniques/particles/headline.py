"""The particles' row of README.md's headline table, on the particles sample.

The module protocol (ORDER, collect, rows) is in analysis/readme_headline.py.
"""

ORDER = 1
TRACE = "traces/samples/particles_walk_256.nbt"


def collect(run):
    return {"viewport": run("trace", "info", TRACE, "--json")["properties"]["viewport"],
            "table": run("particles", TRACE, "--json"),
            "center": run("particles", TRACE, "--json", "--set", "particles.mode=center")}


def rows(d):
    (p,), (c,) = d["table"], d["center"]
    return [(f"Particles ({p['particles_per_frame']:,.0f} sprites of {p['sprite']} px, {d['viewport']})",
             f"N-buffer queries read {p['query_depth_tests_per_frame']:,.0f} texels a frame against "
             f"{p['raster_depth_tests_per_frame'] / 1e6:.1f} M raster depth tests; {p['popping']} popping "
             f"(the centre test pops {c['popping']:,} sprite-frames)",
             f"`nbsim particles {TRACE}` (`--set particles.mode=center`)", "[particles](docs/particles.md)")]
