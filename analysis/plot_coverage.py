#!/usr/bin/python3
"""Figure 4 of Décoret 2005 from `nbsim nbuffer coverage` output: the extra pixels each covering
(the paper's five cases, the corner squares, one square, ...) reads, for every box size, as
labelled false-colour maps side by side, and the share of each of the paper's five cases.

Usage: /usr/bin/python3 analysis/plot_coverage.py COVERAGE.csv OUT.png
Reads only the CSV (columns w,h,area,case and, per covering V, V_level,V_lookups,V_extra_px).
analysis/report.py imports load, summary, case_shares and plot.
"""
import argparse
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import LogNorm  # noqa: E402

# What each covering is, for titles (a covering the CSV has and this table lacks gets its name).
TITLES = {
    "paper": "the paper's five cases (at most 4 lookups)",
    "corners": "corner squares, 2^floor(log2 max) (at most 4)",
    "one": "one square (1 lookup)",
    "rect": "rectangle levels, every one (exact, at most 4)",
    "rect_aspect1": "rectangle levels, sides at most 2x apart",
}
CASES = ["four_quadrants", "two_side_by_side", "two_stacked", "four_in_a_row", "four_in_a_column"]


def load(path):
    """(W, H, maps, lookups, cases): per covering name (CSV order), extra pixels read / box area
    and lookups as H x W grids indexed [h-1, w-1]; cases: the case name of each box, the same grid."""
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        rows = list(reader)
        fields = reader.fieldnames or []
    if not rows:
        raise ValueError(f"{path}: no rows")
    missing = [c for c in ("w", "h", "area", "case") if c not in fields]
    names = [c[: -len("_extra_px")] for c in fields if c.endswith("_extra_px")]
    if not names:
        missing.append("<covering>_extra_px")
    if missing:
        raise ValueError(f"{path}: no column {', '.join(missing)}")
    w = np.array([int(r["w"]) for r in rows])
    h = np.array([int(r["h"]) for r in rows])
    if w.min() < 1 or h.min() < 1:
        raise ValueError(f"{path}: box sides must be at least 1")
    area = np.array([int(r["area"]) for r in rows], dtype=float)
    W, H = int(w.max()), int(h.max())

    def grid(v, fill=np.nan, dtype=float):
        g = np.full((H, W), fill, dtype=dtype)
        g[h - 1, w - 1] = v
        return g

    maps, lookups = {}, {}
    for n in names:
        maps[n] = grid(np.array([int(r[f"{n}_extra_px"]) for r in rows], dtype=float) / area)
        if f"{n}_lookups" in fields:
            lookups[n] = grid(np.array([int(r[f"{n}_lookups"]) for r in rows], dtype=float))
    cases = grid(np.array([r["case"] for r in rows], dtype=object), fill="", dtype=object)
    return W, H, maps, lookups, cases


def summary(maps, lookups=None):
    """Per covering: mean and worst extra area (fractions of the box), the share of exact sizes and
    the mean lookups."""
    out = {}
    for n, g in maps.items():
        sizes = int(np.count_nonzero(~np.isnan(g)))
        out[n] = {"mean_extra": float(np.nanmean(g)), "worst_extra": float(np.nanmax(g)),
                  "exact_fraction": float(np.count_nonzero(g == 0) / sizes), "sizes": sizes,
                  "mean_lookups": float(np.nanmean(lookups[n])) if lookups and n in lookups else None}
    return out


def case_shares(maps, cases):
    """Per case of Fig. 3: its share of box sizes and each covering's mean extra area in it."""
    total = int(np.count_nonzero(cases != ""))
    out = []
    for c in CASES:
        mask = cases == c
        k = int(np.count_nonzero(mask))
        out.append({"case": c, "share": k / total if total else 0.0,
                    "extra": {n: float(np.nanmean(g[mask])) if k else 0.0 for n, g in maps.items()}})
    return out


def plot(W, H, maps, out):
    """The maps side by side, one colour scale (log), written to out (PNG)."""
    floor = 1e-3  # exact coverings (0) are drawn at the floor of the log scale
    vmax = max(float(np.nanmax(g)) for g in maps.values())
    vmax = max(vmax, 10 * floor)
    n = len(maps)
    cols = min(n, 3)
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(5.2 * cols + 1, 5.0 * rows + 0.6), constrained_layout=True, squeeze=False)
    for ax in axes.flat[n:]:
        ax.axis("off")
    im = None
    for ax, (name, g) in zip(axes.flat, maps.items()):
        im = ax.imshow(np.maximum(g, floor), origin="lower", extent=(0.5, W + 0.5, 0.5, H + 0.5),
                       norm=LogNorm(vmin=floor, vmax=vmax), cmap="viridis", interpolation="nearest")
        ax.set_title(f"{name}: {TITLES.get(name, name)}\nmean extra {100 * np.nanmean(g):.1f}% of the box", fontsize=10)
        ax.set_xlabel("box width w (pixels)")
        ax.set_ylabel("box height h (pixels)")
    cb = fig.colorbar(im, ax=axes.ravel().tolist(), shrink=0.9)
    cb.set_label(f"extra pixels read / box area (exact = {floor:g})")
    fig.suptitle("N-buffer covering tightness (Décoret 2005, Fig. 4)")
    fig.savefig(out, dpi=110)
    plt.close(fig)


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("csv")
    ap.add_argument("out")
    a = ap.parse_args(argv)
    try:
        W, H, maps, lookups, cases = load(a.csv)
    except (OSError, KeyError, ValueError, UnicodeDecodeError, csv.Error) as e:
        print(f"plot_coverage: cannot read {a.csv}: {e}", file=sys.stderr)
        return 2
    plot(W, H, maps, a.out)
    for name, s in summary(maps, lookups).items():
        print(f"{name}: mean extra {100 * s['mean_extra']:.1f}% of the box, exact for {100 * s['exact_fraction']:.1f}% of sizes")
    print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
