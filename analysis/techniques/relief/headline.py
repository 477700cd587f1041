"""The relief textures' row of README.md's headline table, on the relief sample.

The module protocol (ORDER, collect, rows) is in analysis/readme_headline.py.
"""

ORDER = 4
TRACE = "traces/samples/relief_fbm_64.nbt"


def collect(run):
    return {"table": run("relief", TRACE, "--json")}


def rows(d):
    methods = {}
    for r in d["table"]["rows"]:
        m = methods.setdefault(r["method"], {"fragments": 0, "errors": 0, "lookups": 0, "walk_mismatches": 0})
        for k in m:
            m[k] += r[k]
    nb = methods["nbuffer"]
    others = ", ".join(f"{name} {m['errors']}" for name, m in sorted(methods.items()) if name != "nbuffer")
    first = d["table"]["rows"][0]
    return [(f"Relief textures ({first['field'].split(':')[0]} heightfield, {first['field_size']}²)",
             f"the N-buffer empty-space walk: {nb['errors']} hit errors in {nb['fragments']:,} rays at "
             f"{nb['lookups'] / nb['fragments']:.1f} lookups a ray (errors of the others: {others}); "
             f"{sum(m['walk_mismatches'] for m in methods.values())} walks unlike GL's",
             f"`nbsim relief {TRACE}`", "[relief](docs/relief.md)")]
