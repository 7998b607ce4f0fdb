"""Study files (``python -m post study STUDY.toml``): which cases, which namelist changes.

A study file (TOML, read with the standard library's ``tomllib``) names its base cases,
either one case file (``base``) or a set of committed cases (``cases`` with the
``scenes``/``meshes``/``layouts`` filters of ``post sweep``), and the changes to apply to
each: a ``[grid]`` (every combination of its value lists) and/or a ``[[list]]`` (one
derived case per entry). A change names a namelist variable as ``group.variable``
(``contact.friction``), ``group[name].variable`` (``body[slab].youngs_modulus``: the
group whose ``name``, ``slave`` or ``body`` is ``slab``) or ``group[k].variable`` (the
k-th group of that name, from 1). Each derived case is written with f90nml; the
engine (``post/engine.py``) runs them. Paths in the file are relative to the file.
docs/studies.md is the how-to.
"""

from __future__ import annotations

import hashlib
import itertools
import math
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import f90nml

from pre.namelists import NAMELISTS

from .cost import MAX_REPEATS, ONCE, RepeatPolicy
from .measures import parse_file_measure
from .sweep import REPO, SUMMARY_COLUMNS, Run, find_cases

SELECTOR_KEYS = ("name", "slave", "body")
"""The variable a ``group[name]`` selector matches, first present wins (``&body``:
name; ``&contact``: slave; ``&dirichlet``/``&pressure``: body)."""

FIXED = {"case.output": "the engine names each case's result file",
         "case.geometry": "the geometry comes with the base case"}
"""Variables a study may not change, and why."""

KEYS = {"base", "cases", "scenes", "meshes", "layouts", "generate", "out", "timeout",
        "measures", "figures", "grid", "list", "repeats", "repeat_below"}
"""The top-level keys of a study file."""

_PATH = re.compile(r"^([A-Za-z_]\w*)(?:\[([^\]]+)\])?\.([A-Za-z_]\w*)$")


class StudyError(ValueError):
    """A study file that cannot be run; the message is one line naming the cause."""


@dataclass(frozen=True)
class Variable:
    """A namelist variable a study changes: ``group[selector].name``."""

    group: str
    selector: str | int | None
    name: str

    @property
    def path(self) -> str:
        sel = "" if self.selector is None else f"[{self.selector}]"
        return f"{self.group}{sel}.{self.name}"


def parse_variable(path: str, where: str = "study") -> Variable:
    """``'body[slab].youngs_modulus'`` -> Variable; StudyError for an unknown group or
    variable (namelist names are case-insensitive)."""
    m = _PATH.match(path.strip())
    if not m:
        raise StudyError(f"{where}: {path!r} is not group.variable, group[name].variable "
                         f"or group[k].variable")
    group, sel, name = m.group(1).lower(), m.group(2), m.group(3).lower()
    if group not in NAMELISTS:
        raise StudyError(f"{where}: {path}: no namelist group &{group} "
                         f"(known: {', '.join(NAMELISTS)})")
    if name not in NAMELISTS[group]:
        raise StudyError(f"{where}: {path}: &{group} has no variable {name!r} "
                         f"(known: {', '.join(sorted(NAMELISTS[group]))})")
    var = Variable(group, None if sel is None else (int(sel) if sel.strip().isdigit() else sel.strip()),
                   name)
    if f"{group}.{name}" in FIXED:
        raise StudyError(f"{where}: {path} cannot be changed: {FIXED[f'{group}.{name}']}")
    return var


def _groups(nml: f90nml.Namelist, group: str) -> list[f90nml.Namelist]:
    """The entries of a (possibly repeated) group, in file order."""
    if group not in nml:
        return []
    entries = nml[group]
    return list(entries) if isinstance(entries, list) else [entries]


