"""The inputs of the attack suite (`attack.py`, docs/attack.md):
namelist texts, geometry files, output paths and result files a user could give,
deterministically generated, each with what it may do.

Every attack is an :class:`Attack`: a name, its family, a ``setup`` that writes the
work folder and returns voiga's arguments (or post's), the exit codes allowed and,
for inputs that must be refused, words the message must contain. Oracles beyond
the exit code (inputs unchanged, results equal to the base case's, values recorded
as an independent parser reads them, geometry valid by an independent check) are
chosen by flags and applied by `attack.py`.
"""
from __future__ import annotations

import os
import random
import shutil
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np

from test_fuzz import BASE as FUZZ_BASE

REPO = Path(__file__).resolve().parents[2]
GEOMETRY = REPO / "cases" / "ironing" / "geometry.h5"

#: The base case (test_fuzz.py's): the ironing slab (3 x 1 elements, a VO layer)
#: pressed on a rigid plane and slid, frictional GPTS, natural damping, 4 steps.
BASE = FUZZ_BASE

ANY = frozenset({0, 1, 2, 3})
REFUSED = frozenset({2})
RUNS = frozenset({0})
Setup = Callable[[Path], list[str]]


@dataclass(frozen=True)
class Attack:
    """One input and what it may do."""

    family: str  # namelist | geometry | output | post
    name: str
    setup: Setup
    allowed: frozenset[int] = ANY
    #: words the error line must contain when the input is refused (exit 2)
    words: tuple[str, ...] = ()
    #: the run must give the base case's result bit for bit (a change of form only)
    same: bool = False
    #: compare the values the result records with an independent parse of the case
    semantic: bool = False
    #: a geometry voiga accepts must pass the independent check
    geometry: bool = False
    #: files of the work folder that must keep their bytes (besides case and geometry)
    protect: tuple[str, ...] = ()
    #: one of the issue's examples (always in the reduced set)
    example: bool = False
    #: files of the work folder that must not exist afterwards (nothing created through a link)
    absent: tuple[str, ...] = ()
    #: (name, other): the file at `name` afterwards must be `other`'s (kept as it was put there)
    same_as: tuple[tuple[str, str], ...] = ()
    #: what is done to the files while the run is stopped after its first step
    during: Callable[[Path], None] | None = None


def stage(work: Path, text: str = BASE, name: str = "case.nml") -> Path:
    """The work folder with the ironing geometry and the case `text`."""
    shutil.copy(GEOMETRY, work / "geometry.h5")
    case = work / name
    case.write_text(text)
    return case


def with_text(text: str, *args: str) -> Setup:
    def setup(work: Path) -> list[str]:
        return [str(stage(work, text).name), *args]
    return setup


def with_bytes(data: bytes, *args: str) -> Setup:
    def setup(work: Path) -> list[str]:
        case = stage(work)
        case.write_bytes(data)
        return [case.name, *args]
    return setup


# --- namelist: form ---------------------------------------------------------------------


def form_attacks() -> list[Attack]:
    """Changes of form only: the run must equal the base run bit for bit."""
    lines = BASE.splitlines()
    groups = [g.strip() + "\n/" for g in BASE.split("/\n") if g.strip()]
    out = []
    same = {
        "bom": b"\xef\xbb\xbf" + BASE.encode(),
        "crlf": BASE.replace("\n", "\r\n").encode(),
        "tabs": BASE.replace("  ", "\t").encode(),
        "one-line": " ".join(BASE.split()).encode(),
        "slash-and-group": BASE.replace("/\n&", "/ &").encode(),
        "upper-case": BASE.replace("&case", "&CASE").replace("&body", "&Body").encode(),
        "dollar-end": BASE.replace("&contact", "$contact").rsplit("/", 1)[0].encode() + b"$end\n",
        "amp-end": BASE.rsplit("/", 1)[0].encode() + b"&end\n",
        "comments": "\n".join(f"{line} ! a / & = ' comment" if "=" in line else line
                              for line in lines).encode(),
        "comment-lines": ("! head & / =\n" + BASE.replace("\n&", "\n! before & group /\n&")).encode(),
        "blank-lines": BASE.replace("\n", "\n\n").encode(),
        "trailing-blanks": "\n".join(line + "   " for line in lines).encode(),
        "no-final-newline": BASE.rstrip("\n").encode(),
        "commas": BASE.replace(",\n", "\n").encode(),
        "reversed-groups": "\n".join(reversed(groups)).encode() + b"\n",
    }
    for name, data in same.items():
        out.append(Attack("namelist", f"form/{name}", with_bytes(data, "--quiet"), RUNS, same=True,
                          example=name in ("bom", "one-line", "slash-and-group")))
    rng = random.Random(19)
    for k in range(6):
        order = groups[:]
        rng.shuffle(order)
        out.append(Attack("namelist", f"form/order-{k}", with_bytes(("\n".join(order) + "\n").encode(),
                                                                     "--quiet"), RUNS, same=True))
    return out


