#!/usr/bin/env python3
"""Checks README.md and the book (docs/src/**/*.md) against the repository and the CLI.

- Links: every relative link points to a file or folder that exists, and every `#anchor` to a
  heading of its target (anchors as GitHub and mdBook make them).
- The book: every chapter under docs/src is listed in SUMMARY.md.
- Code blocks: every fenced block names its language (rustdoc compiles an unlabelled block of the
  README, or of a chapter included as a doc test, as Rust).
- Commands in console / sh blocks (`$ ` lines of a console block, every line of an sh block):
  `mcbench <subcommand>` (also as a path such as target/release/mcbench, or after the `--` of
  `cargo run`) names a subcommand and flags that the binary's `--help` lists, experiments that
  `mcbench list experiments` lists and test beds that `mcbench list testbeds` lists; `cargo <sub>`
  is a cargo subcommand whose `--help` lists its flags, `-p` names a workspace package and
  `--bin/--example/--test/--bench` one of its targets; a `scripts/...` path exists.

The CLI is the debug binary (`${CARGO_TARGET_DIR:-target}/debug/mcbench`, which `cargo test` builds),
or --mcbench PATH / $MCBENCH. Prints one line per problem (`file:line: what`) and exits 1 when there is
any; `--self-test` checks that the checker itself catches a broken link, a missing anchor and an
unknown flag.

Usage: python3 scripts/check_docs.py [--root DIR] [--mcbench PATH] [--self-test]
"""

from __future__ import annotations

import argparse
import functools
import json
import os
import re
import shlex
import subprocess
import sys
import tempfile
from pathlib import Path

COMMAND_LANGS = {"console", "sh", "bash", "shell"}
LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
REF_DEF = re.compile(r"^\s{0,3}\[[^\]]+\]:\s*<?(\S+?)>?(?:\s+\"[^\"]*\")?\s*$")
CODE_SPAN = re.compile(r"(`+)(.+?)\1")
FLAG = re.compile(r"(?:^|[\[|(])(--?[A-Za-z][A-Za-z0-9-]*)")


def slug(heading: str) -> str:
    """The anchor of a heading: mdBook's `normalize_id` (GitHub's is the same for these texts)."""
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", heading)  # a link's text only
    text = text.replace("`", "")
    out = []
    for ch in text.strip():
        if ch.isalnum() or ch in "_-":
            out.append(ch.lower())
        elif ch.isspace():
            out.append("-")
    return "".join(out)


class Doc:
    """One markdown file: its lines, code blocks and headings."""

    def __init__(self, path: Path):
        self.path = path
        self.lines = path.read_text(encoding="utf-8").split("\n")
        self.blocks: list[tuple[int, str, list[str]]] = []  # (line of the opening fence, lang, lines)
        self.prose: list[tuple[int, str]] = []  # lines outside fenced blocks
        fence, start, lang, body = None, 0, "", []
        for n, line in enumerate(self.lines, 1):
            stripped = line.lstrip()
            if fence is None:
                m = re.match(r"(`{3,}|~{3,})(.*)$", stripped)
                if m:
                    fence, start, lang, body = m.group(1), n, m.group(2).strip(), []
                else:
                    self.prose.append((n, line))
            elif stripped.startswith(fence) and stripped.strip() == stripped.strip()[0] * len(stripped.strip()):
                self.blocks.append((start, lang, body))
                fence = None
            else:
                body.append(line)
        if fence is not None:
            self.blocks.append((start, lang, body))
            self.unclosed = start
        else:
            self.unclosed = None

    @functools.cached_property
    def anchors(self) -> set[str]:
        seen: dict[str, int] = {}
        out = set()
        for _, line in self.prose:
            m = re.match(r"^ {0,3}(#{1,6})\s+(.*?)\s*#*\s*$", line)
            if not m:
                continue
            base = slug(m.group(2))
            k = seen.get(base, 0)
            seen[base] = k + 1
            out.add(base if k == 0 else f"{base}-{k}")
        for _, line in self.prose:  # explicit anchors: <a id="x"></a> or <a name="x">
            out.update(re.findall(r"<a\s+(?:id|name)=\"([^\"]+)\"", line))
        return out


