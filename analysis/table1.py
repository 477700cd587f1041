#!/usr/bin/python3
"""Table 1 of Décoret 2005 (N-buffer build cost) beside ours, from `nbsim bench nbuffer` output.

Usage: nbsim bench nbuffer --only build[,update] | /usr/bin/python3 analysis/table1.py [--csv OUT.csv]
Reads JSON lines (one object per line), or the JSON array `--json-out FILE` writes, from stdin or
from the file given with --input. Prints a Markdown table of the "build" objects and, when the
input has "update" objects (incremental updates against a full rebuild), a second one of those;
other objects are skipped. analysis/report.py imports read_rows, read_update_rows, table_rows,
update_table_rows and PAPER.
"""
import argparse
import csv
import io
import json
import sys

# The paper's Table 1: build time in ms on its 2005 GPU, and its number of levels.
PAPER = {"256x256": (8, 2.0), "512x512": (9, 8.0), "640x480": (10, 10.0), "1024x1024": (10, 31.0)}


def _is_build(obj):
    return isinstance(obj, dict) and obj.get("bench", "build") == "build" and "build_ms" in obj


def _is_update(obj):
    return isinstance(obj, dict) and obj.get("bench") == "update" and "update_ms" in obj


def _objects(text):
    """Every object of JSON lines or of one JSON array (nbsim bench --json-out)."""
    if text.lstrip().startswith("["):
        try:
            objs = json.loads(text)
        except json.JSONDecodeError as e:
            raise ValueError(f"not a JSON array: {e}") from e
        if not isinstance(objs, list):
            raise ValueError("not a JSON array")
        return objs
    objs = []
    for n, line in enumerate(text.splitlines(), 1):
        line = line.strip()
        if not line:
            continue
        try:
            objs.append(json.loads(line))
        except json.JSONDecodeError as e:
            raise ValueError(f"line {n} is not JSON: {e}") from e
    return objs


def read_rows(stream):
    """Build results from JSON lines or from one JSON array (nbsim bench --json-out)."""
    return [o for o in _objects(stream.read()) if _is_build(o)]


def read_update_rows(stream):
    """Update results (bench "update") from JSON lines or from one JSON array."""
    return [o for o in _objects(stream.read()) if _is_update(o)]


def table_rows(rows):
    """One dict per size: ours beside the paper's levels and ms (None where the paper has no row)."""
    table = []
    for r in rows:
        try:
            paper_levels, paper_ms = PAPER.get(r["size"], (None, None))
            table.append({
                "size": r["size"], "levels": r["levels"], "paper_levels": paper_levels, "paper_ms_2005_gpu": paper_ms,
                "build_ms": float(r["build_ms"]), "copy_ms": float(r["copy_ms"]), "ratio": float(r["ratio"]),
            })
        except (KeyError, TypeError, ValueError) as e:
            raise ValueError(f"build result without a usable {e}: {r}") from e
    return table


def update_table_rows(rows):
    """One dict per dirty-rectangle size: update time, texels recomputed and per second, against a rebuild.
    texels_per_s is recomputed from the other fields when the input predates it."""
    table = []
    for r in rows:
        try:
            update_ms, texels = float(r["update_ms"]), int(r["texels_recomputed"])
            per_s = r.get("texels_per_s")
            table.append({
                "size": r["size"], "dirty": r["dirty"], "update_ms": update_ms, "texels_recomputed": texels,
                "texels_per_s": float(per_s) if per_s is not None else (texels / (update_ms * 1e-3) if update_ms > 0 else None),
                "rebuild_ms": float(r["rebuild_ms"]), "ratio": float(r["ratio"]),
            })
        except (KeyError, TypeError, ValueError) as e:
            raise ValueError(f"update result without a usable {e}: {r}") from e
    return table


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--input", help="JSON-lines file (default: stdin)")
    ap.add_argument("--csv", help="also write the table as CSV")
    a = ap.parse_args(argv)
    try:
        with (open(a.input) if a.input else sys.stdin) as f:
            text = f.read()
        rows = read_rows(io.StringIO(text))
        table = table_rows(rows)
        updates = update_table_rows(read_update_rows(io.StringIO(text)))
    except (OSError, ValueError) as e:
        print(f"table1: {e}", file=sys.stderr)
        return 2
    if not rows:
        print("table1: no build results in the input", file=sys.stderr)
        return 2
    print("| size | levels (paper) | paper, 2005 GPU (ms) | nbsim core, 1 CPU core (ms) | level-by-level copy (ms) | build / copy |")
    print("|---|---|---|---|---|---|")
    for t in table:
        paper = f"{t['paper_ms_2005_gpu']:.0f}" if t["paper_ms_2005_gpu"] is not None else "-"
        print(f"| {t['size']} | {t['levels']} ({t['paper_levels'] or '-'}) | {paper} | {t['build_ms']:.2f} | "
              f"{t['copy_ms']:.2f} | {t['ratio']:.2f} |")
    if updates:
        print()
        print("| size | dirty rectangle | update (ms) | texels recomputed | texels/s | full rebuild (ms) | update / rebuild |")
        print("|---|---|---|---|---|---|---|")
        for u in updates:
            per_s = f"{u['texels_per_s'] / 1e6:.0f} M" if u["texels_per_s"] is not None else "-"
            print(f"| {u['size']} | {u['dirty']} | {u['update_ms']:.4g} | {u['texels_recomputed']} | {per_s} | "
                  f"{u['rebuild_ms']:.2f} | {u['ratio']:.3g} |")
    if a.csv:
        with open(a.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(table[0]))
            w.writeheader()
            w.writerows(table)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