# --- namelist: structure ---------------------------------------------------------------


def structure_attacks() -> list[Attack]:
    """Broken structure: refused naming the line or the group."""
    out = []
    i_solver = BASE.index("&solver")
    i_dir = BASE.index("&dirichlet")
    dirichlet = BASE[i_dir:BASE.index("/", i_dir) + 1]
    refuse = {
        "stray-text": (BASE.replace("&solver", "n_steps = 4\n&solver"), ["text outside any namelist group"]),
        "stray-word": (BASE.replace("&solver", "solver\n&solver"), ["text outside"]),
        "missing-amp": (BASE.replace("&solver", "solver"), ["text outside"]),
        "unclosed-last": (BASE.rstrip().rstrip("/"), ["&contact", "is not closed"]),
        "unclosed-middle": (BASE[:i_solver].rstrip().rstrip("/") + "\n" + BASE[i_solver:],
                            ["is not closed with '/'"]),
        "lone-amp": (BASE.replace("&solver", "& solver"), ["does not start a namelist group"]),
        "amp-end-outside": ("&end\n" + BASE, ["does not start a namelist group"]),
        "unknown-group": (BASE + "&friction mu = 0.3 /\n", ["unknown namelist group &friction"]),
        "two-case": (BASE + BASE[:BASE.index("/") + 1], ["groups &case, &solver and &output may appear once each"]),
        "two-solver": (BASE + BASE[i_solver:BASE.index("/", i_solver) + 1],
                       ["groups &case, &solver and &output may appear once each"]),
        "no-case": (BASE[BASE.index("/") + 1:], ["group &case is missing"]),
        "duplicate-dirichlet": (BASE + dirichlet + "\n", ["both prescribe ux", "'top'"]),
        "duplicate-dirichlet-y": (BASE + dirichlet.replace("fix_x = .true., ", "").replace("ux = 0.0, 0.3, ", "")
                                  + "\n", ["both prescribe uy"]),
        "empty": ("", ["group &case is missing"]),
        "only-comments": ("! nothing\n! here\n", ["group &case is missing"]),
        "nul-bytes": (BASE.replace("&solver", "\x00\x00&solver"), ["text outside"]),
        "binary": ("\x89HDF\r\n\x1a\n" + BASE, ["text outside"]),
        "long-line": (BASE.replace("&solver", " " * 100000 + "x\n&solver"), ["text outside"]),
        "65-phases": (BASE.replace("n_steps = 2, 2", "n_steps = " + ", ".join(["1"] * 65)),
                      ["n_steps", "takes at most 64 values (65 given)"]),
        "100001-knots": (BASE.replace("nel_xi = 3,", "knots_xi = " + ", ".join(["0.5"] * 100001) + ","),
                         ["knots_xi", "takes at most 100000 values (100001 given)"]),
        "index-out-of-range": (BASE.replace("ux = 0.0, 0.3", "ux(65) = 1.0"), ["ux(65)", "index out of range"]),
        "unknown-variable": (BASE.replace("friction = 0.3", "friction = 0.3, mu = 0.3"),
                             ["unknown variable 'mu'"]),
        "case-in-string": (BASE.replace("'fuzz block'", "'&dirichlet body=x /'") + "\n&body", ["not closed"]),
    }
    for name, (text, words) in refuse.items():
        out.append(Attack("namelist", f"structure/{name}", with_text(text, "--check"), REFUSED, tuple(words),
                          example=name in ("65-phases", "100001-knots", "duplicate-dirichlet")))
    # accepted structure: a string holding group syntax, 64 phases
    ok = {
        "string-with-syntax": BASE.replace("'fuzz block'", "'a / &body $end ! x'"),
        "64-phases": BASE.replace("n_steps = 2, 2", "n_steps = " + ", ".join(["1"] * 64)).replace(
            "ux = 0.0, 0.3, uy = -0.03, -0.03", "ux = " + ", ".join(["0.0"] * 64) + ", uy = "
            + ", ".join(["-0.03"] * 64)),
        "repeat-count": BASE.replace("uy = -0.03, -0.03", "uy = 2*-0.03"),
        "indexed": BASE.replace("ux = 0.0, 0.3", "ux(2) = 0.3, ux(1) = 0.0"),
    }
    for name, text in ok.items():
        out.append(Attack("namelist", f"structure/{name}", with_text(text, "--quiet"), RUNS, semantic=True))
    return out


