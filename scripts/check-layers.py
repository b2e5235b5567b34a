#!/usr/bin/env python3
"""The include graph of vmpray's libraries, checked against their layers.

Each library folder has a layer; a file may include headers of its own
folder and of folders in lower layers only (folders of one layer are
independent of each other), and the headers of one folder include each
other without a cycle (a source file may include any header of its folder:
database.cpp builds the BVH whose header names the database). tests/ and
examples/ may include anything and are not checked.

usage: scripts/check-layers.py [--graph]   (exit 1 on any violation;
--graph prints the edges between folders)
"""
import collections
import pathlib
import re
import sys

# Lowest first. A folder not named here belongs to the nearest named parent.
LAYERS = [
    ("csp", 0), ("topology", 0), ("tracer", 0),
    ("nodes/net", 1),
    ("nodes/ranks", 2),
    ("nodes/machine", 3),
    ("mpi", 4),
    ("app/viz", 5),
    ("app", 6),
]
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)


def folder_of(path):
    best = None
    for folder, _ in LAYERS:
        if path == folder or path.startswith(folder + "/"):
            if best is None or len(folder) > len(best):
                best = folder
    return best


def main():
    root = pathlib.Path(__file__).resolve().parent.parent
    rank = dict(LAYERS)
    problems = []
    between = collections.Counter()
    modules = collections.defaultdict(lambda: collections.defaultdict(set))  # folder -> module -> modules
    for source in sorted(root.rglob("*")):
        rel = source.relative_to(root).as_posix()
        if source.suffix not in (".hpp", ".cpp", ".h") or rel.startswith(("build/", "tests/", "examples/")):
            continue
        here = folder_of(rel)
        if here is None:
            continue
        module = rel
        if source.suffix != ".cpp":
            modules[here].setdefault(module, set())
        text = source.read_text(encoding="utf-8", errors="replace")
        for line_no, target in ((text.count("\n", 0, m.start()) + 1, m.group(1)) for m in INCLUDE.finditer(text)):
            there = folder_of(target)
            if there is None:
                continue
            if there == here:
                if source.suffix != ".cpp":
                    modules[here][module].add(target)
                continue
            between[(here, there)] += 1
            if rank[there] >= rank[here]:
                problems.append(f"{rel}:{line_no}: {here} (layer {rank[here]}) includes {target} "
                                f"of {there} (layer {rank[there]})")
    for folder, graph in sorted(modules.items()):
        for cycle in cycles(graph):
            problems.append(f"{folder}: include cycle " + " -> ".join(cycle + [cycle[0]]))
    if "--graph" in sys.argv[1:]:
        for (a, b), n in sorted(between.items()):
            print(f"{a} -> {b}: {n}")
    for p in problems:
        print(p, file=sys.stderr)
    print(f"check-layers: {len(problems)} problem(s); {sum(len(g) for g in modules.values())} headers "
          f"of {len(modules)} folders", file=sys.stderr)
    return 1 if problems else 0


def cycles(graph):
    """One cycle per strongly connected component of more than one module."""
    index, low, on_stack, stack, found, counter = {}, {}, set(), [], [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in graph:
                continue
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    sys.setrecursionlimit(10000)
    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


if __name__ == "__main__":
    sys.exit(main())
