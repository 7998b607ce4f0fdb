"""Stale mentions in the docs: repository paths, file names and code names that the pages
(README.md, docs/*.md) write but the tree no longer has.

`python3 test/python/check_docs.py` prints one line per stale mention, ``page:line:
what``, and exits 1 if there is any (`make lint` runs it; test_docs.py runs it on the
tree and on planted mistakes). What it checks, each chosen to have no false alarms:

- a path under a top-level folder of the repository (``src/``, ``app/``, ``test/``,
  ``pre/``, ``post/``, ``bench/``, ``cases/``, ``docs/``), in backticks or in plain
  text (plain text only when it ends in a file extension or ``/``, so that the prose
  "pre/post" is not a path); ``<placeholder>`` and ``*`` match any name, ``{a,b}`` each
  of its names, a trailing ``:line`` or ``::test`` is dropped. Generated folders
  (``build/``, ``results/``) and web addresses are not repository paths.
- a bare Fortran, C or Python file name in backticks (``newton.f90``): some file of the
  repository has that name.
- a code name in backticks: a snake_case identifier (``tresca_fixed_point``,
  ``n_steps``), a Fortran component chain (``pair%law%eps_n``), a call
  (``solve_steps(...)``) or a Python module path (``post.reader.read_result``) occurs
  in the sources (Fortran, C, Python, namelists, TOML, Makefile). Mathematical
  subscripts (``xi_0``, ``eta_j``: a part of one letter or only digits) are not code
  names, nor the few names of other libraries in ``EXTERNAL``.
- where a page ties names to a Fortran file, ``(`newton.f90`, `residual_floor`)``,
  ```src/contact/pair.f90` (`pair_zone`, ...)`` or ```pair_zone` in `pair.f90```,
  a file of that name defines them (as a module, procedure, type, or in a declaration):
  a procedure that moved makes its old file's mention stale, even where that file
  still calls it.
"""
from __future__ import annotations

import re
import subprocess
import sys
from collections.abc import Iterable
from fnmatch import fnmatch
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
TOP = ("src", "app", "test", "pre", "post", "bench", "cases", "docs")
SOURCE_SUFFIXES = (".f90", ".F90", ".c", ".h", ".py", ".nml", ".toml")
CODE_FILE = re.compile(r"^[A-Za-z0-9_.-]+\.(?:f90|F90|c|h|py)$")
# Names of other libraries the pages mention (OpenBLAS's kernel, splipy's internals).
EXTERNAL = {"dgemm_kernel", "raise_order_implicit"}

TICK = re.compile(r"`([^`\n]+)`")
TOPS = "|".join(TOP)
PATH = re.compile(rf"(?<![\w./~:-])(?:{TOPS})/[\w./*<>{{}},+-]*")
IDENT = r"[A-Za-z_][A-Za-z0-9_]*"
NAME = re.compile(rf"{IDENT}")
# `(file.f90, name, name)` or `file.f90` (`name`, `name`) or `name` in `file.f90`
FILE_FIRST = re.compile(r"\(`([\w/.-]+\.f90)`((?:,\s*`[^`\n]+`)+)")
FILE_THEN_LIST = re.compile(r"`([\w/.-]+\.f90)`\s*\(((?:`[^`\n]+`,?\s*)+)\)")
NAME_IN_FILE = re.compile(r"`([^`\n]+)`\s+in\s+`([\w/.-]+\.f90)`")


def repository_files(root: Path) -> list[str]:
    """The repository's files, relative to ``root`` (``git ls-files`` where there is a
    checkout: an untracked file of one developer's tree does not make a mention true)."""
    if (root / ".git").exists():
        out = subprocess.run(["git", "ls-files"], cwd=root, capture_output=True, text=True, check=True)
        return [f for f in out.stdout.splitlines() if (root / f).exists()]
    skip = {".git", "build", "results", "__pycache__"}
    return [str(p.relative_to(root)) for p in root.rglob("*")
            if p.is_file() and not skip.intersection(p.relative_to(root).parts)]


class Tree:
    """What the pages are checked against: the files, their folders and the words of
    the sources (every identifier of every Fortran, C, Python, namelist and TOML file)."""

    def __init__(self, root: Path) -> None:
        self.root = root
        self.files = repository_files(root)
        self.folders = {str(Path(f).parents[i]) for f in self.files for i in range(len(Path(f).parts) - 1)}
        self.names = {Path(f).name for f in self.files}
        self.text: dict[str, str] = {}
        words: set[str] = set()
        for f in self.files:
            if f.endswith(SOURCE_SUFFIXES) or Path(f).name == "Makefile":
                self.text[f] = (root / f).read_text(errors="replace")
                words.update(NAME.findall(self.text[f]))
        self.words = words

    def path_exists(self, path: str) -> bool:
        """A file or folder of the repository; placeholders and globs match any name,
        ``{a,b}`` needs each of its names."""
        return all(self._exists(alt) for alt in expand_braces(path.rstrip("/.,;")))

    def _exists(self, path: str) -> bool:
        pattern = re.sub(r"<[^>/]*>", "*", path)
        if "*" in pattern:
            return any(fnmatch(f, pattern) or fnmatch(f, pattern + "/*") for f in self.files)
        return pattern in self.folders or pattern in self.files

    def defined_in(self, file: str) -> set[str]:
        """The names that every Fortran file named like ``file`` (a path or a bare name)
        defines: its modules, procedures, types, and whatever its declarations (``::``)
        name, bindings and public lists included; not what it only uses or calls."""
        out: set[str] = set()
        for f, text in self.text.items():
            if f == file or f.endswith("/" + file):
                code = re.sub(r"!.*", "", text)
                code = re.sub(r"&\s*\n\s*&?", " ", code)
                for line in code.splitlines():
                    line = line.strip()
                    if re.match(r"use\b", line, re.I):
                        continue
                    m = re.match(rf".*?\b(?:subroutine|function|module|program|interface|type)\s+({IDENT})", line, re.I)
                    if m:
                        out.add(m.group(1))
                    if "::" in line:
                        out.update(NAME.findall(line.split("::", 1)[1]))
        return out


