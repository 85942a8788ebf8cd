#!/usr/bin/env python3
"""Lists pairs of sibling modules that import each other (issue 16: no import cycles inside a
folder). Usage: .ci/module_cycles.py [CRATE_SRC_DIR ...] (default: every crates/*/src).
Exits 1 when a pair is found.

Every `use` tree (braces expanded) and every path written in code that starts with `crate::`,
`super::` or `self::` is resolved to a module path; a reference from module a::x to a::y (or to
anything inside a::y) is an edge x -> y of folder a. Two siblings with edges both ways are a
cycle. Test modules (`tests`, `#[cfg(test)] mod tests { .. }`) and comments are ignored.
"""
import glob
import os
import re
import sys


def module_of(src, file):
    parts = os.path.relpath(file, src)[: -len(".rs")].split(os.sep)
    return tuple(parts[:-1] if parts[-1] in ("mod", "lib", "main") else parts)


def code_of(file):
    text = open(file, encoding="utf-8").read()
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    text = re.sub(r"//[^\n]*", "", text)
    text = re.sub(r'"(?:\\.|[^"\\])*"', '""', text)
    # Inline test modules come last by convention: drop from there on.
    return re.split(r"#\[cfg\(test\)\]\s*mod\s+\w+\s*\{", text)[0]


def expand(tree):
    """`a::{b, c::{d, e}}` -> [a::b, a::c::d, a::c::e] (as lists of names)."""
    tree = re.sub(r"\s+", "", tree)
    m = re.match(r"^((?:\w+::)*)\{(.*)\}$", tree)
    if not m:
        return [tree.split("::")]
    prefix = [p for p in m.group(1).split("::") if p]
    items, depth, start = [], 0, 0
    body = m.group(2)
    for i, ch in enumerate(body + ","):
        if ch == "{":
            depth += 1
        elif ch == "}":
            depth -= 1
        elif ch == "," and depth == 0:
            if body[start:i]:
                items.append(body[start:i])
            start = i + 1
    return [prefix + sub for item in items for sub in expand(item)]


def references(code):
    for m in re.finditer(r"\buse\s+([^;]+);", code):
        yield from expand(re.sub(r"\s+as\s+\w+", "", m.group(1)))
    for m in re.finditer(r"\b(?:crate|super|self)(?:::\w+)+", code):
        yield m.group(0).split("::")


def resolve(module, path):
    base, rest = list(module), list(path)
    if rest[0] == "crate":
        base, rest = [], rest[1:]
    elif rest[0] == "self":
        rest = rest[1:]
    elif rest[0] == "super":
        while rest and rest[0] == "super":
            base, rest = base[:-1], rest[1:]
    else:
        return None
    return tuple(base + rest)


def cycles(src):
    files = glob.glob(os.path.join(src, "**", "*.rs"), recursive=True)
    modules = {module_of(src, f): f for f in files}
    edges = set()
    for module, file in modules.items():
        if not module or "tests" in module:
            continue
        folder = module[:-1]
        for path in references(code_of(file)):
            target = resolve(module, path)
            if target is None or len(target) <= len(folder) or target[: len(folder)] != folder:
                continue
            sibling = folder + (target[len(folder)],)
            if sibling != module and sibling in modules:
                edges.add((module, sibling))
    return sorted({tuple(sorted(e)) for e in edges if (e[1], e[0]) in edges})


def main(srcs):
    srcs = srcs or sorted(glob.glob("crates/*/src"))
    found = 0
    for src in srcs:
        for a, b in cycles(src):
            found += 1
            print(f"{src}: {'::'.join(a)} <-> {'::'.join(b)}")
    print(f"{found} pair(s) of sibling modules importing each other in {len(srcs)} crate(s)")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