class Checker:
    def __init__(self, root: Path, mcbench: Path):
        self.root = root.resolve()
        self.mcbench = mcbench
        self.cargo_dir = Path(__file__).resolve().parent.parent  # the workspace cargo commands refer to
        self.problems: list[str] = []
        self.docs: dict[Path, Doc] = {}
        self.counts = {"files": 0, "links": 0, "blocks": 0, "mcbench": 0, "cargo": 0}

    def problem(self, path: Path, line: int, what: str) -> None:
        self.problems.append(f"{path.relative_to(self.root)}:{line}: {what}")

    def doc(self, path: Path) -> Doc:
        path = path.resolve()
        if path not in self.docs:
            self.docs[path] = Doc(path)
        return self.docs[path]

    def files(self) -> list[Path]:
        files = [self.root / "README.md"]
        files += sorted((self.root / "docs" / "src").rglob("*.md"))
        return [f for f in files if f.exists()]

    # ---- links -------------------------------------------------------------------------------

    def check_links(self, path: Path) -> None:
        doc = self.doc(path)
        for n, line in doc.prose:
            text = CODE_SPAN.sub(lambda m: " " * len(m.group(0)), line)
            targets = [m.group(1) for m in LINK.finditer(text)]
            m = REF_DEF.match(text)
            if m:
                targets.append(m.group(1))
            for target in targets:
                self.counts["links"] += 1
                self.check_target(path, n, target)

    def check_target(self, path: Path, n: int, target: str) -> None:
        if re.match(r"^[a-zA-Z][a-zA-Z0-9+.-]*:", target):  # https:, mailto:, ...
            return
        file_part, _, anchor = target.partition("#")
        dest = (path.parent / file_part).resolve() if file_part else path.resolve()
        if not dest.exists():
            self.problem(path, n, f"broken link `{target}`: {file_part} does not exist")
            return
        if anchor:
            if dest.is_dir() or dest.suffix != ".md":
                self.problem(path, n, f"link `{target}`: an anchor needs a markdown file")
            elif anchor not in self.doc(dest).anchors:
                self.problem(path, n, f"link `{target}`: no heading with anchor #{anchor} in {file_part or 'this file'}")

    def check_summary(self) -> None:
        src = self.root / "docs" / "src"
        summary = src / "SUMMARY.md"
        if not src.exists():
            return
        if not summary.exists():
            self.problem(src, 0, "docs/src has no SUMMARY.md")
            return
        listed = set()
        for _, line in self.doc(summary).prose:
            for m in LINK.finditer(line):
                listed.add((src / m.group(1).partition("#")[0]).resolve())
        for chapter in sorted(src.rglob("*.md")):
            if chapter.name != "SUMMARY.md" and chapter.resolve() not in listed:
                self.problem(chapter, 1, "chapter not listed in docs/src/SUMMARY.md")

    # ---- code blocks and commands ------------------------------------------------------------

    def check_blocks(self, path: Path) -> None:
        doc = self.doc(path)
        if doc.unclosed:
            self.problem(path, doc.unclosed, "code block never closed")
        for start, lang, body in doc.blocks:
            self.counts["blocks"] += 1
            if not lang:
                self.problem(path, start, "code block without a language (use text, console, toml, rust, ...)")
                continue
            lang = lang.split(",")[0].split()[0].lower()
            if lang not in COMMAND_LANGS:
                continue
            for n, command in commands(lang, body, start):
                self.check_command(path, n, command)

    def check_command(self, path: Path, n: int, line: str) -> None:
        for simple in split_commands(line):
            try:
                tokens = shlex.split(simple, comments=False)
            except ValueError:
                tokens = simple.split()
            tokens = [t.strip("()") for t in tokens]
            tokens = [t for t in tokens if t]
            words = list(tokens)
            while words and re.match(r"^[A-Za-z_][A-Za-z0-9_]*=", words[0]):
                words.pop(0)  # environment assignments
            if not words:
                continue
            if words[0] == "cargo":
                self.check_cargo(path, n, words[1:])
            else:  # mcbench, also behind a wrapper: `time mcbench ...`, `valgrind ... target/release/mcbench ...`
                for i, t in enumerate(words):
                    if os.path.basename(t) == "mcbench":
                        self.check_mcbench(path, n, words[i + 1 :])
                        break
            for t in words:
                if t.startswith("scripts/") and not any(c in t for c in "*?$<"):
                    if not (self.root / t).exists():
                        self.problem(path, n, f"`{t}` does not exist")

    # mcbench

    @functools.cached_property
    def top_help(self) -> "Help":
        return Help(self.run_mcbench(["--help"]))

    @functools.lru_cache(maxsize=None)
    def sub_help(self, sub: str) -> "Help":
        return Help(self.run_mcbench([sub, "--help"]))

    @functools.lru_cache(maxsize=None)
    def listed(self, what: str) -> set[str]:
        """The ids `mcbench list <what>` prints (the first column of its table, header aside)."""
        rows = [line for line in self.run_mcbench(["list", what]).splitlines() if line.startswith("|")]
        return {row.split("|")[1].strip() for row in rows[2:]}

    def run_mcbench(self, args: list[str]) -> str:
        if not self.mcbench.exists():
            sys.exit(f"check_docs: {self.mcbench} does not exist: build it first (cargo build -p experiments)")
        env = dict(os.environ, NO_COLOR="1")
        env.pop("CLICOLOR_FORCE", None)
        res = subprocess.run([str(self.mcbench), *args], capture_output=True, text=True, env=env, timeout=120)
        if res.returncode != 0:
            sys.exit(f"check_docs: `mcbench {' '.join(args)}` failed: {res.stderr.strip()}")
        return res.stdout

    def check_mcbench(self, path: Path, n: int, args: list[str]) -> None:
        self.counts["mcbench"] += 1
        top = self.top_help
        sub = None
        if args and not args[0].startswith(("-", "[", "<")):
            sub = args[0]
            if sub not in top.subcommands:
                self.problem(path, n, f"`mcbench {sub}`: no such subcommand (known: {', '.join(sorted(top.subcommands))})")
                return
            args = args[1:]
        help_ = self.sub_help(sub) if sub else top
        label = f"mcbench {sub}" if sub else "mcbench"
        positional = []
        skip = False
        for tok in args:
            if skip:
                skip = False
                continue
            flags = FLAG.findall(tok)
            if flags:
                for flag in flags:
                    if flag not in help_.options:
                        self.problem(path, n, f"`{label}`: unknown flag {flag}")
                # `--seed N` and `[--seed N]`: the next word is the flag's value
                skip = bool(help_.options.get(flags[-1])) and "=" not in tok and not tok.endswith("]")
                continue
            positional.append(tok)
        self.check_positionals(path, n, sub, label, positional)

    def check_positionals(self, path: Path, n: int, sub: str | None, label: str, values: list[str]) -> None:
        def placeholder(v: str) -> bool:
            return v.startswith("<") or v.endswith("...") or v.isupper() or "<" in v or v.strip("[].") == ""

        for v in values:
            if placeholder(v):
                continue
            alternatives = v.strip("[]").split("|")
            if sub == "list":
                known = self.sub_help("list").possible_values
                bad = [a for a in alternatives if a not in known]
                if bad:
                    self.problem(path, n, f"`{label}`: {', '.join(bad)} is not one of {', '.join(known)}")
            elif sub == "run":
                for a in alternatives:
                    if a not in self.listed("experiments"):
                        self.problem(path, n, f"`{label}`: no experiment named {a} (see `mcbench list experiments`)")
            elif sub == "reference":
                for a in alternatives:
                    if a not in self.listed("testbeds"):
                        self.problem(path, n, f"`{label}`: no test bed named {a} (see `mcbench list testbeds`)")
                break  # only the first positional is a test bed

    # cargo

    @functools.lru_cache(maxsize=None)
    def cargo_help(self, sub: str) -> "Help | None":
        res = subprocess.run(["cargo", sub, "--help"], capture_output=True, text=True, cwd=self.cargo_dir)
        return Help(res.stdout) if res.returncode == 0 else None

    @functools.cached_property
    def workspace(self) -> dict[str, dict[str, set[str]]]:
        """Package name -> target kind -> target names."""
        res = subprocess.run(
            ["cargo", "metadata", "--no-deps", "--format-version", "1", "--offline"],
            capture_output=True,
            text=True,
            cwd=self.cargo_dir,
        )
        if res.returncode != 0:
            sys.exit(f"check_docs: cargo metadata failed: {res.stderr.strip()}")
        out: dict[str, dict[str, set[str]]] = {}
        for pkg in json.loads(res.stdout)["packages"]:
            kinds: dict[str, set[str]] = {}
            for t in pkg["targets"]:
                for k in t["kind"]:
                    kinds.setdefault(k, set()).add(t["name"])
            out[pkg["name"]] = kinds
        return out

    def check_cargo(self, path: Path, n: int, args: list[str]) -> None:
        if args and args[0].startswith("+"):
            args = args[1:]  # toolchain
        if not args or args[0].startswith("-"):
            return
        sub, args = args[0], args[1:]
        self.counts["cargo"] += 1
        help_ = self.cargo_help(sub)
        if help_ is None:
            self.problem(path, n, f"`cargo {sub}`: no such cargo subcommand")
            return
        rest: list[str] | None = None
        if "--" in args:
            i = args.index("--")
            args, rest = args[:i], args[i + 1 :]
        package, targets = None, []
        i = 0
        while i < len(args):
            tok = args[i]
            if tok.startswith("-"):
                name, eq, value = tok.partition("=")
                if re.match(r"^-[A-Za-z][^-]", name):  # a short flag with its value attached: -j2
                    name, value, eq = name[:2], name[2:], "="
                if name not in help_.options:
                    self.problem(path, n, f"`cargo {sub}`: unknown flag {name}")
                elif help_.options[name]:
                    if not eq:
                        i += 1
                        value = args[i] if i < len(args) else ""
                    if name in ("-p", "--package"):
                        package = value
                    elif name in ("--bin", "--example", "--test", "--bench"):
                        targets.append((name[2:], value))
            i += 1
        ws = self.workspace
        if package is not None and package not in ws:
            self.problem(path, n, f"`cargo {sub}`: no workspace package {package}")
            return
        for kind, name in targets:
            pkgs = [package] if package else list(ws)
            if not any(name in ws[p].get(kind, set()) for p in pkgs):
                self.problem(path, n, f"`cargo {sub}`: no {kind} target {name} in {package or 'the workspace'}")
        # after `--` the arguments are mcbench's, unless an example or another binary runs
        runs_other = any(kind == "example" or (kind == "bin" and name != "mcbench") for kind, name in targets)
        if sub == "run" and rest is not None and package in (None, "experiments", "my-estimator") and not runs_other:
            self.check_mcbench(path, n, rest)

    # ---- all ---------------------------------------------------------------------------------

    def run(self) -> list[str]:
        for f in self.files():
            self.counts["files"] += 1
            self.check_links(f)
            self.check_blocks(f)
        self.check_summary()
        return self.problems


