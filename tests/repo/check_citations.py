#!/usr/bin/env python3
"""Every file a comment or a document cites is in the repository.

Over the tracked sources and documents (.h .cpp .glsl .comp .vert .frag .py .cmake .md,
CMakeLists.txt, scripts/), two kinds of mention are checked: a Markdown document's name
(`FORMAT.md`, `docs/model.md`, a link's `../traces/FORMAT.md#limits`) and a path that starts with a
top-level folder of the repository (`model/nbuffer/covering.h`, `tests/model/cull/`). A mention
resolves when it names a tracked file or folder relative to the repository root or to the citing
file's folder or, for a bare name, a tracked file of that name anywhere. A file that exists in the
working tree but is not added yet counts too, so that work in progress passes (a fresh clone
catches the rest). Any mention of the folder `shared` beside the repository (through `..`) is an
offence: it is outside the repository.

Not checked: URLs; absolute paths (/tmp, /usr); output names that no top-level folder prefixes
(run.json, results.csv, OUT/plot.png); the documents a command writes (GENERATED); a top-level
folder and one word with neither extension nor closing slash ("depth tests/frame" is a unit); and
name patterns: paths with an upper-case word outside a document's own name
(`traces/capture/DIR/NAME.h`). Prints each offence as path:line: message; exits 1 if any."""
import os
import pathlib
import re
import subprocess
import sys

root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve()
this = pathlib.Path(__file__).resolve()

CODE_SUFFIXES = {".h", ".cpp", ".glsl", ".comp", ".vert", ".frag", ".py", ".cmake", ".md"}
# Documents that commands write into their output folders (analysis/report.py: headline.md).
GENERATED = {"headline.md"}


def tracked_files():
    try:
        out = subprocess.run(["git", "-C", str(root), "ls-files", "-z"], capture_output=True, check=True)
        names = [n for n in out.stdout.decode("utf-8", "replace").split("\0") if n]
        if names:
            return names
    except (OSError, subprocess.CalledProcessError):
        pass
    names = []
    for folder, dirs, files in os.walk(root):
        dirs[:] = [d for d in dirs if not d.startswith(".") and not d.startswith("build")]
        for f in files:
            names.append(str((pathlib.Path(folder) / f).relative_to(root)).replace(os.sep, "/"))
    return names


files = tracked_files()
file_set = set(files)
dir_set = set()
for f in files:
    parts = f.split("/")
    for i in range(1, len(parts)):
        dir_set.add("/".join(parts[:i]))
basenames = {f.rsplit("/", 1)[-1] for f in files}
top = sorted({f.split("/", 1)[0] for f in files if "/" in f and not f.startswith(".")})

url = re.compile(r"\b[a-z][a-z0-9+.-]*://\S+")
SHARED = ".." + "/shared"  # spelled in two pieces so that a search for the folder's name skips this file
shared = re.compile(re.escape(SHARED) + r"\b")
# A document's name, possibly with a folder or ../ before it and an anchor after it.
md_name = re.compile(r"(?<![\w./-])((?:\.\.?/)*(?:[\w-]+/)*[\w.-]*\w\.md)(?![\w-])")
# A path starting with a top-level folder; the character after it tells whether it is a prefix (a
# glob or a brace list follows).
tops = "|".join(map(re.escape, top)) or "(?!)"
top_path = re.compile(r"(?<![\w./$-])((?:" + tops + r")/[\w./-]*)([*{<]?)")
caps_word = re.compile(r"(?<![A-Za-z0-9])[A-Z][A-Z0-9]*(?:_[A-Z0-9]+)*(?![a-z])")


def is_name_pattern(path):
    """True when a component other than a document's own name holds an upper-case word (DIR, NAME)."""
    parts = path.split("/")
    for i, part in enumerate(parts):
        if i == len(parts) - 1 and part.endswith(".md"):
            continue
        stem = part.split(".", 1)[0] if i == len(parts) - 1 else part
        if any(len(m.group(0)) >= 2 for m in caps_word.finditer(stem)):
            return True
    return False


def exists(path, prefix=False):
    path = path.rstrip("/")
    if not path:
        return True
    if prefix:
        return any(f.startswith(path) for f in files)
    return path in file_set or path in dir_set or (root / path).exists()


def resolves(mention, citing, prefix=False):
    candidates = [mention]
    here = os.path.dirname(citing)
    if here:
        candidates.append(os.path.normpath(os.path.join(here, mention)).replace(os.sep, "/"))
    if any(not c.startswith("../") and exists(c, prefix) for c in candidates):
        return True
    return "/" not in mention.rstrip("/") and mention in basenames


def scanned(name):
    p = pathlib.PurePosixPath(name)
    return p.suffix in CODE_SUFFIXES or p.name == "CMakeLists.txt" or name.startswith("scripts/")


offences = []
for name in files:
    if not scanned(name):
        continue
    path = root / name
    if path.resolve() == this or not path.is_file():
        continue
    for number, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
        text = url.sub(" ", line)
        if shared.search(text):
            offences.append(f"{name}:{number}: cites {SHARED}, which is outside the repository")
            text = re.sub(re.escape(SHARED) + r"/?\S*", " ", text)
        seen = set()
        for m in md_name.finditer(text):
            mention = m.group(1)
            seen.add(m.start(1))
            if "/" in mention and is_name_pattern(mention) or mention.rsplit("/", 1)[-1] in GENERATED:
                continue
            if not resolves(mention, name):
                offences.append(f"{name}:{number}: cites {mention}, which is not in the repository")
        for m in top_path.finditer(text):
            if m.start(1) in seen:
                continue
            mention = m.group(1).rstrip(".,:;")
            if mention.endswith(".md") or is_name_pattern(mention):
                continue
            rest = mention.split("/", 1)[1]
            if "/" not in rest and "." not in rest and not m.group(2) and not m.group(1).endswith("/"):
                continue  # a unit such as tests/frame, or a folder named in passing
            if not resolves(mention, name, prefix=bool(m.group(2))):
                offences.append(f"{name}:{number}: cites {mention}, which is not in the repository")
for o in offences:
    print(o)
if offences:
    print(f"{len(offences)} citation(s) of files that are not in the repository")
sys.exit(1 if offences else 0)