def select(nml: f90nml.Namelist, var: Variable, where: str) -> f90nml.Namelist:
    """The one group entry ``var`` refers to; StudyError when there is none or it is
    ambiguous."""
    entries = _groups(nml, var.group)
    if not entries:
        raise StudyError(f"{where}: {var.path}: the case has no &{var.group} group")
    if var.selector is None:
        if len(entries) > 1:
            raise StudyError(f"{where}: {var.path}: the case has {len(entries)} &{var.group} "
                             f"groups; name one, e.g. {var.group}[1].{var.name}")
        return entries[0]
    if isinstance(var.selector, int):
        if not 1 <= var.selector <= len(entries):
            raise StudyError(f"{where}: {var.path}: the case has {len(entries)} &{var.group} "
                             f"group(s), no number {var.selector}")
        return entries[var.selector - 1]

    def label(entry: f90nml.Namelist) -> str | None:
        return next((str(entry[k]) for k in SELECTOR_KEYS if k in entry), None)

    hits = [e for e in entries if label(e) == var.selector]
    if len(hits) != 1:
        names = ", ".join(str(label(e)) for e in entries)
        how = "no" if not hits else f"{len(hits)}"
        raise StudyError(f"{where}: {var.path}: {how} &{var.group} named {var.selector!r} "
                         f"(the case has: {names})")
    return hits[0]


Changes = tuple[tuple[str, Any], ...]
"""A derived case's changes: (variable path, value) in study-file order (lists as
tuples, so that a change set can be a dict key)."""


def _frozen(value: Any) -> Any:
    return tuple(_frozen(v) for v in value) if isinstance(value, list) else value


def value_text(value: Any) -> str:
    """A value as the file names, titles and the table show it."""
    if isinstance(value, (list, tuple)):
        return ",".join(value_text(v) for v in value)
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)


MAX_STEM = 150
"""Longest case name from the changes; a longer one is replaced by a hash of it."""


def case_stem(base: str, changes: Changes) -> str:
    """``<base stem>+<path>=<value>+...`` (characters other than letters, digits and
    ``._,=+[]-`` become ``_``; a name longer than MAX_STEM becomes ``<base
    stem>+<12 hex digits of its SHA-1>``: the table's columns still say the values)."""
    if not changes:
        return base
    slug = "+".join(f"{path}={value_text(v)}" for path, v in changes)
    stem = base + "+" + re.sub(r"[^A-Za-z0-9._,=+\[\]-]", "_", slug)
    if len(stem) > MAX_STEM:
        stem = base + "+" + hashlib.sha1(slug.encode()).hexdigest()[:12]
    return stem


def parse_case(text: str, where: str) -> f90nml.Namelist:
    """A case file's namelist; StudyError when it is none or has no ``&case``."""
    try:
        nml = f90nml.reads(text)
    except Exception as err:  # f90nml raises plain ValueError/IndexError/... on bad text
        raise StudyError(f"{where}: not a namelist file ({err})") from None
    if "case" not in nml:
        raise StudyError(f"{where}: the case has no &case group")
    return nml


def derive(text: str, changes: Changes, stem: str, where: str,
           geometry: str = "geometry.h5") -> tuple[str, f90nml.Namelist]:
    """The case text with ``changes`` applied, ``&case output`` = ``<stem>.h5``,
    ``&case geometry`` = ``geometry`` (the engine puts the geometry file next to the
    case) and the changes appended to the title; also its namelist."""
    nml = parse_case(text, where)
    for path, value in changes:
        var = parse_variable(path, where)
        select(nml, var, where)[var.name] = list(value) if isinstance(value, tuple) else value
    case = nml["case"]
    case["output"] = f"{stem}.h5"
    case["geometry"] = geometry
    if changes:
        case["title"] = f"{case.get('title', stem)} ({', '.join(f'{p}={value_text(v)}' for p, v in changes)})"
    nml.indent = 2
    nml.end_comma = False
    nml.uppercase = False
    return str(nml) + "\n", nml


