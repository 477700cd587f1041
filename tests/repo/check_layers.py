#!/usr/bin/env python3
"""The layers, lowest first: model/ (the hardware model), io/ (image files, output folders),
traces/ (the trace format, the GL context and the capture renderer), pipeline/ (the command line,
the replay, sweeps, benches). A folder includes only its own layer and the layers below it; model/
never speaks the trace format (its input types are model/scene's)."""
import pathlib
import re
import sys

root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")
include = re.compile(r'^\s*#\s*include\s*[<"]([a-z_]+)/')
# A layer and the top folders its files may not include.
forbidden = {"model": {"io", "traces", "pipeline"}, "io": {"traces", "pipeline"}, "traces": {"pipeline"}}
offences = []
for layer, banned in forbidden.items():
    for path in sorted((root / layer).rglob("*")):
        if path.suffix not in {".h", ".hpp", ".cpp", ".cc", ".inl"}:
            continue
        for number, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
            m = include.match(line)
            if m and m.group(1) in banned:
                offences.append(f"{path.relative_to(root)}:{number}: {layer}/ includes {m.group(1)}/: {line.strip()}")
for o in offences:
    print(o)
if offences:
    print(f"{len(offences)} include(s) against the layers (model < io < traces < pipeline)")
sys.exit(1 if offences else 0)
