#!/usr/bin/python3
"""Writes, or checks, the command reference generated from the commands' own definitions.

The tool prints it (`halfback --help-reference=man|markdown`, from the CLI11 apps every command
registers; src/cli/reference.cpp):
  docs/halfback.1  the whole man page;
  docs/cli.md      the blocks between "<!-- BEGIN generated: halfback NAME -->" and
                   "<!-- END generated: halfback NAME -->", one per command and subcommand; the
                   prose around them is written by hand and left as it is.

  scripts/cli_reference.py --halfback build/release/src/cli/halfback          # rewrite both
  scripts/cli_reference.py --halfback build/release/src/cli/halfback --check  # exit 1 on drift

`cmake --build --preset release --target cli_reference` runs the first; the test
cli_reference_matches_docs the second. A command that has no block in docs/cli.md yet gets one
appended at the end of the file (and --check fails until it is there); a block of a command that
no longer exists is an error: remove it by hand.
"""

import argparse
import difflib
import os
import re
import subprocess
import sys

BLOCK = re.compile(r"<!-- BEGIN generated: (?P<name>[^>]*?) -->\n.*?<!-- END generated: (?P=name) -->\n",
                   re.S)


def generated(halfback, fmt):
    run = subprocess.run([halfback, "--help-reference=" + fmt], capture_output=True, text=True,
                         check=False)
    if run.returncode != 0:
        sys.exit(f"cli_reference: '{halfback} --help-reference={fmt}' failed "
                 f"(status {run.returncode}): {run.stderr.strip()}")
    return run.stdout


def spliced(markdown, generated_markdown, path):
    """markdown with each generated block replaced by its new text; new blocks appended."""
    blocks = {m.group("name"): m.group(0) for m in BLOCK.finditer(generated_markdown)}
    if not blocks:
        sys.exit("cli_reference: the tool's markdown reference holds no block")
    found = []

    def replace(m):
        name = m.group("name")
        if name not in blocks:
            sys.exit(f"cli_reference: {path} has a block for '{name}', which is no command any "
                     "more: remove it (or rename it to the command's new name)")
        found.append(name)
        return blocks[name]

    text = BLOCK.sub(replace, markdown)
    missing = [name for name in blocks if name not in found]
    if missing:
        text = text.rstrip("\n") + "\n\n" + "\n".join(blocks[name] for name in missing)
    return text, missing


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--halfback", required=True, help="the built tool")
    parser.add_argument("--docs", default=os.path.join(os.path.dirname(__file__), "..", "docs"),
                        help="the docs folder (default: the tree's)")
    parser.add_argument("--check", action="store_true",
                        help="write nothing; exit 1 when a file differs from the generated text")
    args = parser.parse_args()

    man_path = os.path.join(args.docs, "halfback.1")
    md_path = os.path.join(args.docs, "cli.md")
    with open(md_path, encoding="utf-8") as f:
        markdown = f.read()
    with open(man_path, encoding="utf-8") as f:
        man = f.read()
    new_man = generated(args.halfback, "man")
    new_markdown, missing = spliced(markdown, generated(args.halfback, "markdown"), md_path)

    drift = []
    for path, old, new in ((man_path, man, new_man), (md_path, markdown, new_markdown)):
        if old == new:
            continue
        drift.append(path)
        if args.check:
            diff = list(difflib.unified_diff(old.splitlines(), new.splitlines(), path,
                                             path + " (generated)", lineterm="", n=1))
            print("\n".join(diff[:60]) + ("\n..." if len(diff) > 60 else ""))
        else:
            tmp = path + ".tmp"
            with open(tmp, "w", encoding="utf-8") as f:
                f.write(new)
            os.replace(tmp, path)
            print(f"cli_reference: {path} rewritten")
    for name in missing:
        print(f"cli_reference: {md_path}: no block for '{name}'"
              + (" (appended at the end: move it to its section)" if not args.check else ""))
    if args.check and drift:
        print("cli_reference: the command reference differs from the commands' definitions in "
              + ", ".join(drift) + "; regenerate it: cmake --build --preset release --target "
              "cli_reference")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
