"""The report's ldi section, from the LDI table (`nbsim ldi table1 --out DIR/ldi`).

It shows Table 1 beside the paper's ratios, the parity test's misclassification and fetches.

Loaded by analysis/report.py with every analysis/techniques/<name>/section.py (NAME, TITLE, ORDER
and section(rep), which returns the section's HTML or raises report_data.Missing / BadInput); report.py
puts analysis/ on the import path first.
"""
import html

from report_plots import FIGSIZE  # first: it selects the headless backend
import matplotlib.pyplot as plt
from report_data import (BadInput, Missing, load_rows, pct)

NAME = "ldi"
TITLE = "Layered depth images: Table 1 and the parity test's misclassification"
ORDER = 3  # the sections' order on the page and in headline.md


LDI_NEED = ["shape", "ldi_size", "vertices", "d_min", "d_max", "layers", "m_crop", "m_comp", "points", "classified",
            "near_surface", "misclassified_layers", "misclassified_ranges", "fetches_per_test_layers",
            "fetches_per_test_ranges"]


LDI_OPTIONAL_NUMBERS = ["c_ratio", "ms_viewpoint", "ms_peel", "ms_crop", "ms_compress", "triangles",
                        "paper_c_ratio", "gl_parity_mismatches", "classified_anywhere", "misclassified_anywhere",
                        "fetches_anywhere_layers", "fetches_anywhere_ranges", "fetches_per_test_all", "fetches_anywhere_all"]


# The paper's Table 1 rows set beside ours (Trapp & Doellner 2008, 1024x1024 LDIs): ldi.json's rows
# carry the paper's row of their stand-in (paper_row, paper_c_ratio); this is the fallback for rows
# of older files, the sphere only. Fixed by the paper.
PAPER_LDI = {"sphere": ("Sphere, 994 vertices, d = 2", 1.78)}


def load_ldi(path):
    """The rows of ldi.json (nbsim ldi table1 --out: one object per shape and LDI size), checked; BadInput otherwise."""
    t = load_rows(path, "nbsim ldi table1", LDI_NEED, ["shape"], LDI_NEED[1:] + LDI_OPTIONAL_NUMBERS)
    for i, r in enumerate(t):
        if r["ldi_size"] <= 0 or r["points"] < 0 or r["classified"] < 0 or r["classified"] > r["points"]:
            raise BadInput(f"{path}: rows[{i}]: ldi_size must be above 0 and classified within [0, points]")
        if r["misclassified_layers"] > r["classified"] or r["misclassified_ranges"] > r["classified"]:
            raise BadInput(f"{path}: rows[{i}]: more points misclassified than classified")
    return t


def ldi_rows(rows):
    """The rows by shape (as given, first appearance) and LDI size, each with the misclassification rates of both
    readers (over the classified points; None without any) and the paper's ratio where it has one."""
    shapes = list(dict.fromkeys(r["shape"] for r in rows))
    out = []
    for r in sorted(rows, key=lambda r: (shapes.index(r["shape"]), r["ldi_size"])):
        rr = dict(r)
        n = r["classified"]
        rr["error_layers"] = r["misclassified_layers"] / n if n else None
        rr["error_ranges"] = r["misclassified_ranges"] / n if n else None
        na = r.get("classified_anywhere")
        rr["error_anywhere"] = r["misclassified_anywhere"] / na if na and r.get("misclassified_anywhere") is not None else None
        base = r["shape"].split(":")[0]
        paper = PAPER_LDI.get(base)
        rr["paper_text"] = r.get("paper_row") or (paper[0] if paper else "")
        rr["paper_c_ratio"] = r.get("paper_c_ratio", paper[1] if paper else None)
        out.append(rr)
    return out