def expand_braces(path: str) -> list[str]:
    m = re.search(r"\{([^{}]*)\}", path)
    if not m:
        return [path]
    return [alt for part in m.group(1).split(",")
            for alt in expand_braces(path[:m.start()] + part + path[m.end():])]


def is_math(name: str) -> bool:
    """``xi_0``, ``eta_j``, ``X_j``, ``a_est``: a symbol with a subscript, not code."""
    parts = name.split("_")
    return any(len(p) == 1 or p.isdigit() for p in parts)


def code_names(span: str) -> list[str]:
    """The code names a backticked span stands for, or none if it is not one."""
    span = span.strip()
    call = re.fullmatch(rf"({IDENT})\(.*\)", span)
    if call:
        span = call.group(1)
    if re.fullmatch(rf"{IDENT}(?:%{IDENT})+", span):
        return span.split("%")
    if re.fullmatch(IDENT, span) and "_" in span.strip("_") and not span.startswith("__"):
        return [] if is_math(span) or span in EXTERNAL else [span]
    return []


def python_target(span: str, tree: Tree) -> str | None:
    """A stale ``pre.x``/``post.x.y``/``bench.x`` module path, else None."""
    if not re.fullmatch(rf"(?:pre|post|bench)(?:\.{IDENT})+", span):
        return None
    parts = span.split(".")
    for k in range(len(parts), 0, -1):
        base = "/".join(parts[:k])
        for f in (base + ".py", base + "/__init__.py"):
            if f in tree.text:
                rest = parts[k:k + 1]
                if rest and rest[0] not in NAME.findall(tree.text[f]):
                    return f"{span}: {f} has no {rest[0]}"
                return None
    return f"{span}: no such module"


def check_page(page: Path, tree: Tree) -> Iterable[str]:
    """``line: what`` for every stale mention of one page."""
    text = page.read_text()
    lines = text.splitlines()
    for n, line in enumerate(lines, 1):
        spans = TICK.findall(line)
        prose = TICK.sub(" ", line)
        for span in spans:
            for m in PATH.finditer(span):
                if m.start() == 0 or span[m.start() - 1] in " =(":
                    path = re.sub(r"(::\w+|:\d+(-\d+)?)$", "", m.group(0))
                    if not tree.path_exists(path):
                        yield f"{n}: {path}: no such file or folder"
            if CODE_FILE.match(span) and span not in tree.names:
                yield f"{n}: {span}: no file of that name"
            for name in code_names(span):
                if name not in tree.words:
                    yield f"{n}: {name}: not in the sources"
            stale = python_target(span, tree)
            if stale:
                yield f"{n}: {stale}"
        for m in PATH.finditer(re.sub(r"\w+://\S+", " ", prose)):
            path = re.sub(r"(::\w+|:\d+(-\d+)?)$", "", m.group(0)).rstrip(".,;:")
            if (path.endswith("/") or re.search(r"\.\w+$", path)) and not tree.path_exists(path):
                yield f"{n}: {path}: no such file or folder"
    yield from check_ties(text, tree)


def check_ties(text: str, tree: Tree) -> Iterable[str]:
    """Names a page places in a Fortran file that the file does not have."""
    def line_of(pos: int) -> int:
        return text.count("\n", 0, pos) + 1

    def tied(file: str, names: str, pos: int) -> Iterable[str]:
        if not any(f == file or f.endswith("/" + file) for f in tree.text):
            return  # a missing file is reported as such
        have = tree.defined_in(file)
        for span in TICK.findall(names):
            for name in code_names(span):
                if name in tree.words and name not in have:
                    yield f"{line_of(pos)}: {name}: not defined in {file}"

    for m in FILE_FIRST.finditer(text):
        yield from tied(m.group(1), m.group(2), m.start())
    for m in FILE_THEN_LIST.finditer(text):
        yield from tied(m.group(1), m.group(2), m.start())
    for m in NAME_IN_FILE.finditer(text):
        yield from tied(m.group(2), f"`{m.group(1)}`", m.start())


def stale_mentions(pages: Iterable[Path], root: Path = REPO) -> list[str]:
    """``page:line: what`` for every stale mention of ``pages``, in order."""
    tree = Tree(root)
    out = []
    for page in pages:
        shown = page.relative_to(root) if page.is_relative_to(root) else page
        found = sorted(set(check_page(page, tree)), key=lambda s: (int(s.split(":")[0]), s))
        out += [f"{shown}:{s}" for s in found]
    return out


def pages(root: Path = REPO) -> list[Path]:
    return [root / "README.md", *sorted((root / "docs").glob("*.md"))]


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    stale = stale_mentions([Path(a).resolve() for a in args] or pages())
    for s in stale:
        print(s)
    print(f"check_docs: {len(stale)} stale mention{'s' * (len(stale) != 1)}")
    return 1 if stale else 0


if __name__ == "__main__":
    sys.exit(main())
