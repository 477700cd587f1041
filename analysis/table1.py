#!/usr/bin/python3
"""Table 1 of Décoret 2005 (N-buffer build cost) beside ours, from `nbsim bench nbuffer` output.

Usage: nbsim bench nbuffer --only build | /usr/bin/python3 analysis/table1.py [--csv OUT.csv]
Reads JSON lines (one object per line), or the JSON array `--json-out FILE` writes, from stdin or
from the file given with --input; objects with "bench" other than "build" are skipped. Prints a
Markdown table. analysis/report.py imports read_rows, table_rows and PAPER.
"""
import argparse
import csv
import json
import sys

# The paper's Table 1: build time in ms on its 2005 GPU, and its number of levels.
PAPER = {"256x256": (8, 2.0), "512x512": (9, 8.0), "640x480": (10, 10.0), "1024x1024": (10, 31.0)}


def _is_build(obj):
    return isinstance(obj, dict) and obj.get("bench", "build") == "build" and "build_ms" in obj


def read_rows(stream):
    """Build results from JSON lines or from one JSON array (nbsim bench --json-out)."""
    text = stream.read()
    if text.lstrip().startswith("["):
        try:
            objs = json.loads(text)
        except json.JSONDecodeError as e:
            raise ValueError(f"not a JSON array: {e}") from e
        if not isinstance(objs, list):
            raise ValueError("not a JSON array")
        return [o for o in objs if _is_build(o)]
    rows = []
    for n, line in enumerate(text.splitlines(), 1):
        line = line.strip()
        if not line:
            continue
        try:
            obj = json.loads(line)
        except json.JSONDecodeError as e:
            raise ValueError(f"line {n} is not JSON: {e}") from e
        if _is_build(obj):
            rows.append(obj)
    return rows


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


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--input", help="JSON-lines file (default: stdin)")
    ap.add_argument("--csv", help="also write the table as CSV")
    a = ap.parse_args(argv)
    try:
        with (open(a.input) if a.input else sys.stdin) as f:
            rows = read_rows(f)
        table = table_rows(rows)
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
    if a.csv:
        with open(a.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(table[0]))
            w.writeheader()
            w.writerows(table)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