# --- namelist: values -----------------------------------------------------------------------

INTS = ["0", "-1", "1", "2", "21", "64", "100001", "2147483647", "2147483648", "-2147483648",
        "1.5", "'x'", ".true.", "1e3", ""]
REALS = ["0.0", "-0.0", "1e-320", "1e-300", "1e100", "1e101", "1e308", "-1.7976931348623157e308",
         "1.8e308", "NaN", "Infinity", "-Infinity", "'x'", ".true.", "1, 2", "-1.0", "0.5", "2.0", ""]
TEXTS = ["''", "' '", "'" + "x" * 32 + "'", "'" + "x" * 33 + "'", "'" + "y" * 5000 + "'", "slab",
         "'a''b'", "'&'", "'/'", "1", "'rigid'", "'slab'", "'top'", "'bottom'"]
LOGICALS = [".true.", ".false.", "T", "F", "1", "'yes'"]
#: (group, variable, values, with --check only): the variables of every group
VARIABLES = [
    ("case", "n_bodies", INTS, True), ("case", "title", TEXTS, True), ("case", "overwrite", LOGICALS, True),
    ("body", "name", TEXTS, True), ("body", "material", TEXTS + ["'linear'"], True),
    ("body", "youngs_modulus", REALS, False), ("body", "poisson_ratio", REALS + ["0.49999", "-0.99"], False),
    ("body", "degree_xi", INTS, True), ("body", "degree_eta", INTS, True), ("body", "nel_xi", INTS, True),
    ("body", "nel_eta", INTS, True), ("body", "layer_degree", INTS, True),
    ("body", "layer_elevations", INTS, True), ("body", "contact_edge", TEXTS, True),
    ("body", "basis", TEXTS + ["'linear'"], True), ("body", "knots_xi", ["0.5", "0.2, 0.4", "0.4, 0.2", "0.0",
                                                                       "1.0", "NaN", "0.5, 0.5"], True),
    ("solver", "n_steps", INTS + ["1500000000, 1500000000", "2, -1", "1000000", "1000001"], True),
    ("solver", "max_iterations", INTS, True), ("solver", "tol_residual", REALS, False),
    ("solver", "tol_energy", REALS, False), ("solver", "min_step_fraction", REALS + ["1e-12", "1e-13"], True),
    ("solver", "max_cuts", INTS, True), ("solver", "grow_iterations", INTS, True),
    ("solver", "n_gauss", INTS, True), ("solver", "predictor", LOGICALS, False),
    ("solver", "linear_solver", TEXTS + ["'multigrid'", "'direct'"], True),
    ("solver", "damping", TEXTS + ["'natural'", "'residual'"], True),
    ("dirichlet", "ux", REALS, False), ("dirichlet", "uy", REALS, False), ("dirichlet", "fix_x", LOGICALS, False),
    ("dirichlet", "edge", TEXTS, True), ("dirichlet", "body", TEXTS, True),
    ("contact", "penalty_normal", REALS, False), ("contact", "penalty_tangent", REALS, False),
    ("contact", "friction", REALS, False), ("contact", "rigid_normal", REALS + ["0.0, 0.0", "1.0, 1.0"], False),
    ("contact", "rigid_point", REALS, True), ("contact", "n_gauss", INTS, True),
    ("contact", "method", TEXTS + ["'mortar'", "'alm'"], True), ("contact", "master", TEXTS, True),
    ("contact", "tolerance", REALS, False), ("contact", "rigid_curve", TEXTS, True),
    ("contact", "rigid_ux", REALS + ["0.0, 0.1", "0.0, 0.1, 0.2"], False),
    ("contact", "rigid_uy", REALS + ["0.0, -0.01"], False),
    ("output", "fields", TEXTS + ["'stress'", "'von_mises', 'strain'", "'stress', 'stress'"], False),
    ("output", "samples", INTS, True), ("output", "every", INTS, True),
    ("output", "steps", INTS + ["1, 3", "3, 1", "4", "5"], True),
]


