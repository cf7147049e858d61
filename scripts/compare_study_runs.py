#!/usr/bin/env python3
"""Compares two outputs of `halfback study` (e.g. before and after a refactoring) file by file.

    scripts/compare_study_runs.py BEFORE_DIR AFTER_DIR

Every file must be byte-identical, but for what depends on the machine's speed, which is masked
before comparing: the "seconds" of each part's brdf table, the sampling table's time per sample
and the efficiencies that fold it in (ns_per_sample, efficiency_vs_*, pixel_efficiency_*), the
run time in the report's header, the numbers of the report's importance-sampling section, and the
sampling plot (sampling.png/.svg) with report.html's copy of it. Those files are compared masked;
a second run with --no-sampling compares everything but the seconds byte for byte.
Exit status 0 when the outputs agree, 1 otherwise (the differing files are listed).
"""
import csv
import io
import re
import sys
from pathlib import Path

TIMING_COLUMNS = re.compile(r"^(seconds|ns_per_sample|efficiency_vs_.*|pixel_efficiency_.*)$")
UNCOMPARABLE = {"sampling.png", "sampling.svg"}  # drawn from the efficiencies


def mask_csv(text):
    """Masks the timing columns of CSV text (one header, then rows)."""
    rows = list(csv.reader(io.StringIO(text)))
    if not rows:
        return text
    masked = [i for i, name in enumerate(rows[0]) if TIMING_COLUMNS.match(name)]
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(rows[0])
    for row in rows[1:]:
        writer.writerow(["T" if i in masked else cell for i, cell in enumerate(row)])
    return out.getvalue()


def mask_part(text):
    """A part file: sections [NAME] of CSV text, each masked."""
    sections = re.split(r"^(\[[a-z0-9_]+\]\n)", text, flags=re.M)
    return sections[0] + "".join(
        s if s.startswith("[") else mask_csv(s) for s in sections[1:])


def mask_report(text):
    """report.md / report.html: the run time and the sampling section's numbers."""
    text = re.sub(r"\d+(\.\d+)? (s|min|h)\b", "T \\2", text)
    start = text.find("Importance sampling")
    if start < 0:
        return text
    end = text.find("Fitting from measurements", start)
    end = len(text) if end < 0 else end
    section = re.sub(r"data:image/[a-z+]+;base64,[A-Za-z0-9+/=]+", "IMAGE", text[start:end])
    section = re.sub(r"\d+(\.\d+)?(e[-+]?\d+)?", "N", section)
    return text[:start] + section + text[end:]


def normalized(path):
    if path.name in UNCOMPARABLE:
        return None
    data = path.read_bytes()
    if path.suffix == ".part":
        return mask_part(data.decode()).encode()
    if path.name == "sampling.csv":
        return mask_csv(data.decode()).encode()
    if path.name in ("report.md", "report.html"):
        return mask_report(data.decode()).encode()
    return data


def main(before, after):
    names = sorted({p.relative_to(before) for p in before.rglob("*") if p.is_file()} |
                   {p.relative_to(after) for p in after.rglob("*") if p.is_file()})
    differ = []
    for name in names:
        a, b = before / name, after / name
        if not a.exists() or not b.exists():
            differ.append(f"{name}: only in {'after' if b.exists() else 'before'}")
        elif normalized(a) != normalized(b):
            differ.append(f"{name}: differs")
    skipped = [n for n in names if n.name in UNCOMPARABLE]
    print(f"{len(names)} files compared, {len(differ)} differ"
          + (f"; not compared (timing): {', '.join(map(str, skipped))}" if skipped else ""))
    for line in differ:
        print("  " + line)
    return 1 if differ else 0


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    sys.exit(main(Path(sys.argv[1]), Path(sys.argv[2])))