def ldi_reading(rows):
    """What the LDI table shows, as plain sentences computed from its rows."""
    out = []
    lossless = [r for r in rows if r["error_layers"] is not None and r["misclassified_layers"] != r["misclassified_ranges"]]
    if lossless:
        out.append("THE READERS DISAGREE in " + ", ".join(f"{r['shape']} {r['ldi_size']}" for r in lossless) +
                   ": compression is lossless, so both must misclassify the same points.")
    else:
        out.append(f"Both readers misclassify the same number of points in every row ({len(rows)} rows): the compression "
                   "is lossless, so it changes the cost of a test, not its answer.")
    bad_gl = [r for r in rows if r.get("gl_parity_mismatches")]
    if bad_gl:
        out.append("GL AND THE MODEL DISAGREE on " + ", ".join(f"{r['shape']} {r['ldi_size']} ({r['gl_parity_mismatches']:,})"
                                                              for r in bad_gl) + " parity answers.")
    for shape in dict.fromkeys(r["shape"] for r in rows):
        g = [r for r in rows if r["shape"] == shape and r["error_layers"] is not None]
        if not g:
            continue
        lo, hi = g[0], g[-1]
        s = (f"{shape}: misclassified {pct(lo['error_layers'], 2)} of its test points at {lo['ldi_size']}² "
             + (f"and {pct(hi['error_layers'], 2)} at {hi['ldi_size']}²" if hi is not lo else "")
             + ("" if lo.get("error_anywhere") is None else
                f" (uniform points anywhere in their texel: {pct(lo['error_anywhere'], 2)}"
                + (f" falling to {pct(hi['error_anywhere'], 2)})" if hi is not lo and hi.get("error_anywhere") is not None else ")"))
             + f"; a test reads {hi['fetches_per_test_layers']:.2f} layer texels uncompressed against "
             f"{hi['fetches_per_test_ranges']:.2f} texels compressed"
             + ("" if hi.get("fetches_per_test_all") is None else
                f" and {hi['fetches_per_test_all']:.2f} with the paper's reader (every layer: O(d) against the compressed O(d/2))"))
        if hi.get("c_ratio") is not None:
            s += f", C_ratio {hi['c_ratio']:.2f}"
            if hi.get("paper_c_ratio") is not None:
                s += f" (the paper's {hi['paper_text']}: {hi['paper_c_ratio']:.2f})"
        out.append(s + ".")
    return out


