"""Normalizes nbsim's outputs for scripts/golden (stdin -> stdout).
  json     drops every key whose name contains "host" (host_seconds, cycles_per_host_second, ...)
  csv      drops every such column
  info     `nbsim trace info --json` without what differs between two captures of the same frames:
           the file's name and layout (bytes, chunks, offsets, format version), the command line
           and GL's host time (gl_ms)
  command  the arguments of the trace's recorded command line, one a line, without the program
           name and its -o/--out FILE"""
import csv
import json
import shlex
import sys


def strip(value):
    if isinstance(value, dict):
        return {k: strip(v) for k, v in value.items() if "host" not in k}
    if isinstance(value, list):
        return [strip(v) for v in value]
    return value


def main():
    kind = sys.argv[1] if len(sys.argv) > 1 else ""
    if kind == "json":
        json.dump(strip(json.load(sys.stdin)), sys.stdout, indent=1)
        sys.stdout.write("\n")
    elif kind == "csv":
        rows = list(csv.reader(sys.stdin))
        keep = [i for i, name in enumerate(rows[0]) if "host" not in name] if rows else []
        writer = csv.writer(sys.stdout, lineterminator="\n")
        for row in rows:
            writer.writerow([row[i] for i in keep])
    elif kind == "info":
        info = json.load(sys.stdin)
        keep = {"properties", "scene", "frames", "totals"}
        info = {k: v for k, v in info.items() if k in keep}
        info["properties"] = {k: v for k, v in info["properties"].items() if k != "command_line"}
        info["frames"] = [{k: v for k, v in f.items() if k not in ("offset", "gl_ms")} for f in info["frames"]]
        json.dump(info, sys.stdout, indent=1)
        sys.stdout.write("\n")
    elif kind == "command":
        args = shlex.split(json.load(sys.stdin)["properties"]["command_line"])[1:]
        out = []
        skip = False
        for a in args:
            if skip:
                skip = False
            elif a in ("-o", "--out"):
                skip = True
            elif not a.startswith(("-o=", "--out=")):
                out.append(a)
        sys.stdout.write("".join(a + "\n" for a in out))
    else:
        sys.exit("usage: golden_normalize.py json|csv|info|command < IN > OUT")


if __name__ == "__main__":
    main()
