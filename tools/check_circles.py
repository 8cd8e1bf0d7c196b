#!/usr/bin/env python3
"""check_circles.py OBJECT...: fails when object files depend on each other in
a circle.

An object depends on another when it uses a global symbol the other defines
(nm). A circle (a strongly connected set of two or more objects) means two
files each need the other: one of them has two jobs, or a rule sits in the
wrong file. `make check` runs this over the library's and the CLI's objects;
it prints every circle with the symbols that close it and exits 1, or prints
one line and exits 0.
"""
import collections
import os
import sys

from object_symbols import links


def circles(graph):
    """Strongly connected components of more than one node (Tarjan, iterative)."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []
    counter = 0
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, edges = work[-1]
            advanced = False
            for nxt in edges:
                if nxt not in index:
                    index[nxt] = low[nxt] = counter
                    counter += 1
                    stack.append(nxt)
                    on_stack.add(nxt)
                    work.append((nxt, iter(sorted(graph[nxt]))))
                    advanced = True
                    break
                if nxt in on_stack:
                    low[node] = min(low[node], index[nxt])
            if advanced:
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    found.append(sorted(component))
    return found


def main(objects):
    defined_by, uses = links(objects)
    graph = collections.defaultdict(set)
    for obj in objects:
        graph[obj]
        for sym in uses[obj]:
            other = defined_by.get(sym)
            if other and other != obj:
                graph[obj].add(other)
    found = circles(graph)
    for component in found:
        print("check_circles: circle: " + " ".join(os.path.relpath(o) for o in component))
        for a in component:
            for b in sorted(graph[a] & set(component)):
                syms = sorted(s for s in uses[a] if defined_by.get(s) == b)
                print(f"  {os.path.relpath(a)} uses {os.path.relpath(b)}: {', '.join(syms[:5])}")
    if found:
        return 1
    print(f"check_circles: {len(objects)} objects, no circle")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
