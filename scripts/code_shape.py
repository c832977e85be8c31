#!/usr/bin/env python3
"""The shape of the C code: file-level call circles and the longest functions.

    python3 scripts/code_shape.py [BUILD]        (BUILD defaults to build)

Circles: each object file of BUILD's library, command and tool targets is a node; a file points
to another when it calls or reads a symbol the other defines (`nm`: its undefined symbols against
the other's defined ones). Every strongly connected group of more than one file is a circle,
printed with the symbols that close it. Files of one program only (host/) and of the library
(lib/) are graphed apart, since the same name may be defined in both.

Longest functions: every function body in lib/, host/ and kernels/ (a definition that starts at
the first column and ends at a `}` in the first column), longest first, with the number of lines
from its signature to its closing brace.

Layers: lib/README.md's table lists lib/'s folders from the top down; a call from a folder to
one above it in that table is printed as a call upward.

Configuration: the library reads the environment in one file, lib/core/environment.c (its table
is docs/environment.md); any other lib/ object that calls getenv is printed.

Public functions: each function rsmooth.h and rsmooth_cl.h declare is defined in lib/api/, and each
of rsmooth_io.h's in lib/io/ or lib/stream/ (the file library's layers); any other is printed.

Exits 1 when there is a circle, a call upward, a getenv elsewhere, a public function defined
outside its layer or a function over --max-lines (120), else 0.
Needs binutils' nm. CI runs it as the test code_shape.
"""
import argparse
import collections
import glob
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def objects(build):
    """Source path (relative to the root) -> object file, for the library and the programs."""
    found = {}
    for o in glob.glob(os.path.join(build, "CMakeFiles", "*.dir", "**", "*.o"), recursive=True):
        rel = o.split(".dir" + os.sep, 1)[1][:-2]  # lib/x.c
        if not (rel.startswith("lib/") or rel.startswith("host/")):
            continue
        if os.path.exists(os.path.join(ROOT, rel)):  # not a stale object of a moved file
            found.setdefault(rel, o)
    return found


def symbols(obj):
    out = subprocess.run(["nm", "--defined-only", "-g", obj], capture_output=True, text=True).stdout
    defined = {line.split()[-1] for line in out.splitlines() if line.strip()}
    out = subprocess.run(["nm", "-u", obj], capture_output=True, text=True).stdout
    used = {line.split()[-1] for line in out.splitlines() if line.strip()}
    return defined, used


def strongly_connected(graph):
    """Tarjan's algorithm, iterative: the groups of nodes that reach each other."""
    index, low, on, stack, groups, counter = {}, {}, set(), [], [], [0]
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = counter[0]
        counter[0] += 1
        stack.append(root)
        on.add(root)
        while work:
            node, edges = work[-1]
            advanced = False
            for nxt in edges:
                if nxt not in index:
                    index[nxt] = low[nxt] = counter[0]
                    counter[0] += 1
                    stack.append(nxt)
                    on.add(nxt)
                    work.append((nxt, iter(sorted(graph[nxt]))))
                    advanced = True
                    break
                if nxt in on:
                    low[node] = min(low[node], index[nxt])
            if advanced:
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                group = []
                while True:
                    n = stack.pop()
                    on.discard(n)
                    group.append(n)
                    if n == node:
                        break
                groups.append(sorted(group))
    return groups


def layers():
    """lib/'s folders from the top down, as lib/README.md's table lists them."""
    with open(os.path.join(ROOT, "lib", "README.md"), encoding="utf-8") as f:
        return re.findall(r"^\| `(\w+)/` \|", f.read(), re.M)


def layer_of(src, order):
    parts = src.split("/")
    return order.index(parts[1]) if len(parts) > 2 and parts[1] in order else None


