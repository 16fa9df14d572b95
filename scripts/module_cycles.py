#!/usr/bin/env python3
"""Import cycles between the modules of a Rust crate.

Follows a crate's `mod name;` declarations from its src/lib.rs (with `#[path = ..]`), takes each
file as one module (inline `mod name { .. }` blocks belong to their file), and draws an edge from a
module to every module a path in it names: `crate::a::b::Item`, `super::Item`,
`self::child::Item`, a child module named directly (`child::Item`) and a module imported by `use`,
in `use` declarations and in code alike (`mod child;` declarations are not edges). A path names the
longest module prefix it has (`crate::a::b::Item` names `a::b` when that module exists, else `a`).
Then the strongly connected components of that graph (Tarjan): a component of more than one module
is an import cycle.

Test code (`#[cfg(test)]` modules, inline or in files of their own) is left out unless --tests is
given: a test may import any module of its crate without making the library's layers circular.

Usage: module_cycles.py [--max N] [--list] [--tests] CRATE_SRC [CRATE_SRC ...]
Prints each crate's largest component (and with --list every component of more than one module) and
exits 1 when a component has more than N modules (default 4).
"""

import argparse
import re
import sys
from pathlib import Path

IDENT = r"[A-Za-z_][A-Za-z0-9_]*"


def strip_comments_and_strings(text):
    """The source with comments, string and char literals blanked (newlines kept)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            i = j
        elif text.startswith("/*", i):
            depth, i = 1, i + 2
            while i < n and depth:
                if text.startswith("/*", i):
                    depth, i = depth + 1, i + 2
                elif text.startswith("*/", i):
                    depth, i = depth - 1, i + 2
                else:
                    if text[i] == "\n":
                        out.append("\n")
                    i += 1
        elif c == "r" and re.match(r'r#*"', text[i:i + 40]) and (i == 0 or not re.match(r"[A-Za-z0-9_]", text[i - 1])):
            m = re.match(r'r(#*)"', text[i:])
            end = '"' + m.group(1)
            j = text.find(end, i + len(m.group(0)))
            j = n if j < 0 else j + len(end)
            out.append(" " + "\n" * text.count("\n", i, j))
            i = j
        elif c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            out.append(" " + "\n" * text.count("\n", i, j))
            i = j + 1
        elif c == "'":
            # A char literal ('a', '\n', '\u{..}') or a lifetime ('a): only literals are blanked.
            m = re.match(r"'(\\.[^']*|[^\\'])'", text[i:])
            if m:
                out.append(" ")
                i += len(m.group(0))
            else:
                out.append(c)
                i += 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def module_of(src, path):
    """The module path (tuple of names) of a file under `src`."""
    parts = list(path.relative_to(src).with_suffix("").parts)
    if parts[-1] in ("mod", "lib", "main"):
        parts = parts[:-1]
    return tuple(parts)


def use_paths(tree, prefix=()):
    """The full paths of a `use` tree (`a::{b, c::{d, e}}` -> a::b, a::c::d, a::c::e)."""
    tree = tree.strip()
    if not tree:
        return []
    depth = 0
    for i, ch in enumerate(tree):
        if ch == "{":
            if depth == 0:
                head = tree[:i].rstrip(":").strip()
                inner = tree[i + 1:tree.rfind("}")]
                base = prefix + tuple(p for p in head.split("::") if p)
                out, part, d = [], "", 0
                for ch2 in inner:
                    if ch2 == "," and d == 0:
                        out += use_paths(part, base)
                        part = ""
                        continue
                    d += ch2 == "{"
                    d -= ch2 == "}"
                    part += ch2
                out += use_paths(part, base)
                return out
            depth += 1
    name = tree.split(" as ")[0].strip()
    alias = tree.split(" as ")[1].strip() if " as " in tree else None
    parts = tuple(p for p in name.split("::") if p)
    return [(prefix + parts, alias)]


MOD_DECL = re.compile(r"((?:#\[[^\]]*\]\s*)*)(?:pub(?:\([^)]*\))?\s+)?mod\s+(" + IDENT + r")\s*;")


def blank_test_blocks(text):
    """`text` with every `#[cfg(test)]` inline module's block blanked (newlines kept)."""
    out = text
    for m in reversed(list(re.finditer(r"#\[cfg\(test\)\]\s*(?:pub(?:\([^)]*\))?\s+)?mod\s+" + IDENT + r"\s*\{", text))):
        depth, i = 0, m.end() - 1
        while i < len(out):
            depth += out[i] == "{"
            depth -= out[i] == "}"
            i += 1
            if depth == 0:
                break
        out = out[:m.start()] + re.sub(r"[^\n]", " ", out[m.start():i]) + out[i:]
    return out


