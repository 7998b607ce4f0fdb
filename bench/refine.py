"""Hertz meshes beyond the committed m6: copy m6-N2 and insert the midpoint of every
knot span along xi and along eta (more radial knots), so each level has about 4x the
DOFs of the one before (m7 ~ 1.1e5, m8 ~ 4.5e5 DOFs). Also the parameter grids of the
peers' meshes (sections 5 and 6): the knot spans of a committed hertz mesh, each cut
``split`` times."""

from __future__ import annotations

import re

import numpy as np

from .run import ROOT, set_variable


def read_knots(text: str, name: str) -> np.ndarray:
    m = re.search(rf"^\s*{name}\s*=(.*?)(?=^\s*[A-Za-z_]\w*\s*=|^\s*/)", text, re.M | re.S)
    if m is None:
        raise KeyError(name)
    return np.array([float(v) for v in m.group(1).replace("\n", " ").split(",") if v.strip()])


def breakpoints(mesh: str) -> tuple[np.ndarray, np.ndarray]:
    """All knot values (ends included) along xi and eta of cases/hertz/<mesh>-N2.nml."""
    text = (ROOT / "cases" / "hertz" / f"{mesh}-N2.nml").read_text()
    kx, ke = read_knots(text, "knots_xi"), read_knots(text, "knots_eta")
    return np.concatenate([[0.0], kx, [1.0]]), np.concatenate([[0.0], ke, [1.0]])


def cut_spans(b: np.ndarray, split: int) -> np.ndarray:
    """Breakpoints ``b`` with every span cut into ``split`` equal parts."""
    t = np.linspace(0.0, 1.0, split + 1)[:-1]
    return np.append((b[:-1, None] + t * np.diff(b)[:, None]).ravel(), b[-1])


def splits(split: str) -> tuple[int, int]:
    """``'2'`` -> (2, 2), ``'3x1'`` -> (3, 1): cuts per knot span along xi and eta."""
    parts = [int(v) for v in str(split).split("x")]
    if len(parts) == 1:
        parts *= 2
    if len(parts) != 2 or min(parts) < 1:
        raise ValueError(f"split {split!r}: expected n or nxm with n, m >= 1")
    return parts[0], parts[1]


def split_grid(mesh: str, split: str = "1") -> tuple[np.ndarray, np.ndarray]:
    """The breakpoints of hertz <mesh> along xi and eta, every span cut as ``split`` says."""
    bx, be = breakpoints(mesh)
    sx, se = splits(split)
    return cut_spans(bx, sx), cut_spans(be, se)


def midpoints(interior: np.ndarray) -> np.ndarray:
    k = np.concatenate([[0.0], interior, [1.0]])
    mids = 0.5 * (k[:-1] + k[1:])
    return np.sort(np.concatenate([interior, mids]))


def format_list(values: np.ndarray, per_line: int = 4) -> str:
    items = [repr(float(v)) for v in values]
    lines = [", ".join(items[i:i + per_line]) for i in range(0, len(items), per_line)]
    return (",\n" + " " * 13).join(lines)


def refined_hertz_text(level: int) -> str:
    """Case text of hertz N2 at mesh ``m<level>`` (level >= 7), from m6-N2."""
    text = (ROOT / "cases" / "hertz" / "m6-N2.nml").read_text()
    kx, ke = read_knots(text, "knots_xi"), read_knots(text, "knots_eta")
    for _ in range(level - 6):
        kx, ke = midpoints(kx), midpoints(ke)
    text = set_variable(text, "knots_xi", format_list(kx))
    text = set_variable(text, "knots_eta", format_list(ke))
    text = set_variable(text, "mesh", f"'m{level}'")
    text = set_variable(text, "output", f"'m{level}-N2.h5'")
    return set_variable(text, "title", f"'hertz m{level} N2'")


def main(argv: list[str] | None = None) -> int:
    """``python -m bench.refine LEVEL [OUT.nml]``: write the hertz N2 case of mesh
    m<LEVEL> (next to cases/hertz/geometry.h5's copy, which the case names)."""
    import argparse
    import sys

    ap = argparse.ArgumentParser(prog="python -m bench.refine", description=main.__doc__)
    ap.add_argument("level", type=int, help="mesh level, >= 7")
    ap.add_argument("out", nargs="?", help="case file to write (default: m<level>-N2.nml)")
    args = ap.parse_args(argv)
    if args.level < 7:
        print("bench.refine: level must be >= 7 (m1..m6 are committed in cases/hertz)",
              file=sys.stderr)
        return 2
    out = args.out or f"m{args.level}-N2.nml"
    with open(out, "w") as fh:
        fh.write(refined_hertz_text(args.level))
    print(out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
