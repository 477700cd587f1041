"""The shadow volumes' row of README.md's headline table, on the shadows sample.

The module protocol (ORDER, collect, rows) is in analysis/readme_headline.py.
"""

ORDER = 2
TRACE = "traces/samples/shadows_city_fly_320_litmap256.nbt"


def collect(run):
    return {"viewport": run("trace", "info", TRACE, "--json")["properties"]["viewport"],
            "table": run("shadows", TRACE, "--json")}


def rows(d):
    (s,) = d["table"]
    return [(f"Shadow volumes with litmaps ({s['scene']}, {d['viewport']}, {s['litmap_size']}² litmaps)",
             f"clamping cuts the shadow-volume fill to {100 * s['fill_ratio_to_infinite']:.1f}% of the infinite volumes' "
             f"(the paper: 2.5% at 640x480); {s['mask_diff']} shadow-mask pixels unlike GL's",
             f"`nbsim shadows {TRACE}`", "[shadows](docs/shadows.md)")]
