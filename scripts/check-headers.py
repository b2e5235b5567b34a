#!/usr/bin/env python3
"""Every header opens with its contract, in at most 15 comment lines.

A header's opening comment says what the unit is for, its invariants, its
thread-safety and who owns what; a protocol is described once, in
docs/architecture.md, and a rationale beside the code it explains in the
.cpp file. This counts, for each header git tracks (`git ls-files '*.hpp'`),
the lines starting with `//` before its first other line, lists every header
whose opening is longer than the limit with its count, and exits 1 if there
is one, 0 otherwise.

usage: scripts/check-headers.py   (run from anywhere inside the repository)
"""
import pathlib
import subprocess
import sys

LIMIT = 15


def opening_lines(path):
    count = 0
    with open(path, encoding="utf-8", errors="replace") as f:
        for line in f:
            if not line.lstrip().startswith("//"):
                break
            count += 1
    return count


def main():
    top = subprocess.run(["git", "rev-parse", "--show-toplevel"], check=True,
                         capture_output=True, text=True).stdout.strip()
    names = subprocess.run(["git", "ls-files", "*.hpp"], cwd=top, check=True,
                           capture_output=True, text=True).stdout.split()
    root = pathlib.Path(top)
    over = []
    for name in sorted(names):
        path = root / name
        if path.is_file():
            count = opening_lines(path)
            if count > LIMIT:
                over.append((count, name))
    for count, name in over:
        print(f"{name}: {count} opening comment lines (at most {LIMIT})")
    if over:
        sys.stdout.flush()
        print(f"check-headers: {len(over)} header(s) open with more than "
              f"{LIMIT} comment lines", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
