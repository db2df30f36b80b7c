#!/usr/bin/env python3
"""The include graph of the host's sources, and the layout rules it must keep.

Reads every #include "..." of host/src (the installable library), host/apps
and host/bench, resolves it as the compiler does (the including file's folder
first, then the include roots host/src and host/bench), and fails, naming the
files, when
  - a library file includes anything outside host/src (the benchmark above all),
  - a program in host/apps includes the benchmark,
  - files include each other in a cycle, or
  - folders (each one CMake target) depend on each other in a cycle.
Includes that resolve nowhere here (the generator's bpaccel_params.h, the
Verilated model's headers) are outside the graph.

  include_graph.py [--host DIR]           check; exit 1 on a finding
  include_graph.py --print                the folder graph, as docs/host.md shows it
  include_graph.py --self-test            the checks on small broken trees
"""
import argparse
import os
import re
import sys
import tempfile

INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)
PARTS = ("src", "apps", "bench")


def sources(host):
    for part in PARTS:
        for folder, _, files in os.walk(os.path.join(host, part)):
            for name in sorted(files):
                if name.endswith((".hpp", ".cpp", ".h")):
                    yield os.path.normpath(os.path.join(folder, name))


def resolve(host, including, name):
    for base in (os.path.dirname(including), os.path.join(host, "src"), os.path.join(host, "bench")):
        candidate = os.path.normpath(os.path.join(base, name))
        if os.path.isfile(candidate):
            return candidate
    return None


def graph(host):
    edges = {}
    for path in sources(host):
        with open(path, encoding="utf-8") as f:
            text = f.read()
        targets = set()
        for name in INCLUDE.findall(text):
            target = resolve(host, path, name)
            if target:
                targets.add(target)
        edges[path] = targets
    return edges


def folder(host, path):
    """The folder of a file relative to host/, e.g. src/device or bench/model."""
    return os.path.relpath(os.path.dirname(path), host)


def part(host, path):
    return os.path.relpath(path, host).split(os.sep)[0]


def cycles(nodes, edges):
    """One cycle per strongly connected component of more than one node (or a self loop)."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []
    counter = [0]

    def visit(v):  # Tarjan, iterative enough for these sizes
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in sorted(edges.get(v, ())):
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
            if len(component) > 1 or v in edges.get(v, ()):
                found.append(sorted(component))

    sys.setrecursionlimit(10000)
    for v in sorted(nodes):
        if v not in index:
            visit(v)
    return found


def folder_edges(host, edges):
    result = {}
    for src, targets in edges.items():
        a = folder(host, src)
        for t in targets:
            b = folder(host, t)
            if a != b:
                result.setdefault(a, {}).setdefault(b, 0)
                result[a][b] += 1
    return result


def findings(host):
    edges = graph(host)
    rel = lambda p: os.path.relpath(p, host)
    out = []
    for src, targets in sorted(edges.items()):
        for t in sorted(targets):
            if part(host, src) == "src" and part(host, t) != "src":
                out.append(f"library file {rel(src)} includes {rel(t)}, outside the library")
            if part(host, src) == "apps" and part(host, t) == "bench":
                out.append(f"program {rel(src)} includes {rel(t)}, of the benchmark")
    for component in cycles(edges.keys(), edges):
        out.append("files include each other in a cycle: " + ", ".join(rel(p) for p in component))
    folders = folder_edges(host, edges)
    folder_graph = {a: set(b) for a, b in folders.items()}
    for component in cycles(set(folder_graph) | {b for bs in folder_graph.values() for b in bs}, folder_graph):
        out.append("folders (CMake targets) depend on each other in a cycle: " + ", ".join(component))
    return out, folders


def print_graph(folders):
    """Each folder and the folders it includes from (with the number of includes)."""
    names = sorted(set(folders) | {b for bs in folders.values() for b in bs})
    width = max(len(n) for n in names)
    for a in names:
        deps = folders.get(a, {})
        listed = ", ".join(f"{b} ({n})" for b, n in sorted(deps.items())) or "-"
        print(f"{a.ljust(width)}  ->  {listed}")


def self_test():
    """Each rule fails on a tree made to break it, and passes on a sound one."""
    def tree(files):
        root = tempfile.mkdtemp(prefix="include-graph-")
        for path, text in files.items():
            full = os.path.join(root, path)
            os.makedirs(os.path.dirname(full), exist_ok=True)
            with open(full, "w", encoding="utf-8") as f:
                f.write(text)
        return root

    sound = {"src/core/a.hpp": "", "src/device/b.hpp": '#include "../core/a.hpp"\n',
             "bench/model/c.hpp": '#include "device/b.hpp"\n', "apps/main.cpp": '#include "device/b.hpp"\n'}
    cases = {
        "sound": (sound, None),
        "library includes the benchmark": (dict(sound, **{"src/core/a.hpp": '#include "../../bench/model/c.hpp"\n'}),
                                           "outside the library"),
        "program includes the benchmark": (dict(sound, **{"apps/main.cpp": '#include "model/c.hpp"\n'}),
                                           "of the benchmark"),
        "file cycle": (dict(sound, **{"src/device/d.hpp": '#include "e.hpp"\n', "src/device/e.hpp": '#include "d.hpp"\n'}),
                       "files include each other"),
        "folder cycle": (dict(sound, **{"src/core/f.hpp": '#include "../device/b.hpp"\n'}), "folders (CMake targets)"),
    }
    failed = 0
    for name, (files, expected) in cases.items():
        got, _ = findings(tree(files))
        ok = (not got) if expected is None else any(expected in f for f in got)
        print(f"self-test {name}: {'ok' if ok else 'WRONG'} {got}")
        failed += not ok
    return failed


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--host", default=os.path.normpath(os.path.join(here, "..", "..")))
    parser.add_argument("--print", action="store_true", help="print the folder graph")
    parser.add_argument("--self-test", action="store_true")
    args = parser.parse_args()
    if args.self_test:
        return 1 if self_test() else 0
    problems, folders = findings(args.host)
    if args.print:
        print_graph(folders)
    for p in problems:
        print("include graph:", p)
    if problems:
        return 1
    files = sum(1 for _ in sources(args.host))
    print(f"include graph: {files} files in {', '.join(PARTS)}: no library->benchmark edge, no cycle")
    return 0


if __name__ == "__main__":
    sys.exit(main())