def headline_ldi(label, rows, reading):
    """The LDI Table 1 reproduction and misclassification, as Markdown."""
    lines = [f"Layered depth images ({label}): Table 1 beside the paper's ratios, and the parity test's misclassification "
             "against the exact reference",
             "",
             "| shape | LDI | vertices | d_min/d_max | M_crop | M_comp | C_ratio | paper | misclassified | anywhere in the texel | fetches/test (layers, ranges) | ms viewpoint/peel/crop/compress |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    ms = lambda r, k: "-" if r.get(k) is None else f"{r[k]:,.1f}"  # noqa: E731
    for r in rows:
        lines.append(f"| {r['shape']} | {r['ldi_size']} | {r['vertices']:,} | {r['d_min']}/{r['d_max']} | {r['m_crop']:,} | "
                     f"{r['m_comp']:,} | {'-' if r.get('c_ratio') is None else format(r['c_ratio'], '.3f')} | "
                     f"{'-' if r.get('paper_c_ratio') is None else format(r['paper_c_ratio'], '.2f')} | "
                     f"{pct(r['error_layers'], 2)} of {r['classified']:,} | "
                     f"{pct(r.get('error_anywhere'), 2)} | "
                     f"{r['fetches_per_test_layers']:.2f}, {r['fetches_per_test_ranges']:.2f} | "
                     f"{ms(r, 'ms_viewpoint')}/{ms(r, 'ms_peel')}/{ms(r, 'ms_crop')}/{ms(r, 'ms_compress')} |")
    return "\n".join(lines + [""] + [f"- {s}" for s in reading])


def section(rep):
    path = rep.technique_table_path(NAME)
    if path is None:
        raise Missing(["ldi/ldi.json"])
    rows = ldi_rows(load_ldi(path))
    rep.used(path, "ldi")
    num = lambda d: (lambda v: "-" if v is None else f"{v:,.{d}f}")  # noqa: E731
    cols = [("shape", "shape", None), ("LDI side", "ldi_size", None), ("vertices", "vertices", None),
            ("d_min", "d_min", None), ("d_max", "d_max", None), ("layers (chosen view)", "layers", None),
            ("M_crop (values)", "m_crop", None), ("M_comp (values)", "m_comp", None),
            ("C_ratio", "c_ratio", num(3)), ("paper C_ratio", "paper_c_ratio", num(2)),
            ("paper row", "paper_text", lambda v: v or "-"),
            ("viewpoint ms", "ms_viewpoint", num(1)), ("peel ms", "ms_peel", num(1)),
            ("crop ms", "ms_crop", num(2)), ("compress ms", "ms_compress", num(2)),
            ("points", "points", None), ("near a surface", "near_surface", None),
            ("misclassified (layers)", "error_layers", lambda v: pct(v, 3)),
            ("misclassified (ranges)", "error_ranges", lambda v: pct(v, 3)),
            ("misclassified anywhere in the texel", "error_anywhere", lambda v: pct(v, 3)),
            ("fetches/test (layers)", "fetches_per_test_layers", num(2)),
            ("fetches/test (ranges)", "fetches_per_test_ranges", num(2)),
            ("fetches/test (every layer, the paper's)", "fetches_per_test_all", num(2))]
    tab = rep.table("ldi", cols, rows,
                     row_class=lambda r: "bad" if r["misclassified_layers"] != r["misclassified_ranges"]
                     or r.get("gl_parity_mismatches") else "")
    reading = ldi_reading(rows)
    shapes = list(dict.fromkeys(r["shape"] for r in rows))
    rep.headline_last.append(headline_ldi(f"{len(shapes)} shapes, {len(rows)} LDIs", rows, reading))

    # cost against error: one line per shape and reader through its LDI sizes; x the texels a test reads
    # (uncompressed: layer texels, 4 bytes; compressed: RG32UI texels, 8 bytes), y the misclassification
    fig, ax = plt.subplots(figsize=FIGSIZE, constrained_layout=True)
    cmap = plt.get_cmap("tab10")
    floor = None
    for i, shape in enumerate(shapes):
        g = [r for r in rows if r["shape"] == shape and r["error_layers"] is not None]
        if not g:
            continue
        # the LDI's sampling error (uniform points anywhere in their texel) when the rows have it, else the
        # test points' against their texel-centre reference
        anywhere = all(r.get("error_anywhere") is not None and r.get("fetches_anywhere_layers") is not None for r in g)
        series = ((("error_anywhere", "fetches_anywhere_layers", "-o", "layers"),
                   ("error_anywhere", "fetches_anywhere_ranges", "--s", "ranges")) if anywhere else
                  (("error_layers", "fetches_per_test_layers", "-o", "layers"),
                   ("error_ranges", "fetches_per_test_ranges", "--s", "ranges")))
        for key, fetch, style, reader in series:
            xs = [r[fetch] for r in g]
            ys = [100 * r[key] for r in g]
            positive = [y for y in ys if y > 0]
            if positive:
                floor = min(floor or positive[0], min(positive))
            ax.plot(xs, ys, style, color=cmap(i % 10), ms=4, lw=1, label=f"{shape} ({reader})")
            if reader == "layers":
                for r, x, y in zip(g, xs, ys):
                    ax.annotate(str(r["ldi_size"]), (x, y), xytext=(3, 3), textcoords="offset points", fontsize=6)
    if floor is not None:
        ax.set_yscale("symlog", linthresh=floor)
    ax.set_xlabel("texels read per parity test (solid: R32F layers; dashed: compressed RG32UI)")
    ax.set_ylabel("misclassified points (%)")
    ax.set_title("Volumetric parity test: cost against error, per shape and LDI side (labels)", fontsize=10)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=6, ncols=2, loc="best")
    img = rep.save(fig, "ldi.png")
    return (f"<p>From <code>{rep.rel(path)}</code> (<code>nbsim ldi table1 --out</code>: each shape peeled on Mesa "
            "at each LDI side after viewpoint selection over the grid, cropped and compressed on GL, and its test "
            "points classified by the GLSL parity test with both readers and by the exact reference in double "
            "precision, along each point's texel-centre line; \"anywhere\": as many points uniform in the unit "
            "cube, each anywhere in its texel, against the exact crossings on its own line: the LDI's sampling error, "
            "which the plot shows). Memory in the paper's units: values of 32 bits, M_crop = w_crop x h_crop x d, M_comp = 2 "
            "w_c^2 (both channels counted, as the paper does). Times: wall clock on llvmpipe, glFinish-bounded. The "
            "paper's rows beside ours are the two the issue quotes (its other rows were not at hand). Misclassified: "
            "the parity answer differs from the exact crossing count's parity; points within epsilon of a surface "
            "are counted apart. Rows where the two readers disagree, or GL and the model do, are red.</p>" + tab +
            "<p><b>What it shows</b> (computed from the table):</p><ul>" +
            "".join(f"<li>{html.escape(s)}</li>" for s in reading) + "</ul>" +
            rep.figure(img, "Misclassification (of the uniform points anywhere in their texel when the rows have "
                        "them, else of the test points) against texels read per test, per shape and reader; the labels "
                        "are the LDI sides. Read off: how fast the error falls with resolution and what the "
                        "compressed reader saves per test."))
