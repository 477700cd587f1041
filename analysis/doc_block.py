"""Generated blocks inside hand-written Markdown: the text between a BEGIN and an END marker line is
written by a script from a command's output, and a test checks that it is current.

    replace_block(text, begin, end, block, path) -> text with the block between the markers
    run(render, begin, end, description): the command line shared by the generators:
        SCRIPT            print the block made from the JSON on stdin
        SCRIPT --update F rewrite F's block
        SCRIPT --check F  exit 1 when F's block is not what the JSON gives (exit 2: bad input)
"""
import argparse
import json
import os
import sys


def replace_block(text, begin, end, block, path):
    if text.count(begin) != 1 or text.count(end) != 1 or text.index(begin) > text.index(end):
        raise ValueError(f"{path} must hold the marker lines once each, in order:\n  {begin}\n  {end}")
    head, rest = text.split(begin, 1)
    _, tail = rest.split(end, 1)
    return head + begin + "\n\n" + block + "\n" + end + tail


def run(render, begin, end, description, regenerate):
    name = os.path.basename(sys.argv[0]).removesuffix(".py")
    parser = argparse.ArgumentParser(description=description)
    mode = parser.add_mutually_exclusive_group()
    mode.add_argument("--update", metavar="FILE", help="rewrite FILE's generated block")
    mode.add_argument("--check", metavar="FILE", help="exit 1 when FILE's generated block is not current")
    args = parser.parse_args()
    try:
        block = render(json.load(sys.stdin))
        if not args.update and not args.check:
            sys.stdout.write(block)
            return 0
        path = args.update or args.check
        with open(path, encoding="utf-8") as f:
            text = f.read()
        new = replace_block(text, begin, end, block, path)
    except (json.JSONDecodeError, ValueError, KeyError, TypeError, OSError) as e:
        print(f"{name}: {e}", file=sys.stderr)
        return 2
    if args.check:
        if new != text:
            print(f"{name}: the generated block in {path} is stale; regenerate it with\n  {regenerate} --update {path}",
                  file=sys.stderr)
            return 1
        return 0
    with open(path, "w", encoding="utf-8") as f:
        f.write(new)
    return 0