class Crate:
    def __init__(self, src, tests=False):
        self.src = Path(src)
        self.tests = tests
        self.modules = {}
        self.texts = {}
        self.walk((), self.src / "lib.rs", mod_rs=True)
        self.edges = {m: set() for m in self.modules}

    def walk(self, module, path, mod_rs):
        """Registers `module` (file `path`) and the file modules it declares."""
        text = strip_comments_and_strings(path.read_text())
        if not self.tests:
            text = blank_test_blocks(text)
        self.modules[module] = path
        self.texts[module] = text
        here = path.parent if mod_rs else path.parent / path.stem
        for m in MOD_DECL.finditer(text):
            attrs, name = m.group(1), m.group(2)
            if "cfg(test)" in attrs and not self.tests:
                continue
            at = re.search(r'path\s*=\s*"([^"]*)"', path.read_text()[m.start():m.end()]) if "path" in attrs else None
            if at:
                child = path.parent / at.group(1)
                self.walk(module + (name,), child, mod_rs=child.name == "mod.rs")
            elif (here / (name + ".rs")).exists():
                self.walk(module + (name,), here / (name + ".rs"), mod_rs=False)
            elif (here / name / "mod.rs").exists():
                self.walk(module + (name,), here / name / "mod.rs", mod_rs=True)

    def longest_module(self, path):
        """The longest prefix of `path` that is a module of the crate (None: none, or the root)."""
        for k in range(len(path), 0, -1):
            if tuple(path[:k]) in self.modules:
                return tuple(path[:k])
        return None

    def resolve(self, module, inline, path, aliases):
        """The crate-absolute path `path` means in `module` at inline depth `inline`, or None."""
        if not path:
            return None
        head, rest = path[0], list(path[1:])
        if head == "crate":
            return tuple(rest)
        if head in ("super", "self"):
            base = list(module) + [None] * inline
            if head == "super":
                base = base[:-1]
            while rest and rest[0] == "super":
                base, rest = base[:-1], rest[1:]
            if None in base:
                return None  # a path inside an inline module's own items
            return tuple(base) + tuple(rest)
        if head in aliases:
            return aliases[head] + tuple(rest)
        if inline == 0 and module + (head,) in self.modules:
            return module + (head,) + tuple(rest)
        return None

    def scan(self, module):
        text = self.texts[module]
        # Inline `mod name {` blocks: the brace depth at which each opens, to know the nesting of
        # any position.
        opens = [(m.end() - 1) for m in re.finditer(r"\bmod\s+" + IDENT + r"\s*\{", text)]
        depth_at, stack, depth, inline = {}, [], 0, 0
        events = []
        for m in re.finditer(r"[{}]", text):
            events.append((m.start(), m.group(0)))
        ev = iter(events)
        nxt = next(ev, None)
        open_set = set(opens)

        def inline_at(pos):
            nonlocal nxt, depth, inline
            while nxt is not None and nxt[0] < pos:
                p, ch = nxt
                if ch == "{":
                    depth += 1
                    if p in open_set:
                        stack.append(depth)
                        inline += 1
                else:
                    if stack and stack[-1] == depth:
                        stack.pop()
                        inline -= 1
                    depth -= 1
                nxt = next(ev, None)
            return inline

        aliases = {}
        targets = set()
        uses = list(re.finditer(r"\buse\s+([^;]*);", text))
        for m in uses:
            level = inline_at(m.start())
            for parts, alias in use_paths(m.group(1)):
                full = self.resolve(module, level, parts, aliases if level == 0 else {})
                if full is None:
                    continue
                target = self.longest_module(full)
                if target is not None:
                    targets.add(target)
                    name = alias or (parts[-1] if parts else None)
                    if level == 0 and name and name not in ("self", "*") and target == full:
                        aliases[name] = full
                    if level == 0 and name == "self" and target == full[:len(target)]:
                        aliases[full[-1]] = full
        # Paths in code (outside `use`): `a::b::c` sequences.
        stack.clear()
        depth, inline = 0, 0
        ev = iter(events)
        nxt = next(ev, None)
        spans = [(m.start(), m.end()) for m in uses]
        for m in re.finditer(r"(?<![A-Za-z0-9_:])(" + IDENT + r"(?:\s*::\s*" + IDENT + r")+)", text):
            if any(a <= m.start() < b for a, b in spans):
                continue
            level = inline_at(m.start())
            parts = tuple(p.strip() for p in m.group(1).split("::"))
            full = self.resolve(module, level, parts, aliases if level == 0 else {})
            if full is None:
                continue
            target = self.longest_module(full)
            if target is not None:
                targets.add(target)
        targets.discard(module)
        self.edges[module] |= targets

    def build(self):
        for module in self.modules:
            self.scan(module)
        return self

    def components(self):
        """Tarjan's strongly connected components (iterative)."""
        index, low, on, stack, comps = {}, {}, set(), [], []
        counter = [0]
        for root in self.modules:
            if root in index:
                continue
            work = [(root, iter(sorted(self.edges[root])))]
            index[root] = low[root] = counter[0]
            counter[0] += 1
            stack.append(root)
            on.add(root)
            while work:
                v, it = work[-1]
                w = next(it, None)
                if w is not None:
                    if w not in index:
                        index[w] = low[w] = counter[0]
                        counter[0] += 1
                        stack.append(w)
                        on.add(w)
                        work.append((w, iter(sorted(self.edges[w]))))
                    elif w in on:
                        low[v] = min(low[v], index[w])
                    continue
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    comp = []
                    while True:
                        w = stack.pop()
                        on.discard(w)
                        comp.append(w)
                        if w == v:
                            break
                    comps.append(sorted(comp))
        return sorted(comps, key=len, reverse=True)


def name(module):
    return "::".join(module) or "crate"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--max", type=int, default=4, help="the largest component allowed (default 4)")
    ap.add_argument("--list", action="store_true", help="list every component of more than one module")
    ap.add_argument("--tests", action="store_true", help="count the imports of test code too")
    ap.add_argument("src", nargs="+", help="a crate's src folder")
    args = ap.parse_args()
    failed = False
    for src in args.src:
        if not (Path(src) / "lib.rs").is_file():
            print(f"{src}: no lib.rs there", file=sys.stderr)
            return 2
        crate = Crate(src, args.tests).build()
        comps = crate.components()
        largest = comps[0] if comps else []
        bad = [c for c in comps if len(c) > args.max]
        print(f"{src}: {len(crate.modules)} modules, largest import cycle {len(largest)} module(s)"
              + (f": {', '.join(name(m) for m in largest)}" if 1 < len(largest) <= 12 else ""))
        if args.list:
            for c in comps:
                if len(c) > 1:
                    print(f"  {len(c)}: {', '.join(name(m) for m in c)}")
        for c in bad:
            failed = True
            print(f"{src}: an import cycle of {len(c)} modules (more than {args.max}): "
                  + ", ".join(name(m) for m in c), file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
