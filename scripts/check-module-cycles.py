#!/usr/bin/env python3
"""Finds module cycles inside each crate (scripts/check-architecture.py runs it).

A crate's modules are the top-level modules under its `src/` (a folder module with
its sub-modules counts as one); module `a` uses module `b` when a file of `a`
names `crate::b` (or `super::b` from where `super` is the crate root), in a `use`
or in a path, outside comments, strings and tests (`#[cfg(test)] mod … { }`
blocks, files named tests.rs: a test may use whatever it tests). The crate
root (lib.rs, main.rs) is not a module here: it is the crate's facade. Two modules that reach each
other through such uses form a cycle; each cycle is one error line.

Usage: check-module-cycles.py [crates/<dir> ...] (default: every crate).
Exit status 1 when some crate has a cycle.
"""
import glob
import os
import re
import sys

IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def strip(text: str) -> str:
    """The code without comments, string and char literals (kept as blanks)."""
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
        elif c == "r" and re.match(r'r#*"', text[i:]) and not (i and (text[i - 1].isalnum() or text[i - 1] == "_")):
            hashes = re.match(r'r(#*)"', text[i:]).group(1)
            end = text.find('"' + hashes, i + 2 + len(hashes))
            i = n if end < 0 else end + 1 + len(hashes)
            out.append('""')
        elif c == '"':
            i += 1
            while i < n and text[i] != '"':
                i += 2 if text[i] == "\\" else 1
            i += 1
            out.append('""')
        elif c == "'" and re.match(r"'(\\.|[^\\'])'|'\\u\{[0-9a-fA-F]+\}'|'\\x[0-9a-fA-F]{2}'", text[i:]):
            m = re.match(r"'(\\.|[^\\'])'|'\\u\{[0-9a-fA-F]+\}'|'\\x[0-9a-fA-F]{2}'", text[i:])
            i += len(m.group(0))
            out.append("' '")
        else:
            out.append(c)
            i += 1
    return "".join(out)


def without_tests(code: str) -> str:
    """The code without its `#[cfg(test)] mod name { … }` blocks."""
    out, pos = [], 0
    for m in re.finditer(r"#\[cfg\(test\)\]\s*(?:pub(?:\([^)]*\))?\s+)?mod\s+\w+\s*\{", code):
        if m.start() < pos:
            continue
        depth, j = 1, m.end()
        while j < len(code) and depth:
            depth += {"{": 1, "}": -1}.get(code[j], 0)
            j += 1
        out.append(code[pos : m.start()])
        pos = j
    out.append(code[pos:])
    return "".join(out)


def heads(code: str, pos: int) -> list[str]:
    """The first segment of each path starting at `pos` (`a::x` or `{a, b::y}`)."""
    if pos < len(code) and code[pos] == "{":
        depth, j, start, parts = 0, pos, pos + 1, []
        while j < len(code):
            if code[j] == "{":
                depth += 1
            elif code[j] == "}":
                depth -= 1
                if depth == 0:
                    parts.append(code[start:j])
                    break
            elif code[j] == "," and depth == 1:
                parts.append(code[start:j])
                start = j + 1
            j += 1
        out = []
        for p in parts:
            m = IDENT.match(p.strip())
            if m:
                out.append(m.group(0))
        return out
    m = IDENT.match(code, pos)
    return [m.group(0)] if m else []


def module_of(src: str, path: str) -> list[str]:
    """The module path of a file under src (lib.rs → [], a/b.rs → [a, b], a/mod.rs → [a])."""
    rel = os.path.relpath(path, src)[: -len(".rs")].split(os.sep)
    if rel[-1] == "mod":
        rel = rel[:-1]
    if rel in (["lib"], ["main"]):
        return []
    return rel


def crate_graph(dir_: str) -> dict[str, set[str]]:
    src = os.path.join(dir_, "src")
    files = [f for f in glob.glob(os.path.join(src, "**", "*.rs"), recursive=True)]
    # Separate binaries (src/bin/) are crates of their own.
    files = [f for f in files if not os.path.relpath(f, src).startswith("bin" + os.sep)]
    # Test files: a test may use whatever it tests.
    files = [f for f in files if os.path.basename(f) != "tests.rs"]
    tops = {m[0] for m in (module_of(src, f) for f in files) if m}
    graph: dict[str, set[str]] = {t: set() for t in tops}
    for f in files:
        here = module_of(src, f)
        if not here:
            continue
        code = without_tests(strip(open(f, encoding="utf-8").read()))
        for m in re.finditer(r"(?<![A-Za-z0-9_:])((?:crate|super|self)(?:::(?:super|self))*)::", code):
            segs = m.group(1).split("::")
            if segs[0] == "crate":
                base: list[str] | None = []
                segs = segs[1:]
            else:
                base = list(here)
            for s in segs:
                if s == "super":
                    base = base[:-1] if base else None
                    if base is None:
                        break
            if base is None:
                continue
            if base:
                target = [base[0]]
            else:
                target = heads(code, m.end())
            for t in target:
                if t in tops and t != here[0]:
                    graph[here[0]].add(t)
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components with more than one module (Tarjan)."""
    index, low, on, stack, out, counter = {}, {}, set(), [], [], [0]

    def visit(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(graph[v]):
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
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def main(argv: list[str]) -> int:
    dirs = argv or sorted(os.path.dirname(p) for p in glob.glob("crates/*/Cargo.toml"))
    bad = 0
    for d in dirs:
        g = crate_graph(d)
        for comp in cycles(g):
            edges = ", ".join(f"{a}→{b}" for a in comp for b in sorted(g[a]) if b in comp)
            print(f"error: {d}: module cycle {' ↔ '.join(comp)} ({edges})", file=sys.stderr)
            bad += 1
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