def set_value(text: str, group: str, name: str, value: str) -> str:
    """`text` with `name = value` in `group` (replacing the variable's assignment; a
    group the text lacks is added)."""
    if "&" + group not in text:
        text = text + f"&{group}\n/\n"
    i = text.index("&" + group)
    j = text.index("/\n", i)
    body = text[i:j]
    start = body.find(f" {name} =")
    if start < 0:
        body = body.rstrip() + f"\n  {name} = {value}\n"
    else:
        end = start + len(f" {name} =")
        rest = body[end:]
        stop = len(rest)
        for k, c in enumerate(rest):
            if c == "\n" or (c == "," and k + 1 < len(rest) and rest[k + 1:].lstrip()[:1].isalpha()
                             and "=" in rest[k + 1:].split(",")[0]):
                stop = k
                break
        body = body[:end] + " " + value + rest[stop:]
    return text[:i] + body + text[j:]


#: values whose run would be long (a huge mesh or step count): only checked, not run
LONG = {"64", "100001", "2147483647", "2147483648", "1e3", "1000000", "1000001", "1500000000, 1500000000",
        "21", "1e-300", "1e-320", "1e-12", "1e-13"}


def value_attacks() -> list[Attack]:
    """Every variable of every group set to values of its type and the wrong ones, in
    and out of range: run to the end (the result's recorded values compared with
    f90nml's reading of the case) unless the run would be long."""
    out = []
    for group, name, values, _ in VARIABLES:
        for k, value in enumerate(values):
            text = set_value(BASE, group, name, value)
            check_only = value in LONG and not (group == "dirichlet" or name in ("youngs_modulus", "poisson_ratio"))
            example = (group, name, value) in (("solver", "n_steps", "1500000000, 1500000000"),
                                               ("solver", "n_steps", "-1"),
                                               ("dirichlet", "uy", "-1.7976931348623157e308"))
            out.append(Attack("namelist", f"value/{group}.{name}={k}",
                              with_text(text, "--check" if check_only else "--quiet"),
                              REFUSED if example else ANY,
                              ("n_steps",) if example and name == "n_steps" else (), semantic=not check_only,
                              example=example))
    return out


def mutate(text: str, rng: random.Random) -> str:
    """One random change of the namelist text (test_fuzz.py's kinds, and more)."""
    lines = text.splitlines() or [""]
    kind = rng.randrange(8)
    i = rng.randrange(len(lines))
    if kind == 0:
        del lines[i]
    elif kind == 1:
        j = rng.randrange(len(lines))
        lines[i], lines[j] = lines[j], lines[i]
    elif kind == 2:
        lines.insert(i, lines[i])
    elif kind == 3:
        pos = rng.randrange(len(lines[i]) + 1)
        lines[i] = lines[i][:pos] + rng.choice(["&", "/", "=", "!", "'", '"', ",,", "\t", "$", "(", ")",
                                                 "*", "%", "é", "\x00"]) + lines[i][pos:]
    elif kind == 4:
        lines = lines[:i]
    elif kind == 5:
        pos = rng.randrange(len(lines[i]) + 1)
        lines[i] = lines[i][:pos] + lines[i][pos + rng.randrange(1, 6):]
    elif kind == 6:
        lines[i] = lines[i].upper() if rng.random() < 0.5 else lines[i] + " " + lines[rng.randrange(len(lines))]
    else:
        lines.insert(i, rng.choice(["/", "&", "&body", "/ &dirichlet body = 'slab' /", "n_steps = 3",
                                    "&solver n_steps = 1 /", "&contact /"]))
    return "\n".join(lines) + "\n"


def random_attacks(n: int = 180) -> list[Attack]:
    rng = random.Random(1919)
    out = []
    for k in range(n):
        text = BASE
        for _ in range(1 + rng.randrange(3)):
            text = mutate(text, rng)
        out.append(Attack("namelist", f"random/{k}", with_text(text, "--quiet"), ANY, semantic=True))
    return out


# --- geometry --------------------------------------------------------------------------------


def edit_geometry(edit: Callable[[h5py.File], None], *args: str) -> Setup:
    def setup(work: Path) -> list[str]:
        case = stage(work)
        with h5py.File(work / "geometry.h5", "r+") as f:
            edit(f)
        return [case.name, *args]
    return setup


