#!/usr/bin/python3
"""Markdown tables of the model's configuration keys, one per unit, from `nbsim config --defaults --json`.

Usage: nbsim config --defaults --json | /usr/bin/python3 analysis/config_table.py
"""
import json
import sys


def main():
    try:
        keys = json.load(sys.stdin)
    except json.JSONDecodeError as e:
        print(f"config_table: input is not JSON: {e}", file=sys.stderr)
        return 2
    units = {}
    for k in keys:
        unit, field = k["key"].split(".", 1)
        units.setdefault(unit, []).append((field, k))
    for unit, fields in units.items():
        print(f"**{unit}**\n")
        print("| key | default | unit | limits | meaning |")
        print("|---|---|---|---|---|")
        for field, k in fields:
            print(f"| `{unit}.{field}` | {json.dumps(k['default'])} | {k['unit']} | {k['limits']} | {k['description']} |")
        print()
    return 0


if __name__ == "__main__":
    sys.exit(main())
