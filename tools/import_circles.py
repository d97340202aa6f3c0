#!/usr/bin/env python3
"""Count the import circles between the library's modules (issue #31).

What it counts:

- Nodes: the file modules of `src/` (`src/a/b.rs` or `src/a/b/mod.rs` is `a::b`; `src/lib.rs`
  is the crate root, `crate`). `src/main.rs` is another crate and is left out. Inline modules
  (`mod x { ... }`) count as part of their file.
- Edges: module A → module B when A names an item of B through
  `use crate::...`, `use super::...`, `use self::...`, a `use` of a child module's path
  (`use model::Eye` in `eye/mod.rs`), or an inline path (`crate::x::y`, `super::x`,
  `child::x`) outside `use` lines. A path resolves to the longest prefix that is a module; the
  item named after that prefix is then followed through that module's `use` re-exports
  (`pub use model::Eye` in `eye/mod.rs` sends `crate::eye::Eye` to `eye::model`, globs
  included), so a facade module's re-exports do not count as circles of their own. Edges from
  a module to itself are dropped.
- Ignored: comments, string and character literals, and `#[cfg(test)] mod NAME { ... }`
  blocks (the unit tests may reach anywhere).
- A circle is a strongly connected component of more than one module (a "knot"): the count the
  issue's target refers to. Also listed: the mutual pairs (A → B and B → A) and the number of
  elementary cycles (Johnson's algorithm, capped by --max-cycles), for a finer picture.

Usage: tools/import_circles.py [--src DIR] [--edges] [--max-cycles N]
"""

import argparse
import os
import re
import sys
from collections import defaultdict

ITEM_KINDS = r"(?:fn|struct|enum|trait|type|const|static|mod|union)"


def module_name(path, src):
    rel = os.path.relpath(path, src)[:-3].split(os.sep)  # drop ".rs"
    if rel == ["lib"]:
        return ()
    if rel[-1] == "mod":
        rel = rel[:-1]
    return tuple(rel)