def replace(key: str, data) -> Callable[[h5py.File], None]:
    def edit(f: h5py.File) -> None:
        g = f["bodies/slab"]
        del g[key]
        g[key] = data
    return edit


def transform(key: str, fn: Callable[[np.ndarray], object]) -> Callable[[h5py.File], None]:
    def edit(f: h5py.File) -> None:
        g = f["bodies/slab"]
        data = fn(g[key][()])
        del g[key]
        g[key] = data
    return edit


def geometry_attacks() -> list[Attack]:
    out = []
    kinds: dict[str, Callable[[np.ndarray], object]] = {
        "int32": lambda a: a.astype(np.int32), "int64": lambda a: a.astype(np.int64),
        "uint8": lambda a: np.abs(a).astype(np.uint8), "float32": lambda a: a.astype(np.float32),
        "float16": lambda a: a.astype(np.float16), "bool": lambda a: a.astype(bool),
        "str": lambda a: a.astype("S8"), "complex": lambda a: a.astype(complex),
        "compound": lambda a: np.array([(x,) for x in np.ravel(a)], dtype=[("v", "f8")]),
        "scalar": lambda a: np.ravel(a)[0], "rank-up": lambda a: a[np.newaxis],
        "rank-down": lambda a: np.ravel(a), "empty": lambda a: np.zeros((0,) * a.ndim),
        "shorter": lambda a: a[..., :-1], "longer": lambda a: np.concatenate([a, a[..., -1:]], axis=-1),
        "reversed": lambda a: a[::-1].copy(), "doubled": lambda a: a * 2, "negative": lambda a: -a,
        "nan": lambda a: np.where(np.arange(a.size).reshape(a.shape) == 0, np.nan, a.astype(float)),
        "inf": lambda a: np.where(np.arange(a.size).reshape(a.shape) == 0, np.inf, a.astype(float)),
        "huge": lambda a: a.astype(float) * 1e300, "tiny": lambda a: a.astype(float) * 1e-300,
        "zero": lambda a: np.zeros_like(a), "transposed": lambda a: a.T.copy(),
    }
    for key in ("degree", "knots_xi", "knots_eta", "control_points", "weights"):
        for kind, fn in kinds.items():
            out.append(Attack("geometry", f"dataset/{key}/{kind}", edit_geometry(transform(key, fn), "--check"),
                              geometry=True, example=(key, kind) in (("degree", "float32"), ("knots_xi", "str"))))
        out.append(Attack("geometry", f"dataset/{key}/missing", edit_geometry(lambda f, k=key: f["bodies/slab"]
                                                                              .__delitem__(k), "--check"),
                          REFUSED, (key,), geometry=True))
    # knot vectors of the slab elevated to degree 2 with 3 functions: [0 0 0 1 1 1]
    knots = {
        "p+2-start": [0, 0, 0, 0, 1, 1], "p+2-end": [0, 0, 1, 1, 1, 1], "p-start": [0, 0, 0.5, 1, 1, 1],
        "interior-p+1": [0, 0, 0, 0.5, 0.5, 0.5, 1, 1, 1], "not-0-1": [0, 0, 0, 2, 2, 2],
        "decreasing": [0, 0, 0.7, 0.3, 1, 1], "all-zero": [0, 0, 0, 0, 0, 0],
    }
    for name, vector in knots.items():
        n = len(vector) - 3
        def edit(f: h5py.File, vector=vector, n=n) -> None:
            g = f["bodies/slab"]
            cp = g["control_points"][()]
            xs = np.linspace(cp[0, 0, 0], cp[0, -1, 0], n)
            new = np.stack([np.stack([xs, np.full(n, cp[j, 0, 1])], axis=1) for j in range(cp.shape[0])])
            for key, data in (("degree", np.array([2, 1], dtype=np.int32)), ("knots_xi", np.array(vector, float)),
                              ("control_points", new), ("weights", np.ones(new.shape[:2]))):
                del g[key]
                g[key] = data
        out.append(Attack("geometry", f"knots/{name}", edit_geometry(edit, "--check"), geometry=True,
                          example=name == "p+2-start"))
    # maps that fold, flip or degenerate
    def corner(f: h5py.File, factor: float) -> None:
        g = f["bodies/slab"]
        cp = g["control_points"][()]
        cp[0, 0] = cp[-1, -1] + (cp[-1, -1] - cp[0, 0]) * factor
        del g["control_points"]
        g["control_points"] = cp
    for factor in (-0.9, -0.5, 0.2, 0.5, 1.0, 3.0):
        out.append(Attack("geometry", f"fold/corner-{factor}", edit_geometry(lambda f, x=factor: corner(f, x),
                                                                             "--quiet"),
                          geometry=True, example=factor == 0.5))
    for name, fn in {"clockwise": lambda a: a[:, ::-1].copy(), "collapsed": lambda a: a * 0 + 1.0,
                     "line": lambda a: np.stack([a[..., 0], a[..., 0]], -1)}.items():
        out.append(Attack("geometry", f"map/{name}", edit_geometry(transform("control_points", fn), "--quiet"),
                          geometry=True))
    # attributes and the file
    attrs = {"edge-int": 5, "edge-empty": "", "edge-long": "e" * 33, "edge-same": "bottom", "edge-utf8": "bödén"}
    for name, value in attrs.items():
        out.append(Attack("geometry", f"attr/{name}", edit_geometry(
            lambda f, v=value: f["bodies/slab"].attrs.__setitem__("edge_xi0", v), "--check"), geometry=True))
    files: dict[str, Callable[[Path], None]] = {
        "empty": lambda p: p.write_bytes(b""), "text": lambda p: p.write_text("geometry\n"),
        "truncated": lambda p: p.write_bytes(GEOMETRY.read_bytes()[:3000]),
        "folder": lambda p: (p.unlink(), p.mkdir()), "missing": lambda p: p.unlink(),
        "no-body": lambda p: h5py.File(p, "r+").__delitem__("bodies/slab"),
        "body-dataset": lambda p: _body_as_dataset(p),
    }
    for name, fn in files.items():
        def setup(work: Path, fn=fn) -> list[str]:
            case = stage(work)
            fn(work / "geometry.h5")
            return [case.name, "--check"]
        out.append(Attack("geometry", f"file/{name}", setup, REFUSED, ("geometry",)))
    return out


