#!/usr/bin/env python3
"""The tests mirror the sources: every source folder (model/, io/, traces/, pipeline/ or a folder
below them that directly holds .cpp or .h files) has its test folder tests/<same path>/, and every
test folder (a folder under tests/ that directly holds .cpp files) is tests/<a source folder>/. Except:
the helper folders below (shared helpers, fuzz targets, golden outputs, sanitizer files, the
analysis scripts' tests, these checks) and any data/, fixture/ or corpus/ folder of test inputs;
and the few source folders listed below whose code other tests cover, each with its reason."""
import pathlib
import sys

root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")
# The source trees, lowest layer first.
source_tops = ["model", "io", "traces", "pipeline"]
# Folders under tests/ that mirror no source folder, and why.
test_helpers = {
    "tests/common": "helpers shared by the suites (the brute-force reference, running nbsim)",
    "tests/fuzz": "the fuzz targets (scripts/fuzz), with their seeds and dictionaries",
    "tests/golden": "the golden outputs (scripts/golden)",
    "tests/sanitize": "the sanitizer build's suppressions",
    "tests/analysis": "analysis/'s Python tests (analysis/ is Python, not a source folder here)",
    "tests/repo": "these checks of the repository itself",
}
# Test inputs: any folder of these names (and everything below it) under tests/.
data_names = {"data", "fixture", "corpus"}
# Source folders without a test folder of their own, and why (keep this short and honest).
untested = {
    "model/depth": "the depth unit's SystemC wrapper needs a raster unit in front of it; its cores "
    "(model/raster/depth_test.h, stencil_test.h) are tests/model/raster's, and every `nbsim compare` "
    "(tests/pipeline/sim, tests/model/<technique>) checks its counters and depth against GL's",
    "model/occlusion": "holds only roles.h, an empty list (occlusion culling draws with the core roles); "
    "tests/model/scene's TechniqueRolesTest checks the joined table",
}
code = {".cpp", ".h"}


def folders_with(top: pathlib.Path, suffixes: set) -> set:
    """Folders under `top` (relative to root, as strings) that directly hold a file with one of `suffixes`."""
    if not top.is_dir():
        return set()
    return {p.parent.relative_to(root).as_posix() for p in top.rglob("*") if p.is_file() and p.suffix in suffixes}


def is_helper(test_folder: str) -> bool:
    parts = pathlib.PurePosixPath(test_folder).parts
    if any(part in data_names for part in parts[1:]):
        return True
    return any(test_folder == h or test_folder.startswith(h + "/") for h in test_helpers)


sources = set().union(*(folders_with(root / top, code) for top in source_tops))
tests = {t for t in folders_with(root / "tests", {".cpp"}) if not is_helper(t)}

offences = []
for s in sorted(sources):
    if s in untested:
        continue
    if f"tests/{s}" not in tests:
        offences.append(f"{s}/: a source folder without tests (tests/{s}/ with a test .cpp), nor in the allow-list")
for t in sorted(tests):
    mirrored = t.removeprefix("tests/")
    if mirrored not in sources:
        offences.append(f"{t}/: a test folder that mirrors no source folder ({mirrored}/ holds no .cpp or .h)")
for s in sorted(untested):
    if s not in sources:
        offences.append(f"{s}: allow-listed as untested, but not a source folder: drop it from the list")
    elif f"tests/{s}" in tests:
        offences.append(f"{s}: allow-listed as untested, but tests/{s}/ exists: drop it from the list")
for o in offences:
    print(o)
if offences:
    print(f"{len(offences)} offence(s) against the tests' layout (tests/<path>/ mirrors <path>/)")
sys.exit(1 if offences else 0)