class Help:
    """What a `--help` text lists: options (and whether each takes a value), subcommands, values."""

    def __init__(self, text: str):
        self.options: dict[str, bool] = {}
        self.subcommands: set[str] = set()
        self.possible_values: list[str] = []
        section = ""
        for line in text.splitlines():
            if line and not line[0].isspace():
                section = line.strip().rstrip(":").lower()
                continue
            if section == "commands":
                m = re.match(r"^\s+([a-z][a-z0-9-]*)", line)
                if m:
                    self.subcommands.add(m.group(1))
            m = re.match(r"^\s+(-[A-Za-z0-9])?(?:,\s+)?(--[A-Za-z0-9][A-Za-z0-9-]*)?(.*)$", line)
            if m and (m.group(1) or m.group(2)):
                takes_value = bool(re.match(r"^[ =]\[?<", m.group(3) or "")) or bool(
                    re.match(r"^\s+<", m.group(3) or "")
                )
                for opt in (m.group(1), m.group(2)):
                    if opt:
                        self.options[opt] = takes_value
            pv = re.search(r"\[possible values: ([^\]]+)\]", line)
            if pv:
                self.possible_values = [v.strip() for v in pv.group(1).split(",")]


def commands(lang: str, body: list[str], start: int):
    """(line number, command) of a console or sh block; `\\` continues a command on the next line."""
    current, first = None, 0
    for i, raw in enumerate(body, start + 1):
        line = raw.rstrip()
        if current is None:
            if lang == "console":
                if not line.startswith("$ "):
                    continue  # output
                line = line[2:]
            if not line.strip() or line.lstrip().startswith("#"):
                continue
            current, first = "", i
        line = strip_comment(line)
        if line.endswith("\\"):
            current += line[:-1] + " "
            continue
        yield first, current + line
        current = None
    if current:
        yield first, current