def _body_as_dataset(path: Path) -> None:
    with h5py.File(path, "r+") as f:
        del f["bodies/slab"]
        f["bodies/slab"] = np.zeros(3)


# --- output paths ------------------------------------------------------------------------------


def output_case(output: str, extra: str = "") -> str:
    return BASE.replace("output = 'out.h5'", f"output = '{output}'" + extra)


def output_attacks() -> list[Attack]:
    out = []

    def refused_output(name: str, output: str, words: tuple[str, ...], prep: Callable[[Path], None] | None = None,
                       args: tuple[str, ...] = (), example: bool = False) -> None:
        def setup(work: Path) -> list[str]:
            case = stage(work, output_case(output))
            (work / "sub").mkdir()
            (work / "other.h5").write_bytes(GEOMETRY.read_bytes())
            if prep:
                prep(work)
            return [case.name, "--quiet", *args]
        out.append(Attack("output", name, setup, REFUSED, words, protect=("other.h5",), example=example))

    for prefix in ("", "./", "sub/../", "sub/./../", "./sub//../", "absolute:"):
        for target, words in (("geometry.h5", ("is the geometry file",)), ("case.nml", ("is the case file",))):
            def prep(work: Path, t=target, p=prefix) -> None:
                if p == "absolute:":
                    text = (work / "case.nml").read_text().replace(f"'absolute:{t}'", f"'{(work / t).resolve()}'")
                    (work / "case.nml").write_text(text)
            refused_output(f"output/{prefix.rstrip(':') or 'plain'}-{target}", prefix + target, words, prep,
                           example=prefix == "" and target == "geometry.h5")
    for link, target in (("g-link.h5", "geometry.h5"), ("c-link.nml", "case.nml"), ("chain.h5", "g-link.h5"),
                         ("sub/up.h5", "../geometry.h5")):
        def prep(work: Path, link=link, target=target) -> None:
            if link == "chain.h5":
                (work / "g-link.h5").symlink_to("geometry.h5")
            (work / link).symlink_to(target)
        refused_output(f"output/symlink-{link.replace('/', '-')}", link, ("is the",), prep)
    # a hard link is another name of the same file: compared by identity, it is the geometry
    def hard(work: Path) -> None:
        os.link(work / "geometry.h5", work / "hard.h5")
    refused_output("output/hardlink-no-overwrite", "hard.h5", ("is the geometry file",), hard)

    def hard_overwrite(work: Path) -> list[str]:
        case = stage(work, output_case("hard.h5"))
        hard(work)
        return [case.name, "--quiet", "--overwrite"]
    # (compared by identity, issue 36: another name of the geometry is the geometry)
    out.append(Attack("output", "output/hardlink-overwrite", hard_overwrite, REFUSED, ("is the geometry file",)))
    long_geometry = "./" + "/" * 243 + "geometry.h5"
    refused_output("output/long-to-geometry", long_geometry, ("is the geometry file",), example=True)
    for name, output, words in (("dot", ".", ("is a folder",)), ("dotdot", "..", ("is a folder",)),
                                ("root", "/", ("is a folder",)), ("folder", "sub", ("is a folder",)),
                                ("trailing-slash", "new.h5/", ("new.h5/",)),
                                ("missing-folder", "none/out.h5", ("No such file or directory",)),
                                ("through-a-file", "case.nml/out.h5", ("Not a directory",)),
                                ("existing-result", "other.h5", ("exists", "not a voiga result", "--overwrite")),
                                ("too-long", "x" * 4200, ("longer than 4095",)),
                                ("part-of-geometry", "geometry", ("is the",))):
        prep = None
        if name == "part-of-geometry":
            def prep(work: Path) -> None:
                shutil.move(work / "geometry.h5", work / "geometry.part")
                text = (work / "case.nml").read_text().replace("geometry = 'geometry.h5'",
                                                               "geometry = 'geometry.part'")
                (work / "case.nml").write_text(text)
        refused_output(f"output/{name}", output, words, prep)
    for name, output in (("spaces", "my result.h5"), ("unicode", "résultat.h5"), ("deep", "a" * 250 + "/" + "b" * 250),
                         ("long-name", "n" * 250 + ".h5"), ("dots", "sub/../sub/./r.h5"), ("default", "")):
        def setup(work: Path, output=output) -> list[str]:
            if "/" in output and not output.startswith("sub"):
                (work / output.split("/")[0]).mkdir()
            (work / "sub").mkdir(exist_ok=True)
            text = output_case(output) if output else BASE.replace("output = 'out.h5', ", "")
            return [stage(work, text).name, "--quiet"]
        out.append(Attack("output", f"output/ok-{name}", setup, RUNS, same=True))
    # --dump
    for name, dump, words in (("geometry", "geometry.h5", ("is the geometry file",)),
                              ("case", "case.nml", ("is the case file",)),
                              ("result", "out.h5", ("is the result file",)),
                              ("result-dotted", "./sub/../out.h5", ("is the result file",)),
                              ("folder", "sub", ("is a folder",)), ("missing-folder", "none/d.h5", ("No such file",)),
                              ("empty", "", ("--dump needs a file name",))):
        def setup(work: Path, dump=dump) -> list[str]:
            case = stage(work)
            (work / "sub").mkdir()
            return [case.name, "--quiet", "--dump", dump]
        out.append(Attack("output", f"dump/{name}", setup, REFUSED, words, example=name == "geometry"))
    out += restart_attacks()
    return out


