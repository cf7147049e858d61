#!/usr/bin/env python3
"""Check that every relative link of README.md, docs/*.md and docs/reliability/*.md resolves.

The generated reports under docs/study-data/ and docs/fit-data/ are not checked (their pictures
are written beside them by the commands that make them).

A link resolves when the file (or directory) it names exists, relative to the Markdown file, and,
if it has a #fragment into a Markdown file, that file has a heading whose GitHub anchor is the
fragment. Links to web pages (scheme:) and mail addresses are not checked. Code spans and fenced
code blocks are skipped, so that examples of Markdown are not taken for links.

Usage: check-doc-links.py [ROOT]   (ROOT: the repository, by default this script's parent's parent)
Prints one line per broken link (file:line: target: why) and exits 1 if there is any.
"""

import re
import sys
import unicodedata
from pathlib import Path

LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
REFERENCE = re.compile(r"^\s{0,3}\[[^\]]+\]:\s*<?(\S+?)>?(?:\s+.*)?$")
FENCE = re.compile(r"^\s{0,3}(```|~~~)")
CODE_SPAN = re.compile(r"(`+)(?:(?!\1).)+?\1")
HEADING = re.compile(r"^\s{0,3}(#{1,6})\s+(.*?)\s*#*\s*$")


def github_anchor(text):
    """The anchor GitHub gives a heading: lower case, punctuation dropped, spaces as hyphens."""
    text = re.sub(r"<[^>]+>", "", text)  # inline HTML
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", text)  # links keep their text
    text = text.replace("`", "").lower()
    kept = []
    for ch in text:
        category = unicodedata.category(ch)
        if ch in "-_ " or category[0] in "LN" or category == "Mn":
            kept.append(ch)
    return "".join(kept).replace(" ", "-")


def lines_outside_code(path, keep_code_spans=False):
    """(line number, text) of each line outside fenced code, code spans blanked unless kept."""
    inside = None
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        fence = FENCE.match(line)
        if fence:
            if inside is None:
                inside = fence.group(1)
            elif fence.group(1) == inside:
                inside = None
            continue
        if inside is None:
            yield number, line if keep_code_spans else CODE_SPAN.sub("", line)


_anchors = {}


def anchors_of(path):
    if path not in _anchors:
        seen = {}
        result = set()
        for _, line in lines_outside_code(path, keep_code_spans=True):
            heading = HEADING.match(line)
            if not heading:
                continue
            anchor = github_anchor(heading.group(2))
            count = seen.get(anchor, 0)
            seen[anchor] = count + 1
            result.add(anchor if count == 0 else f"{anchor}-{count}")
        _anchors[path] = result
    return _anchors[path]


def problem(source, target):
    """Why target (a link in source) does not resolve, or None."""
    if re.match(r"^[a-zA-Z][a-zA-Z0-9+.-]*:", target) or target.startswith("//"):
        return None  # a web page or a mail address
    file_part, _, fragment = target.partition("#")
    resolved = (source.parent / file_part).resolve() if file_part else source
    if not resolved.exists():
        return "no such file"
    if fragment and resolved.suffix == ".md" and resolved.is_file():
        if fragment.lower() not in anchors_of(resolved):
            return f"no heading with anchor #{fragment} in {resolved.name}"
    return None


def main():
    root = Path(sys.argv[1]).resolve() if len(sys.argv) > 1 else Path(__file__).resolve().parents[1]
    files = [root / "README.md"] + sorted((root / "docs").glob("*.md"))
    files += sorted((root / "docs" / "reliability").glob("*.md"))
    broken = 0
    checked = 0
    for source in files:
        if not source.is_file():
            print(f"{source}: missing", file=sys.stderr)
            broken += 1
            continue
        for number, line in lines_outside_code(source):
            targets = [m.group(1) for m in LINK.finditer(line)]
            reference = REFERENCE.match(line)
            if reference:
                targets.append(reference.group(1))
            for target in targets:
                checked += 1
                why = problem(source, target)
                if why:
                    broken += 1
                    print(f"{source.relative_to(root)}:{number}: {target}: {why}")
    print(f"{checked} relative links checked in {len(files)} files, {broken} broken")
    return 1 if broken else 0


if __name__ == "__main__":
    sys.exit(main())