def lookup(nml: f90nml.Namelist, path: str) -> Any:
    """The value of a variable in a parsed case (None when it is not set)."""
    var = parse_variable(path)
    try:
        return select(nml, var, "").get(var.name)
    except StudyError:
        return None


@dataclass
class Study:
    """A parsed study file (or the ``post sweep`` flags)."""

    out: Path
    """Folder of the derived cases, their results, the table and the figures."""
    base: Path | None = None
    """One base case file, or None for the committed cases in ``cases``."""
    cases: Path = REPO / "cases"
    scenes: list[str] | None = None
    meshes: list[str] | None = None
    layouts: list[str] | None = None
    generate: bool = False
    """Build the cases scenes x meshes x layouts with ``pre.cases`` where none is committed."""
    grid: dict[str, list[Any]] = field(default_factory=dict)
    points: list[dict[str, Any]] = field(default_factory=list)
    """The ``[[list]]`` entries."""
    measures: dict[str, str] = field(default_factory=dict)
    """Column name -> measure read from the result file (:func:`post.measures.file_measure`)."""
    timeout: float = 3600.0
    figures: bool = True
    repeats: int = 1
    """Runs of each short case to time it (1: each case once)."""
    repeat_below: float = 3.0
    """A case is short when its first run took less CPU time than this (seconds)."""
    source: Path | None = None
    """The study file."""

    @property
    def where(self) -> str:
        return str(self.source) if self.source else "study"

    def policy(self) -> RepeatPolicy:
        """How the engine repeats the short cases: at least ``repeats`` runs, more (up
        to three times as many) while they took less than 1 CPU second together."""
        if self.repeats <= 1:
            return ONCE
        return RepeatPolicy(short_s=self.repeat_below, min_repeats=self.repeats, max_repeats=3 * self.repeats,
                            budget_s=1.0)

    def change_sets(self) -> list[Changes]:
        """Every combination of the grid, for every list entry (one empty change set
        when the study changes nothing)."""
        keys = list(self.grid)
        grid = [dict(zip(keys, combo, strict=True)) for combo in itertools.product(*self.grid.values())]
        sets = []
        for point in self.points or [{}]:
            for g in grid:
                both = set(point) & set(g)
                if both:
                    raise StudyError(f"{self.where}: {sorted(both)[0]} is both in [grid] and [[list]]")
                sets.append(tuple((k, _frozen(v)) for k, v in {**point, **g}.items()))
        return sets

    def parameters(self) -> list[str]:
        """The variable paths the study changes, in file order."""
        names = list(self.grid)
        for point in self.points:
            names += [k for k in point if k not in names]
        return names

    def base_runs(self) -> list[Run]:
        """The base cases (unchanged), as runs into ``out``."""
        if self.base is not None:
            if not self.base.is_file():
                raise StudyError(f"{self.where}: base case {self.base} does not exist")
            text = self.base.read_text()
            case = parse_case(text, f"{self.where}: base case {self.base}")["case"]
            scene = str(case.get("scene", self.base.parent.name))
            geometry = (self.base.parent / str(case.get("geometry", "geometry.h5"))).resolve()
            if not geometry.is_file():
                raise StudyError(f"{self.where}: base case {self.base}: no geometry file {geometry}")
            run = Run(scene, str(case.get("mesh", "")), str(case.get("layout", "")), self.base,
                      self.out / scene / f"{self.base.stem}.nml", geometry_file=geometry)
            run.text = derive(text, (), self.base.stem, self.where, geometry.name)[0]
            return [run]
        if not self.cases.is_dir():
            raise StudyError(f"{self.where}: no cases folder {self.cases}")
        if self.generate:
            return self._generated()
        runs = find_cases(self.cases, self.out, self.scenes, self.meshes, self.layouts)
        if not runs:
            raise StudyError(f"{self.where}: no committed case in {self.cases} matches "
                             f"scenes={self.scenes} meshes={self.meshes} layouts={self.layouts}")
        return runs

    def _generated(self) -> list[Run]:
        """scenes x meshes x layouts: the committed case where there is one, else one
        built by ``pre.cases.build_case``."""
        from pre.cases import build_case, to_namelist_text

        if not (self.scenes and self.meshes and self.layouts):
            raise StudyError(f"{self.where}: generate = true needs scenes, meshes and layouts")
        runs = []
        for scene, mesh, layout in itertools.product(self.scenes, self.meshes, self.layouts):
            path = self.cases / scene / f"{mesh}-{layout}.nml"
            run = Run(scene, mesh, layout, path, self.out / scene / path.name)
            if not path.is_file():
                if not (self.cases / scene / "geometry.h5").is_file():
                    raise StudyError(f"{self.where}: no geometry {self.cases / scene / 'geometry.h5'}")
                try:
                    run.text = to_namelist_text(build_case(scene, mesh, layout))
                except (KeyError, ValueError) as err:
                    raise StudyError(f"{self.where}: cannot build {scene} {mesh} {layout}: "
                                     f"{str(err).strip(chr(39))}") from None
            runs.append(run)
        return runs

    def runs(self) -> list[Run]:
        """Every derived case: the base cases times the change sets. Raises StudyError
        (before anything runs) for a change the base case cannot take."""
        params = self.parameters()
        runs = []
        for base in self.base_runs():
            text = base.text if base.text is not None else base.case.read_text()
            for changes in self.change_sets():
                if not changes:
                    runs.append(base)
                    continue
                stem = case_stem(base.work.stem, changes)
                derived, nml = derive(text, changes, stem, f"{self.where}: {base.label}",
                                      base.geometry.name)
                runs.append(Run(base.scene, base.mesh, base.layout, base.case,
                                base.work.with_name(f"{stem}.nml"), text=derived, changes=changes,
                                params={p: lookup(nml, p) for p in params},
                                geometry_file=base.geometry_file))
        return runs


