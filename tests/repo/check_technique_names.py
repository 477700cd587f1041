#!/usr/bin/env python3
"""Shared code names no technique: a ratchet on the way there.

The shared folders (the replay's top level, the command line, benches, sweeps, the results
declarations, the report, the trace format's core and the capture's core) should not name a
technique (particles, shadows, LDIs, relief, occlusion culling); a technique's code lives in its
own folders. Today they still do. technique_names_baseline.json holds, per shared file, how many
mentions it has; this check fails when a file has more than its baseline (a new mention), when a
shared file that is not in the baseline names a technique, and when a file has fewer (the baseline
must follow the progress down: run this script with --update and commit the baseline).

Usage: check_technique_names.py ROOT [--update]
"""
import json
import pathlib
import re
import sys

root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 and not sys.argv[1].startswith("--") else ".")
update = "--update" in sys.argv[1:]
baseline_path = pathlib.Path(__file__).with_name("technique_names_baseline.json")

# Shared folders: every file below them, except the technique folders named in TECHNIQUE_DIRS.
SHARED = ["pipeline/sim", "pipeline/cli", "pipeline/bench", "pipeline/explore", "pipeline/techniques",
          "analysis", "traces/format", "traces/capture"]
TECHNIQUE_DIRS = {"occlusion", "particles", "shadows", "ldi", "relief"}
SUFFIXES = {".h", ".cpp", ".py"}
# "ldi" only at the start of a word or identifier part (LdiUnit, model::ldi, ldi_table), not in "building".
MENTION = re.compile(r"particle|shadow|relief|occlusion|(?<![a-z])ldi", re.IGNORECASE)


def counts():
    found = {}
    for top in SHARED:
        for path in sorted((root / top).rglob("*")):
            if path.suffix not in SUFFIXES or not path.is_file():
                continue
            rel = path.relative_to(root)
            if any(part in TECHNIQUE_DIRS for part in rel.parts[len(pathlib.Path(top).parts):-1]):
                continue
            n = len(MENTION.findall(path.read_text(errors="replace")))
            if n:
                found[rel.as_posix()] = n
    return found


now = counts()
if update:
    baseline_path.write_text(json.dumps(dict(sorted(now.items())), indent=1) + "\n")
    print(f"{baseline_path.name}: {sum(now.values())} mentions in {len(now)} shared files")
    sys.exit(0)

baseline = json.loads(baseline_path.read_text())
offences = []
for name, n in sorted(now.items()):
    was = baseline.get(name, 0)
    if n > was:
        offences.append(f"{name}: names a technique {n} times, {was} in the baseline: "
                        "a technique's code goes into its own folder, registered in one list")
    elif n < was:
        offences.append(f"{name}: {n} mentions, {was} in the baseline: lower the baseline "
                        f"(python3 {pathlib.Path(__file__).name} ROOT --update)")
for name, was in sorted(baseline.items()):
    if name not in now:
        offences.append(f"{name}: no mentions left (or gone), {was} in the baseline: lower the baseline "
                        f"(python3 {pathlib.Path(__file__).name} ROOT --update)")
for o in offences:
    print(o)
print(f"shared code names a technique {sum(now.values())} times in {len(now)} files (goal: only the registration list)")
sys.exit(1 if offences else 0)
