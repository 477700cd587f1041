#!/usr/bin/python3
"""Table 1 of Décoret 2005 (N-buffer build cost) beside ours, from `nbsim bench nbuffer` output.

Usage: nbsim bench nbuffer --only build | /usr/bin/python3 analysis/table1.py [--csv OUT.csv]
Reads JSON lines (one object per line; lines with "bench" other than "build" are skipped) from
stdin or from the file given with --input. Prints a Markdown table.
"""
import argparse
import csv
import json
import sys

# The paper's Table 1: build time in ms on its 2005 GPU, and its number of levels.
PAPER = {"256x256": (8, 2.0), "512x512": (9, 8.0), "640x480": (10, 10.0), "1024x1024": (10, 31.0)}


def read_rows(stream):
    rows = []
    for n, line in enumerate(stream, 1):
        line = line.strip()
        if not line:
            continue
        try:
            obj = json.loads(line)
        except json.JSONDecodeError as e:
            raise ValueError(f"line {n} is not JSON: {e}") from e
        if obj.get("bench", "build") == "build" and "build_ms" in obj:
            rows.append(obj)
    return rows


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--input", help="JSON-lines file (default: stdin)")
    ap.add_argument("--csv", help="also write the table as CSV")
    a = ap.parse_args(argv)
    try:
        with (open(a.input) if a.input else sys.stdin) as f:
            rows = read_rows(f)
    except (OSError, ValueError) as e:
        print(f"table1: {e}", file=sys.stderr)
        return 2
    if not rows:
        print("table1: no build results in the input", file=sys.stderr)
        return 2
    table = []
    for r in rows:
        paper_levels, paper_ms = PAPER.get(r["size"], (None, None))
        table.append({
            "size": r["size"], "levels": r["levels"], "paper_levels": paper_levels, "paper_ms_2005_gpu": paper_ms,
            "build_ms": r["build_ms"], "copy_ms": r["copy_ms"], "ratio": r["ratio"],
        })
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
