#!/usr/bin/env python3
"""Holds vmpray's memory estimate to measured peaks over a matrix of runs.

For each row, the estimate `vmpray ... --estimate-memory` prints is set
beside the peak resident size of the same run (/usr/bin/time -f %M), each
less that of the same scene and image on one node with the same timing: what
the machine's nodes, links, relays and recording add. A row passes when the
estimate is at least 75% of what was measured (an estimate above the peak
refuses only runs that would have come near the limit). Every run is made
under an address-space limit (ulimit -v) of 90% of the machine's memory, so
a run larger than the machine ends in a failed row rather than the kernel's
out-of-memory killer.

usage: memory-matrix.py [--vmpray PATH] [--quick] [--markdown]
  --quick     the rows of a few seconds each (CI); default: all, up to 4096 nodes
  --markdown  the table as docs/performance.md shows it
Exit 0 when every row passes, 1 when one fails, 2 on bad arguments.
"""
import argparse
import os
import re
import resource
import subprocess
import sys
import tempfile

# (scene and image, machine options, quick?)
SMALL = "teapot --width 16 --height 16"
ROWS = [
    (SMALL, "--topology complete --nodes 256 --threads 1", True),
    (SMALL, "--topology complete --nodes 256 --threads 2", True),
    (SMALL, "--nodes 1024 --threads 2", True),
    (SMALL, "--topology torus:32x32 --threads 2 --workers-per-node 3", True),
    (SMALL, "--topology ring --nodes 256 --timing virtual", True),
    ("rings4 --width 128 --height 128 --cache-pages 8", "--replay {tmp}/r.html --replay-packets 20000", True),
    (SMALL, "--topology complete --nodes 1024 --threads 1", False),
    (SMALL, "--topology complete --nodes 1024 --threads 2", False),
    (SMALL, "--topology complete --nodes 2048 --threads 2", False),
    (SMALL, "--topology complete --nodes 4096 --threads 1", False),
    (SMALL, "--nodes 4096 --threads 2", False),
    (SMALL, "--topology ring --nodes 4096 --threads 2", False),
    (SMALL, "--topology torus:64x64 --threads 2", False),
    (SMALL, "--topology mesh:64x64 --threads 2", False),
    (SMALL, "--nodes 4096 --threads 2 --workers-per-node 3", False),
    ("tetra9 --width 16 --height 16", "--nodes 4096 --threads 2", False),
    (SMALL, "--topology complete --nodes 256 --timing virtual", True),
    (SMALL, "--nodes 4096 --timing virtual", False),
    (SMALL, "--topology torus:64x64 --timing virtual", False),
    ("tetra9 --width 16 --height 16", "--nodes 4096 --timing virtual", False),
    ("rings4 --width 256 --height 256 --cache-pages 8", "--replay {tmp}/r.html --replay-packets 100000", False),
    ("rings4 --width 256 --height 256 --cache-pages 8",
     "--topology ring --replay {tmp}/r.html --replay-packets 100000", False),
]


def memory_total():
    with open("/proc/meminfo") as f:
        for line in f:
            if line.startswith("MemTotal:"):
                return int(line.split()[1]) * 1024
    return 8 << 30


def estimate(vmpray, words):
    out = subprocess.run([vmpray, *words, "--estimate-memory"], capture_output=True, text=True, check=True).stdout
    match = re.search(r"\((\d+) bytes\) resident", out)
    if not match:
        raise RuntimeError("no estimate in: " + out)
    return int(match.group(1))


def peak(vmpray, words, limit, tmp):
    """Peak resident bytes of the run, or None with the error it ended in."""
    def limited():
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    run = subprocess.run(["/usr/bin/time", "-f", "%M", vmpray, *words, "-q", "-o", os.path.join(tmp, "x.png")],
                         capture_output=True, text=True, preexec_fn=limited)
    lines = run.stderr.strip().splitlines()
    if run.returncode != 0 or not lines:
        return None, (lines[-2] if len(lines) > 1 else "exit %d" % run.returncode)
    return int(lines[-1]) * 1024, None


def one_node(machine):
    timing = "--timing virtual" if "--timing virtual" in machine else ""
    return "--nodes 1 " + timing


def main():
    parser = argparse.ArgumentParser(usage=__doc__.split("usage: ")[1].split("\n")[0])
    parser.add_argument("--vmpray", default="build/release/app/vmpray")
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--markdown", action="store_true")
    args = parser.parse_args()
    if not os.access(args.vmpray, os.X_OK):
        parser.error("no vmpray at " + args.vmpray + " (build it, or give --vmpray)")
    ceiling = memory_total() * 9 // 10
    failed = 0
    bases = {}
    with tempfile.TemporaryDirectory() as tmp:
        if args.markdown:
            print("| scene and image | machine | estimate | measured | estimate / measured |")
            print("|---|---|---|---|---|")
        for scene, machine, quick in ROWS:
            if args.quick and not quick:
                continue
            words = (scene + " " + machine.format(tmp=tmp)).split()
            base_words = (scene + " " + one_node(machine)).split()
            est = estimate(args.vmpray, words) - estimate(args.vmpray, base_words)
            key = " ".join(base_words)
            if key not in bases:
                bases[key] = peak(args.vmpray, base_words, ceiling, tmp)[0]
            limit = ceiling
            got, error = peak(args.vmpray, words, limit, tmp)
            if got is None or bases[key] is None:
                failed += 1
                print("%s %s: FAILED under ulimit -v %d KB: %s" % (scene, machine, limit // 1024, error))
                continue
            measured = max(got - bases[key], 1)
            ratio = est / measured
            ok = ratio >= 0.75
            failed += not ok
            shown = machine.replace("{tmp}/", "")
            if args.markdown:
                print("| %s | %s | %.0f MB | %.0f MB | %.2f |" % (scene, shown, est / 1e6, measured / 1e6, ratio))
            else:
                print("%-50s %-56s estimate %8.1f MB measured %8.1f MB  %.2f %s" %
                      (scene, shown, est / 1e6, measured / 1e6, ratio, "" if ok else "BELOW 0.75"), flush=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
