#!/usr/bin/python3
"""Figure 4 of Décoret 2005 from `nbsim nbuffer coverage` output: extra pixels read by one square
and by four squares, for every box size, as a labelled false-colour plot.

Usage: /usr/bin/python3 analysis/plot_coverage.py COVERAGE.csv OUT.png
Reads only the CSV (columns w,h,area,one_extra_px,four_extra_px, ...). analysis/report.py imports
load, summary and plot.
"""
import argparse
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import LogNorm  # noqa: E402


def load(path):
    """(W, H, one, four): extra pixels read / box area, as H x W grids indexed [h-1, w-1]."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        raise ValueError(f"{path}: no rows")
    missing = [c for c in ("w", "h", "area", "one_extra_px", "four_extra_px") if c not in rows[0]]
    if missing:
        raise ValueError(f"{path}: no column {', '.join(missing)}")
    w = np.array([int(r["w"]) for r in rows])
    h = np.array([int(r["h"]) for r in rows])
    area = np.array([int(r["area"]) for r in rows], dtype=float)
    one = np.array([int(r["one_extra_px"]) for r in rows], dtype=float)
    four = np.array([int(r["four_extra_px"]) for r in rows], dtype=float)
    W, H = w.max(), h.max()

    def grid(v):
        g = np.full((H, W), np.nan)
        g[h - 1, w - 1] = v
        return g

    return W, H, grid(one / area), grid(four / area)


def summary(one, four):
    """Mean and worst extra area of each covering (as a fraction of the box), and where four is exact."""
    return {
        "one_mean_extra": float(np.nanmean(one)), "one_worst_extra": float(np.nanmax(one)),
        "four_mean_extra": float(np.nanmean(four)), "four_worst_extra": float(np.nanmax(four)),
        "four_exact_fraction": float(np.count_nonzero(four == 0) / np.count_nonzero(~np.isnan(four))),
        "sizes": int(np.count_nonzero(~np.isnan(four))),
    }


def plot(W, H, one, four, out):
    """The two maps side by side, log colour scale, written to out (PNG)."""
    # Relative extra area; exact coverings (0) are drawn at the floor of the log scale.
    floor = 1e-3
    vmax = max(np.nanmax(one), np.nanmax(four))
    fig, axes = plt.subplots(1, 2, figsize=(11, 5.8), constrained_layout=True)
    for ax, g, title in ((axes[0], one, "one square (1 lookup)"), (axes[1], four, "four squares (at most 4 lookups)")):
        im = ax.imshow(np.maximum(g, floor), origin="lower", extent=(0.5, W + 0.5, 0.5, H + 0.5),
                       norm=LogNorm(vmin=floor, vmax=vmax), cmap="viridis", interpolation="nearest")
        ax.set_title(f"{title}\nmean extra {100 * np.nanmean(g):.0f}% of the box")
        ax.set_xlabel("box width w (pixels)")
        ax.set_ylabel("box height h (pixels)")
    cb = fig.colorbar(im, ax=axes, shrink=0.9)
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
        W, H, one, four = load(a.csv)
    except (OSError, KeyError, ValueError) as e:
        print(f"plot_coverage: cannot read {a.csv}: {e}", file=sys.stderr)
        return 2
    plot(W, H, one, four, a.out)
    print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
