"""The layered depth images' row of README.md's headline table: the sphere of the paper's Table 1, on GL.

The module protocol (ORDER, collect, rows) is in analysis/readme_headline.py.
"""

ORDER = 3


def collect(run):
    return {"table": run("ldi", "table1", "--shapes", "sphere", "--json")}


def rows(d):
    (r,) = d["table"]
    return [(f"Layered depth images ({r['shape']}, {r['ldi_size']}²)",
             f"compression ratio {r['c_ratio']:.3f} (the paper's Table 1: {r['paper_c_ratio']}); "
             f"{r['gl_parity_mismatches']} parity answers unlike GL's",
             "`nbsim ldi table1 --shapes sphere`", "[LDIs](docs/ldi.md)")]