def restart_attacks() -> list[Attack]:
    out = []
    for name, target, words in (("geometry", "geometry.h5", ()), ("case", "case.nml", ()),
                                ("missing", "none.h5", ("does not exist",)), ("text", "notes.h5", ())):
        def setup(work: Path, target=target) -> list[str]:
            stage(work)
            (work / "notes.h5").write_text("notes\n")
            return ["--restart", target]
        out.append(Attack("output", f"restart/{name}", setup, REFUSED, words))
    for name, edit, allowed, words in (
            ("converged", None, REFUSED, ("the run converged",)),
            ("changed-case", "youngs_modulus = 1.0", REFUSED, ("has changed", "youngs_modulus: 2 in the case")),
            ("changed-steps", "n_steps = 2, 2", REFUSED, ("has changed", "n_steps")),
            ("same-case", "", RUNS, ())):
        def setup(work: Path, edit=edit) -> list[str]:
            from subprocess import run
            case = stage(work)
            run([os.environ["ATTACK_VOIGA"], case.name, "--quiet"], cwd=work, capture_output=True, timeout=120)
            if edit is not None:
                with h5py.File(work / "out.h5", "r+") as f:
                    f.attrs["status"] = np.bytes_("interrupted")
                    f.attrs["n_steps_done"] = np.int32(2)
                    for k in list(f["steps"]):
                        if int(k) > 2:
                            del f["steps"][k]
                if edit:
                    new = {"youngs_modulus = 1.0": "youngs_modulus = 2.0", "n_steps = 2, 2": "n_steps = 2, 3"}[edit]
                    case.write_text(case.read_text().replace(edit, new))
            return ["--restart", "out.h5", "--quiet"]
        # a restart reproduces the uninterrupted run bit for bit: the base case's result
        out.append(Attack("output", f"restart/{name}", setup, allowed, words, same=allowed == RUNS,
                          protect=("out.h5",) if allowed == REFUSED else (), example=name == "changed-case"))
    out.append(Attack("output", "restart/force-without-restart", with_text(BASE, "--force-restart"), REFUSED,
                      ("--force-restart needs --restart",)))
    return out


