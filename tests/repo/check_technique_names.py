#!/usr/bin/env python3
"""Shared code names no technique.

The shared folders (the replay's top level, the command line, benches, sweeps, the results
declarations, the report, the trace format's core and the capture's core), the build files of
the layers and of the tests do not name a technique (particles, shadows, LDIs, relief, occlusion culling, apps): a
technique's code lives in its own folders (a folder named after it, below any of them), and the one
registration list names them all:

  cmake/NbsimTechniques.cmake   NBSIM_TECHNIQUES, expanded in C++ as NBSIM_EACH_TECHNIQUE(X)

Each layer's table expands that list (traces/format/technique_chunks.cpp, traces/capture/
techniques.cpp, pipeline/sim/programs.cpp, pipeline/techniques/results.cpp, pipeline/cli/main.cpp,
model/scene/technique_roles.h) and each CMakeLists.txt loops over it; the report's sections need
no list: analysis/report.py discovers analysis/techniques/<name>/.
Exits 1 naming every other shared file that names a technique, with the line.

Usage: check_technique_names.py ROOT
"""
import pathlib
import re
import sys

root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")

SHARED = ["pipeline/sim", "pipeline/cli", "pipeline/bench", "pipeline/explore", "pipeline/techniques",
          "analysis", "traces/format", "traces/capture"]
# Shared files outside those folders: the layers' build files and the draw roles' table.
SHARED_FILES = ["CMakeLists.txt", "model/CMakeLists.txt", "model/sim/CMakeLists.txt", "traces/CMakeLists.txt",
                "pipeline/CMakeLists.txt", "model/scene/technique_roles.h"]
TECHNIQUE_DIRS = {"occlusion", "particles", "shadows", "ldi", "relief", "apps"}
REGISTRATION = {"cmake/NbsimTechniques.cmake"}
SUFFIXES = {".h", ".cpp", ".py", ".txt", ".cmake"}
# "ldi" only at the start of a word or identifier part (LdiUnit, model::ldi, ldi_table), not in "building".
# "apps" only as a word part of its own (apps_program, model::apps), not in "mapps".
MENTION = re.compile(r"particle|shadow|relief|occlusion|(?<![a-z])ldi|(?<![a-z])apps(?![a-z])", re.IGNORECASE)

offences = []
listed = 0

def shared_files():
    """(path, relative path) of every shared file, the registration list included."""
    for top in SHARED:
        for path in sorted((root / top).rglob("*")):
            if path.suffix not in SUFFIXES or not path.is_file():
                continue
            rel = path.relative_to(root)
            if any(part in TECHNIQUE_DIRS for part in rel.parts[len(pathlib.Path(top).parts):-1]):
                continue
            yield path, rel
    for name in SHARED_FILES + sorted(REGISTRATION):
        if (root / name).is_file():
            yield root / name, pathlib.Path(name)
    # The tests' build files outside the technique folders: a technique's tests join the suites
    # from its own tests/<layer>/<name>/CMakeLists.txt (nbsim_add_technique_tests).
    for path in sorted((root / "tests").rglob("CMakeLists.txt")):
        rel = path.relative_to(root)
        if not any(part in TECHNIQUE_DIRS for part in rel.parts[1:-1]):
            yield path, rel


for path, rel in shared_files():
    lines = path.read_text(errors="replace").splitlines()
    hits = [(i + 1, line.strip()) for i, line in enumerate(lines) if MENTION.search(line)]
    if rel.as_posix() in REGISTRATION:
        listed += len(hits)
        continue
    offences += [f"{rel.as_posix()}:{n}: names a technique: {text[:120]}" for n, text in hits]
missing = [r for r in sorted(REGISTRATION) if not (root / r).is_file()]
for r in missing:
    offences.append(f"{r}: the registration file is gone: move it or update REGISTRATION in this script")
for o in offences:
    print(o)
print(f"shared code: {len(offences)} mentions of a technique outside the registration list "
      f"({listed} lines in {', '.join(sorted(REGISTRATION))})")
sys.exit(1 if offences else 0)