MAX_TIMEOUT = 1e6
"""Longest time limit per case (seconds, about 11.6 days)."""


def timeout_problem(value: Any) -> str | None:
    """Why ``value`` is not a time limit in seconds (None when it is one: a finite
    number in (0, MAX_TIMEOUT])."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return f"must be a number of seconds, not {value!r}"
    if not (math.isfinite(value) and 0 < value <= MAX_TIMEOUT):
        return f"must be more than 0 and at most {MAX_TIMEOUT:g} seconds, not {value!r}"
    return None


def check_value(value: Any, where: str) -> None:
    """A value a study may give a namelist variable: a string, a boolean, an
    integer, a finite number, or a (non-nested) list of them; StudyError otherwise."""
    items = value if isinstance(value, list) else [value]
    for item in items:
        if isinstance(item, (str, bool, int)):
            continue
        if isinstance(item, float) and math.isfinite(item):
            continue
        what = ("a list inside a list" if isinstance(item, list) else f"{item!r}")
        raise StudyError(f"{where}: {what} is not a namelist value (strings, numbers, true/false, "
                         "or a list of them)")


def _list(value: Any, key: str, where: str) -> list[str] | None:
    if value is None:
        return None
    if isinstance(value, str):
        return [value]
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise StudyError(f"{where}: {key} must be a name or a list of names")
    return value


def _flatten(table: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    """TOML's dotted keys (``contact.friction = ...`` is a table ``contact``) back to
    ``'contact.friction'`` paths."""
    flat: dict[str, Any] = {}
    for key, value in table.items():
        path = f"{prefix}.{key}" if prefix else key
        if isinstance(value, dict):
            flat.update(_flatten(value, path))
        else:
            flat[path] = value
    return flat


def load_study(path: Path, out: Path | None = None) -> Study:
    """Parse and check a study file (everything but whether each change fits each base
    case, which :meth:`Study.runs` checks). ``out`` overrides the file's ``out``."""
    where = str(path)
    if not path.is_file():
        raise StudyError(f"no study file {path}")
    try:
        data = tomllib.loads(path.read_text())
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as err:
        raise StudyError(f"{where}: not a TOML file ({err})") from None
    unknown = sorted(set(data) - KEYS)
    if unknown:
        raise StudyError(f"{where}: unknown key {unknown[0]!r} (known: {', '.join(sorted(KEYS))})")
    here = path.resolve().parent

    def rel(value: Any, key: str) -> Path:
        if not isinstance(value, str):
            raise StudyError(f"{where}: {key} must be a path (a string)")
        return (here / value).resolve()

    study = Study(out=out or Path("results") / path.stem, source=path)
    if "out" in data and out is None:
        study.out = rel(data["out"], "out")
    if "base" in data:
        if any(k in data for k in ("cases", "scenes", "meshes", "layouts", "generate")):
            raise StudyError(f"{where}: give either base or cases/scenes/meshes/layouts, not both")
        study.base = rel(data["base"], "base")
    if "cases" in data:
        study.cases = rel(data["cases"], "cases")
    study.scenes = _list(data.get("scenes"), "scenes", where)
    study.meshes = _list(data.get("meshes"), "meshes", where)
    study.layouts = _list(data.get("layouts"), "layouts", where)
    for key in ("generate", "figures"):
        if key in data and not isinstance(data[key], bool):
            raise StudyError(f"{where}: {key} must be true or false, not {data[key]!r}")
    study.generate = bool(data.get("generate", False))
    study.figures = bool(data.get("figures", True))
    if "timeout" in data:
        problem = timeout_problem(data["timeout"])
        if problem:
            raise StudyError(f"{where}: timeout {problem}")
        study.timeout = float(data["timeout"])
    if "repeats" in data:
        if not isinstance(data["repeats"], int) or isinstance(data["repeats"], bool) or \
                not 1 <= data["repeats"] <= MAX_REPEATS:
            raise StudyError(f"{where}: repeats must be a whole number of runs, at least 1 and at most "
                             f"{MAX_REPEATS}")
        study.repeats = data["repeats"]
    if "repeat_below" in data:
        below = data["repeat_below"]
        if not isinstance(below, (int, float)) or isinstance(below, bool) or not 0 < below < float("inf"):
            raise StudyError(f"{where}: repeat_below must be a positive number of CPU seconds")
        study.repeat_below = float(below)
    grid = data.get("grid", {})
    if not isinstance(grid, dict):
        raise StudyError(f"{where}: grid must be a table ([grid])")
    for key, values in _flatten(grid).items():
        parse_variable(key, f"{where}: [grid]")
        if not isinstance(values, list) or not values:
            raise StudyError(f"{where}: [grid] {key} must be a non-empty list of values")
        for value in values:
            check_value(value, f"{where}: [grid] {key}")
        study.grid[key] = values
    points = data.get("list", [])
    if not isinstance(points, list) or not all(isinstance(p, dict) for p in points):
        raise StudyError(f"{where}: list must be an array of tables ([[list]])")
    for k, point in enumerate(points, start=1):
        flat = _flatten(point)
        for key, value in flat.items():
            parse_variable(key, f"{where}: [[list]] entry {k}")
            check_value(value, f"{where}: [[list]] entry {k}: {key}")
        study.points.append(flat)
    measures = data.get("measures", {})
    if isinstance(measures, list):
        measures = {str(m): m for m in measures}
    if not isinstance(measures, dict) or not all(isinstance(v, str) for v in measures.values()):
        raise StudyError(f"{where}: measures must be a list of measures or a table name = measure")
    for name, expr in measures.items():
        if name in SUMMARY_COLUMNS or name in study.parameters():
            raise StudyError(f"{where}: measure name {name!r} is a column of the table already; "
                             f"name it otherwise (measures = {{ my_name = {expr!r} }})")
        try:
            parse_file_measure(expr)
        except ValueError as err:
            raise StudyError(f"{where}: measure {name}: {err}") from None
    study.measures = dict(measures)
    return study