def circles(build):
    """(object files, circles, calls upward) of the build's library and programs."""
    objs = objects(build)
    if not objs:
        sys.exit("code_shape: no object files under %s/CMakeFiles: build it first" % build)
    table = {src: symbols(o) for src, o in objs.items()}
    order = layers()
    found, upward = [], []
    for header, homes in (("rsmooth.h", ("lib/api/",)), ("rsmooth_cl.h", ("lib/api/",)),
                          ("rsmooth_io.h", ("lib/io/", "lib/stream/"))):
        with open(os.path.join(ROOT, "lib", "include", header), encoding="utf-8") as f:
            names = set(re.findall(r"RSMOOTH_API[^;(]*?\b(rsmooth_\w+)\s*\(", f.read()))
        for src, (defined, _) in sorted(table.items()):
            for name in sorted(names & defined):
                if src.startswith("lib/") and not src.startswith(homes):
                    upward.append("%s defines %s (%s): its home is %s" % (src, name, header,
                                                                          " or ".join(homes)))
    readers = sorted(src for src, (_, used) in table.items()
                     if src.startswith("lib/") and "getenv" in used
                     and src != "lib/core/environment.c")
    upward.extend("%s reads the environment (getenv): only lib/core/environment.c may" % src
                  for src in readers)
    for side in ("lib/", "host/"):
        files = [s for s in table if s.startswith(side)]
        # lib/ is shared by every program; host/ files may link only some of their neighbours,
        # so a symbol defined twice in host/ (one per program) points at both.
        owner = collections.defaultdict(set)
        for s in files:
            for sym in table[s][0]:
                owner[sym].add(s)
        graph = {s: set() for s in files}
        why = collections.defaultdict(set)
        for s in files:
            for sym in table[s][1]:
                for t in owner.get(sym, ()):
                    if t != s:
                        graph[s].add(t)
                        why[(s, t)].add(sym)
        for (a, b), syms in sorted(why.items()):
            la, lb = layer_of(a, order), layer_of(b, order)
            if la is not None and lb is not None and lb < la:
                upward.append("%s -> %s (%s)" % (a, b, ", ".join(sorted(syms)[:3])))
        for group in strongly_connected(graph):
            if len(group) > 1:
                members = set(group)
                edges = ["%s -> %s (%s)" % (a, b, ", ".join(sorted(why[(a, b)])[:3]))
                         for a in group for b in sorted(graph[a]) if b in members]
                found.append((group, edges))
    return len(table), found, upward


DEF_RE = re.compile(r"^(?!static_assert|typedef|struct\s+\w+\s*\{|enum|union|#)"
                    r"[A-Za-z_][\w\s\*\(\),\[\]]*?\b(\w+)\s*\([^;]*$")


def functions(paths):
    """(lines, file, line, name) of every function body that starts and ends in column 0."""
    out = []
    for path in paths:
        with open(path, encoding="utf-8", errors="replace") as f:
            lines = f.read().split("\n")
        start = name = None
        for i, line in enumerate(lines):
            if start is None:
                m = DEF_RE.match(line)
                if m and not line.startswith((" ", "\t", "}", "{")):
                    # the body must open before the next blank line or statement
                    for j in range(i, min(i + 12, len(lines))):
                        if lines[j].rstrip().endswith(";") and "{" not in lines[j]:
                            break
                        if "{" in lines[j]:
                            start, name = i, m.group(1)
                            break
            elif line.startswith("}"):
                out.append((i - start + 1, os.path.relpath(path, ROOT), start + 1, name))
                start = None
    return sorted(out, reverse=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("build", nargs="?", default=os.path.join(ROOT, "build"))
    ap.add_argument("--max-lines", type=int, default=120)
    ap.add_argument("--most", type=int, default=12, help="how many of the longest to list")
    a = ap.parse_args()
    count, found, upward = circles(a.build)
    print("file-level circles among %d object files: %d" % (count, len(found)))
    for group, edges in found:
        print("  circle: " + " <-> ".join(group))
        for e in edges:
            print("    " + e)
    print("calls upward between lib/'s layers (lib/README.md), getenv outside "
          "lib/core/environment.c, public functions outside their layer: %d" % len(upward))
    for e in upward:
        print("    " + e)
    srcs = sorted(glob.glob(os.path.join(ROOT, "lib", "**", "*.c"), recursive=True)
                  + glob.glob(os.path.join(ROOT, "host", "*.c"))
                  + glob.glob(os.path.join(ROOT, "kernels", "*.cl")))
    funcs = functions(srcs)
    over = [f for f in funcs if f[0] > a.max_lines]
    print("functions read: %d; over %d lines: %d; the longest:" % (len(funcs), a.max_lines, len(over)))
    for n, path, line, name in funcs[:max(a.most, len(over))]:
        print("  %5d  %s:%d  %s" % (n, path, line, name))
    return 1 if found or upward or over else 0


if __name__ == "__main__":
    sys.exit(main())