def strip(text):
    """Removes comments, string and char literals (keeping line breaks, so nothing merges)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            depth, i = 1, i + 2
            while i < n and depth:
                if text.startswith("/*", i):
                    depth, i = depth + 1, i + 2
                elif text.startswith("*/", i):
                    depth, i = depth - 1, i + 2
                else:
                    i += 1
            out.append(" ")
        elif c == "r" and re.match(r'r#*"', text[i:i + 10]) and not (
            i and (text[i - 1].isalnum() or text[i - 1] == "_")
        ):
            m = re.match(r'r(#*)"', text[i:])
            end = text.find('"' + m.group(1), i + len(m.group(0)))
            i = n if end < 0 else end + 1 + len(m.group(1))
            out.append('""')
        elif c == '"':
            i += 1
            while i < n and text[i] != '"':
                i += 2 if text[i] == "\\" else 1
            i += 1
            out.append('""')
        elif c == "'":
            m = re.match(r"'(?:\\u\{[0-9a-fA-F]+\}|\\x[0-9a-fA-F]{2}|\\.|[^\\'])'", text[i:])
            if m:
                out.append("' '")
                i += len(m.group(0))
            else:
                out.append(c)
                i += 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def drop_test_modules(text):
    while True:
        m = re.search(r"#\[cfg\(test\)\]\s*(?:pub(?:\([^)]*\))?\s+)?mod\s+\w+\s*\{", text)
        if not m:
            return text
        depth, i = 1, m.end()
        while i < len(text) and depth:
            depth += {"{": 1, "}": -1}.get(text[i], 0)
            i += 1
        text = text[: m.start()] + text[i:]


def split_top(s):
    """Splits a use-tree list at top-level commas."""
    parts, depth, cur = [], 0, []
    for c in s:
        if c == "," and depth == 0:
            parts.append("".join(cur))
            cur = []
            continue
        depth += {"{": 1, "}": -1}.get(c, 0)
        cur.append(c)
    parts.append("".join(cur))
    return [p.strip() for p in parts if p.strip()]


def expand_use(tree, prefix=()):
    """Yields (path segments, imported name or '*' or None for `self`) for every leaf."""
    tree = tree.strip()
    if tree.startswith("::"):
        return  # an extern crate named absolutely
    m = re.match(r"^((?:\w+\s*::\s*)*)\{(.*)\}$", tree, re.S)
    if m:
        segs = tuple(s.strip() for s in m.group(1).split("::") if s.strip())
        for part in split_top(m.group(2)):
            yield from expand_use(part, prefix + segs)
        return
    alias = None
    am = re.match(r"^(.*?)\s+as\s+(\w+)$", tree, re.S)
    if am:
        tree, alias = am.group(1), am.group(2)
    segs = tuple(s.strip() for s in tree.split("::"))
    full = prefix + segs
    if full[-1] == "self":
        yield full[:-1], alias or full[-2] if len(full) > 1 else None
    elif full[-1] == "*":
        yield full, "*"
    else:
        yield full, alias or full[-1]


class Crate:
    def __init__(self, src):
        self.modules = {}  # name -> stripped text
        for root, _, files in os.walk(src):
            for f in files:
                if not f.endswith(".rs"):
                    continue
                path = os.path.join(root, f)
                if os.path.relpath(path, src) == "main.rs":
                    continue
                with open(path, encoding="utf-8") as fh:
                    text = drop_test_modules(strip(fh.read()))
                self.modules[module_name(path, src)] = text
        self.uses = {}  # module -> list of (absolute path segments, name, is_pub)
        self.defined = {}  # module -> set of item names it defines
        for mod, text in self.modules.items():
            self.defined[mod] = set(
                re.findall(ITEM_KINDS + r"\s+(\w+)", text)
                + re.findall(r"macro_rules!\s*(\w+)", text)
            )
            entries = []
            for m in re.finditer(r"(\bpub(?:\s*\([^)]*\))?\s+)?\buse\s+([^;]+);", text):
                for segs, name in expand_use(m.group(2)):
                    absolute = self.absolute(mod, segs)
                    if absolute is not None:
                        entries.append((absolute, name, bool(m.group(1))))
            self.uses[mod] = entries

    def children(self, mod):
        return {m[-1] for m in self.modules if len(m) == len(mod) + 1 and m[: len(mod)] == mod}

    def absolute(self, mod, segs):
        """The path from the crate root, or None for a path outside the crate."""
        if not segs:
            return None
        if segs[0] == "crate":
            return segs[1:]
        if segs[0] in ("super", "self"):
            base = list(mod)
            while segs and segs[0] in ("super", "self"):
                if segs[0] == "super":
                    if not base:
                        return None
                    base.pop()
                segs = segs[1:]
            return tuple(base) + tuple(segs)
        if segs[0] in self.children(mod):
            return tuple(mod) + tuple(segs)
        return None

    def resolve(self, path, seen=None):
        """The module that holds the item a crate-absolute path names."""
        k = len(path)
        while k and tuple(path[:k]) not in self.modules:
            k -= 1
        mod, rest = tuple(path[:k]), path[k:]
        if not rest or rest[0] == "*":
            return mod
        name = rest[0]
        seen = set() if seen is None else seen
        if (mod, name) in seen:
            return mod
        seen.add((mod, name))
        if name in self.defined.get(mod, ()):
            return mod
        for target, imported, _ in self.uses.get(mod, ()):
            if imported == name and target and target[-1] != "*":
                return self.resolve(tuple(target) + tuple(rest[1:]), seen)
        for target, imported, _ in self.uses.get(mod, ()):
            if imported == "*":
                base = tuple(target[:-1])
                if base in self.modules and (
                    name in self.defined[base]
                    or any(i == name or i == "*" for _, i, _ in self.uses.get(base, ()))
                ):
                    got = self.resolve(base + tuple(rest), seen)
                    if got != base or name in self.defined[base]:
                        return got
        return mod

    def edges(self):
        graph = defaultdict(set)
        for mod, text in self.modules.items():
            targets = []
            for path, name, _ in self.uses[mod]:
                if name == "*":
                    targets.append(tuple(path[:-1]))
                else:
                    targets.append(self.resolve(path))
            body = re.sub(r"\buse\s+[^;]+;", " ", text)
            for m in re.finditer(r"(?<![\w:])(\w+(?:\s*::\s*\w+)+)", body):
                segs = tuple(s.strip() for s in m.group(1).split("::"))
                absolute = self.absolute(mod, segs)
                if absolute is not None:
                    targets.append(self.resolve(absolute))
            for t in targets:
                if t != mod and t in self.modules:
                    graph[mod].add(t)
        return graph


def sccs(nodes, graph):
    index, low, stack, on, out = {}, {}, [], set(), []
    counter = [0]
    sys.setrecursionlimit(10000)

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            out.append(sorted(comp))

    for v in sorted(nodes):
        if v not in index:
            visit(v)
    return out


def count_cycles(comp, graph, cap):
    """Elementary cycles inside one component (Johnson-style search from each start node)."""
    order = {v: i for i, v in enumerate(comp)}
    members = set(comp)
    total = 0
    for s in comp:
        # Cycles whose smallest node is s: search only nodes ordered after s.
        stack = [(s, iter(sorted(graph.get(s, ()))))]
        path, on_path = [s], {s}
        while stack:
            v, it = stack[-1]
            for w in it:
                if w not in members or order[w] < order[s]:
                    continue
                if w == s:
                    total += 1
                    if total >= cap:
                        return total
                elif w not in on_path:
                    path.append(w)
                    on_path.add(w)
                    stack.append((w, iter(sorted(graph.get(w, ())))))
                    break
            else:
                stack.pop()
                on_path.discard(path.pop())
    return total


def name(mod):
    return "::".join(mod) if mod else "crate"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument("--src", default=os.path.join(here, "..", "src"))
    ap.add_argument("--edges", action="store_true", help="also print every edge inside a circle")
    ap.add_argument("--max-cycles", type=int, default=100000)
    args = ap.parse_args()

    crate = Crate(args.src)
    graph = crate.edges()
    knots = [c for c in sccs(crate.modules, graph) if len(c) > 1]
    knots.sort(key=lambda c: (-len(c), c))
    pairs = sorted(
        (a, b) for a in graph for b in graph[a] if a < b and a in graph.get(b, ())
    )
    cycles = sum(count_cycles(c, graph, args.max_cycles) for c in knots)

    print(f"modules: {len(crate.modules)}, edges: {sum(len(v) for v in graph.values())}")
    print(f"import circles (strongly connected components of more than one module): {len(knots)}")
    for c in knots:
        print(f"  [{len(c)}] " + ", ".join(name(m) for m in c))
        if args.edges:
            for a in c:
                for b in sorted(graph.get(a, ())):
                    if b in c:
                        print(f"        {name(a)} -> {name(b)}")
    print(f"mutual pairs (2-cycles): {len(pairs)}")
    for a, b in pairs:
        print(f"  {name(a)} <-> {name(b)}")
    capped = " (capped)" if cycles >= args.max_cycles else ""
    print(f"elementary cycles: {cycles}{capped}")


if __name__ == "__main__":
    main()