def strip_comment(line: str) -> str:
    """The line without a trailing `# comment` (a # after a blank, outside quotes)."""
    quote = None
    for i, ch in enumerate(line):
        if quote:
            if ch == quote:
                quote = None
        elif ch in "'\"":
            quote = ch
        elif ch == "#" and (i == 0 or line[i - 1].isspace()):
            return line[:i].rstrip()
    return line


def split_commands(line: str) -> list[str]:
    """Simple commands of a line: split at `&&`, `||`, `;` and a ` | ` pipe, outside quotes."""
    parts, cur, quote, i = [], "", None, 0
    while i < len(line):
        ch = line[i]
        if quote:
            quote = None if ch == quote else quote
        elif ch in "'\"":
            quote = ch
        elif line.startswith(("&&", "||"), i) or ch == ";" or (ch == "|" and line[i - 1 : i] == " "):
            parts.append(cur)
            cur = ""
            i += 2 if line.startswith(("&&", "||"), i) else 1
            continue
        cur += ch
        i += 1
    parts.append(cur)
    return [p.strip() for p in parts if p.strip()]


def self_test(mcbench: Path) -> int:
    """The checker on a small tree with one problem of each kind it must report."""
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        (root / "docs" / "src").mkdir(parents=True)
        (root / "docs" / "src" / "SUMMARY.md").write_text("# Summary\n\n- [A](a.md)\n")
        (root / "docs" / "src" / "a.md").write_text("# A chapter\n\n## Known heading\n")
        (root / "docs" / "src" / "orphan.md").write_text("# Orphan\n")
        (root / "README.md").write_text(
            "# Title\n\n"
            "[ok](docs/src/a.md#known-heading) [missing](docs/src/nope.md) [anchor](docs/src/a.md#unknown)\n\n"
            "```console\n$ mcbench run --quick --no-such-flag\n$ mcbench frobnicate\n"
            "$ cargo run --release -- list --params\n$ mcbench run no-such-experiment\n"
            "$ cargo test --workspace --no-such-cargo-flag\n```\n\n```\nunlabelled\n```\n"
        )
        problems = Checker(root, mcbench).run()
    expected = [
        "docs/src/nope.md does not exist",
        "no heading with anchor #unknown",
        "`mcbench run`: unknown flag --no-such-flag",
        "`mcbench frobnicate`: no such subcommand",
        "no experiment named no-such-experiment",
        "`cargo test`: unknown flag --no-such-cargo-flag",
        "code block without a language",
        "orphan.md:1: chapter not listed",
    ]
    missed = [e for e in expected if not any(e in p for p in problems)]
    extra = [p for p in problems if not any(e in p for e in expected)]
    for p in problems:
        print(f"self-test found: {p}")
    if missed or extra:
        print(f"check_docs self-test FAILED: missed {missed}, unexpected {extra}", file=sys.stderr)
        return 1
    print(f"check_docs self-test: all {len(expected)} planted problems found")
    return 0


def main() -> int:
    here = Path(__file__).resolve().parent.parent
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--root", type=Path, default=here, help="repository root (default: this script's)")
    ap.add_argument("--mcbench", type=Path, default=None, help="the mcbench binary whose --help is the truth")
    ap.add_argument("--self-test", action="store_true", help="check that the checker catches planted problems")
    args = ap.parse_args()
    target = Path(os.environ.get("CARGO_TARGET_DIR", here / "target"))
    mcbench = args.mcbench or Path(os.environ.get("MCBENCH", target / "debug" / "mcbench"))
    if args.self_test:
        return self_test(mcbench)
    checker = Checker(args.root, mcbench)
    problems = checker.run()
    for p in problems:
        print(p)
    if problems:
        print(f"check_docs: {len(problems)} problem(s)", file=sys.stderr)
        return 1
    c = checker.counts
    print(
        f"check_docs: {c['files']} files hold: {c['links']} links, {c['blocks']} code blocks, "
        f"{c['mcbench']} mcbench and {c['cargo']} cargo commands"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
