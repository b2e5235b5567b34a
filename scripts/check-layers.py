#!/usr/bin/env python3
"""The include graph of vmpray's libraries, checked against their layers.

Each library folder has a layer; a file may include headers of its own
folder and of folders in lower layers only (folders of one layer are
independent of each other). Within a folder, the modules include each other
without a cycle: a module is x.hpp with x.cpp (either may be missing), and
module x depends on module y when either file of x includes y.hpp. So a
source file including a header whose module includes the source's own
header back is a cycle, as two headers including each other are; a cycle
is a problem, and the usual way out is a header of the plain types both
sides name.
tests/ and examples/ may include anything and are not checked.

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
    ("app/render", 5), ("app/viz", 5),
    ("app/experiments", 6),
    ("app", 7),
]
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)


def folder_of(path):
    best = None
    for folder, _ in LAYERS:
        if path == folder or path.startswith(folder + "/"):
            if best is None or len(folder) > len(best):
                best = folder
    return best


def module_of(path):
    """x.hpp, x.cpp and x.h are one module, x."""
    return path.rsplit(".", 1)[0]


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
        module = module_of(rel)
        modules[here].setdefault(module, set())
        text = source.read_text(encoding="utf-8", errors="replace")
        for line_no, target in ((text.count("\n", 0, m.start()) + 1, m.group(1)) for m in INCLUDE.finditer(text)):
            there = folder_of(target)
            if there is None:
                continue
            if there == here:
                if module_of(target) != module:
                    modules[here][module].add(module_of(target))
                continue
            between[(here, there)] += 1
            if rank[there] >= rank[here]:
                problems.append(f"{rel}:{line_no}: {here} (layer {rank[here]}) includes {target} "
                                f"of {there} (layer {rank[there]})")
    found = [(folder, cycle) for folder, graph in sorted(modules.items()) for cycle in cycles(graph)]
    for folder, (component, cycle) in found:
        line = f"{folder}: include cycle " + " -> ".join(cycle + [cycle[0]])
        if len(component) > len(cycle):
            line += " (and " + ", ".join(sorted(component - set(cycle))) + " in cycles with them)"
        problems.append(line)
    if "--graph" in sys.argv[1:]:
        for (a, b), n in sorted(between.items()):
            print(f"{a} -> {b}: {n}")
    for line in problems:
        print(line, file=sys.stderr)
    print(f"check-layers: {len(problems)} problem(s); {sum(len(g) for g in modules.values())} modules "
          f"of {len(modules)} folders", file=sys.stderr)
    return 1 if problems else 0


def cycles(graph):
    """Each strongly connected component of more than one module, with one
    cycle through it: the modules along it in order (the last one's include
    closes it)."""
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
                found.append((set(component), cycle_through(graph, set(component))))

    sys.setrecursionlimit(10000)
    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def cycle_through(graph, component):
    """The shortest cycle from the component's first module back to it."""
    start = min(component)
    parent, queue = {start: None}, collections.deque([start])
    while queue:
        v = queue.popleft()
        for w in sorted(graph[v] & component):
            if w == start:
                path = [v]
                while parent[path[-1]] is not None:
                    path.append(parent[path[-1]])
                return path[::-1]
            if w not in parent:
                parent[w] = v
                queue.append(w)
    return sorted(component)


if __name__ == "__main__":
    sys.exit(main())