# --- post --------------------------------------------------------------------------------------


def post_attacks(result: Path) -> list[Attack]:
    """Result files that are not (whole) results, for every command of post."""
    data = result.read_bytes()
    files: dict[str, Callable[[Path], None]] = {
        "empty": lambda p: p.write_bytes(b""), "text": lambda p: p.write_text("a result\n"),
        "missing": lambda p: None,
    }
    for fraction in (0.05, 0.2, 0.5, 0.8, 0.99):
        files[f"truncated-{fraction}"] = lambda p, x=fraction: p.write_bytes(data[:int(len(data) * x)])
    rng = random.Random(7)
    for k in range(8):
        positions = [rng.randrange(len(data)) for _ in range(1 + k)]
        def flip(p: Path, positions=positions) -> None:
            b = bytearray(data)
            for i in positions:
                b[i] ^= 0xFF
            p.write_bytes(bytes(b))
        files[f"flipped-{k}"] = flip
    def edit(fn: Callable[[h5py.File], None]) -> Callable[[Path], None]:
        def make(p: Path) -> None:
            p.write_bytes(data)
            with h5py.File(p, "r+") as f:
                fn(f)
        return make
    files["no-status"] = edit(lambda f: f.attrs.__delitem__("status"))
    files["status-int"] = edit(lambda f: f.attrs.__setitem__("status", 3))
    files["no-bodies"] = edit(lambda f: f.__delitem__("bodies"))
    files["short-displacement"] = edit(lambda f: _shorten(f, "steps/000002/displacement"))
    files["running-partial"] = edit(lambda f: (f.attrs.__setitem__("status", np.bytes_("running")),
                                               f.attrs.__setitem__("n_steps_done", np.int32(2))))
    files["counter-beyond"] = edit(lambda f: f.attrs.__setitem__("n_steps_done", np.int32(99)))
    # issue 36: values no run writes, which post read as if they were results
    refused = {"nan-displacement": edit(lambda f: _poison(f, "steps/000002/displacement", np.nan)),
               "inf-reaction": edit(lambda f: _poison(f, "steps/000004/reactions", np.inf)),
               "nan-control-point": edit(lambda f: _poison(f, "bodies/slab/control_points", np.nan)),
               "negative-counter": edit(lambda f: f.attrs.__setitem__("n_steps_done", np.int32(-5))),
               "negative-planned": edit(lambda f: f.attrs.__setitem__("n_steps_planned", np.int32(-1)))}
    files.update(refused)
    out = []
    for name, make in files.items():
        for command in ("summary", "plot-contact", "history", "hertz", "plot-deformed", "vtk"):
            def setup(work: Path, make=make, command=command) -> list[str]:
                make(work / "bad.h5")
                return [command, "bad.h5"] + ([] if command == "summary" else ["--out", str(work)])
            out.append(Attack("post", f"post/{command}/{name}", setup,
                              REFUSED if name in refused else frozenset({0, 1, 2}),
                              example=(name in ("empty", "truncated-0.5") and command == "summary")
                              or (name == "nan-displacement" and command == "vtk")))
    return out


def _poison(f: h5py.File, key: str, value: float) -> None:
    data = f[key][()].astype(float)
    data.reshape(-1)[0] = value
    f[key][...] = data


def _shorten(f: h5py.File, key: str) -> None:
    data = f[key][()]
    del f[key]
    f[key] = data[:-1]


def all_attacks(result: Path | None = None) -> list[Attack]:
    """Every attack (the post family needs a finished result to damage)."""
    from attack_files import file_attacks

    attacks = form_attacks() + structure_attacks() + value_attacks() + random_attacks() + geometry_attacks() \
        + output_attacks() + file_attacks()
    if result is not None:
        attacks += post_attacks(result)
    return attacks
