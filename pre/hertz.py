"""A Hertz case for any cylinder (``python -m pre hertz``): the committed hertz scene
scaled to radius R, with the given E, nu and indentation, its arc mesh graded from the
expected contact half-width as the committed scene's is.

Geometry: the committed quarter annulus scaled by R (outer radius R, inner 0.05 R,
centre (0, 0), rigid flat y = -R). The mesh is the committed mesh m<k> graded from the
grading half-width ``a_g`` below as the committed one is from its 0.08 R: along the arc,
5 x 2^(k-1) elements over ``theta_c = asin(1.5 a_g / R)``; radially, 49 control points
with the surface element ``0.005 R x a_g / 0.08`` (the committed 0.005 R for the
committed indentation). Scaling the radial size with a keeps the contact zone resolved
alike in both directions: with the committed 0.005 R, an eighth of the committed
indentation (a = 0.023 R, m4 NN2.2, gpts, penalty 1e4 x 0.076 R / a) gave an L2 error of
1.03 % instead of 0.49 %. Loads: the top cut moves down by the indentation ``d`` (u_y = -d) in the
committed number of steps, u_x = 0 on the symmetry cut, frictionless contact with the
flat. The penalty, when the committed case gives one, is scaled by E / a_g (the
committed 1000 for E = 1, R = 1, a_g = 0.08): the penalty's own compliance, about
E* / (eps a) of the pressure, is then the committed one for any cylinder (scaled by
E / R only, m4 NN2.2 at a = 0.02 R gave 4.6 % instead of 1.7 %), and a case with the committed
d / R is the committed one in other units.

Expected half-width. In 2D the approach of a cylinder to a flat is not fixed by the
contact alone (the displacement of a half-plane under a line load grows like a
logarithm; it depends on where it is measured). We estimate it with the approach of the
cylinder's centre, ``d = P / (pi E*) (2 ln(4 R / a) - 1)``, which with Hertz's
``a^2 = 4 P R / (pi E*)`` becomes ``d / R = (a/R)^2 / 4 (2 ln(4 R / a) - 1)``,
independent of E and nu (:func:`expected_half_width`). On the committed scene
(d / R = 0.01) it gives a = 0.0760 R, the runs 0.0757 R (docs/howto.md has the other
indentations). The grading half-width is that estimate times the committed scene's
ratio ``HERTZ_A_EXP / expected_half_width(0.01) = 0.08 / 0.0760``, so the committed
indentation gives the committed knots exactly.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import dataclass
from itertools import pairwise
from pathlib import Path
from typing import Any

from scipy.optimize import brentq

from .cases import GEOMETRY_FILE, HERTZ_DISPLACEMENT, hertz_case, to_namelist_text
from .files import check_output, write_text
from .h5io import write_geometry
from .layouts import parse_layout
from .meshes import (
    HERTZ_A_EXP,
    HERTZ_H_SURFACE,
    HERTZ_R_IN,
    HERTZ_R_OUT,
    arc_parameter_exact,
    hertz_radial_elements,
    hertz_theta_c,
    mesh_level,
)
from .scenes import HERTZ, annular_sector
from .volume import check_volume

MAX_INDENTATION = 0.1
"""Largest indentation d / R accepted (exclusive): beyond it a / R > 0.3 and the
half-space theory is far from the cylinder."""
MAX_MESH_LEVEL = 6
"""Finest mesh (m6: 288 arc elements)."""
EDGE_BAND = (0.9, 1.1)
"""The arc elements overlapping this band of the expected half-width a are the ones
``--edge-refine`` splits (the estimate is within 0.5 % of the runs' a)."""
MAX_EDGE_REFINE = 16


class HertzCaseError(ValueError):
    """A value ``python -m pre hertz`` refuses, or an output it will not overwrite."""


def expected_half_width(indentation: float) -> float:
    """a / R for the indentation d / R: the root of ``(a/R)^2 / 4 (2 ln(4 R/a) - 1) =
    d / R`` (increasing in a/R on (0, 4/e)); see the module docstring."""
    if not 0.0 < indentation < MAX_INDENTATION:
        raise HertzCaseError(f"indentation / radius {indentation:g} outside (0, {MAX_INDENTATION:g})")

    def approach(x: float) -> float:
        return x * x / 4.0 * (2.0 * math.log(4.0 / x) - 1.0) - indentation
    return float(brentq(approach, 1e-12, 1.0, xtol=1e-15, rtol=1e-15))


def grading_half_width(indentation: float) -> float:
    """a_g / R, the half-width the arc mesh is graded from: the estimate scaled as the
    committed scene's (``HERTZ_A_EXP`` for the committed indentation)."""
    return HERTZ_A_EXP * (expected_half_width(indentation)
                          / expected_half_width(HERTZ_DISPLACEMENT / HERTZ_R_OUT))


@dataclass(frozen=True)
class Cylinder:
    """A Hertz problem: cylinder radius, material and indentation (consistent units)."""

    radius: float = HERTZ_R_OUT
    youngs_modulus: float = 1.0
    poisson_ratio: float = 0.3
    indentation: float = HERTZ_DISPLACEMENT

    def check(self) -> None:
        """HertzCaseError naming the first value out of range."""
        values = {"radius": self.radius, "youngs modulus": self.youngs_modulus,
                  "poisson ratio": self.poisson_ratio, "indentation": self.indentation}
        for name, v in values.items():
            if not math.isfinite(v):
                raise HertzCaseError(f"{name} {v!r} is not a finite number")
        if self.radius <= 0:
            raise HertzCaseError(f"radius {self.radius:g} must be > 0")
        if self.youngs_modulus <= 0:
            raise HertzCaseError(f"youngs modulus {self.youngs_modulus:g} must be > 0")
        if not -1.0 < self.poisson_ratio < 0.5:
            raise HertzCaseError(f"poisson ratio {self.poisson_ratio:g} must be in (-1, 0.5)")
        if not 0.0 < self.indentation < MAX_INDENTATION * self.radius:
            raise HertzCaseError(f"indentation {self.indentation:g} must be > 0 and < radius/10 "
                                 f"= {MAX_INDENTATION * self.radius:g}")

    @property
    def half_width(self) -> float:
        """Estimated contact half-width a (:func:`expected_half_width`)."""
        return self.radius * expected_half_width(self.indentation / self.radius)


def split_spans(knots: list[float], parameters: list[tuple[float, float]],
                factor: int) -> list[float]:
    """Interior knots with every span that overlaps one of the parameter intervals
    ``(t0, t1)`` split into ``factor`` equal parameter spans."""
    full = [0.0, *knots, 1.0]
    out: list[float] = []
    for k0, k1 in pairwise(full):
        n = factor if any(k1 > t0 and k0 < t1 for t0, t1 in parameters) else 1
        out.extend(k0 + (k1 - k0) * j / n for j in range(n))
    return out[1:]


def edge_refined_knots(knots: list[float], half_width: float, grading: float,
                       factor: int) -> list[float]:
    """The arc knots refined for a resolved edge: the spans that overlap the angles of
    :data:`EDGE_BAND` times ``half_width`` (a / R) from the lowest point, and the first
    coarse span beyond the graded zone (``grading`` = a_g / R; the zone's elements are
    up to 75 times smaller than it), each split into ``factor``."""
    t0, t1 = (arc_parameter_exact(math.asin(f * half_width)) for f in EDGE_BAND)
    tc = arc_parameter_exact(hertz_theta_c(grading))
    return split_spans(knots, [(t0, t1), (tc, tc + 1e-9)], factor)


def case_stem(mesh: str, layout: str, edge_refine: int = 1,
              surface_size: float | None = None) -> str:
    """``m4-NN2.2``; ``m4-NN2.2-edge4`` for a mesh refined at the edge, ``-surf0.02`` for
    a given surface size."""
    return (f"{mesh}-{layout}" + (f"-edge{edge_refine}" if edge_refine > 1 else "")
            + (f"-surf{surface_size:g}" if surface_size is not None else ""))


def cylinder_case(cyl: Cylinder, mesh: str, layout: str, n_steps: int | None = None,
                  method: str | None = None, penalty_normal: float | str | None = None,
                  edge_refine: int = 1, surface_size: float | None = None) -> dict[str, Any]:
    """The namelist groups of the Hertz case of ``cyl`` on ``mesh`` with ``layout``
    (:func:`pre.cases.hertz_case` scaled). ``penalty_normal``: None scales the committed
    one by E / a_g, ``'auto'`` leaves it out (voiga chooses), a number is written as is.
    ``edge_refine`` > 1 splits the arc elements around the expected edge of the zone and
    the first coarse one into that many (:func:`edge_refined_knots`). ``surface_size``:
    the radial size of the surface element relative to the expected a (None: scaled as
    the committed scene's, about a / 15)."""
    cyl.check()
    if not (isinstance(edge_refine, int) and 1 <= edge_refine <= MAX_EDGE_REFINE):
        raise HertzCaseError(f"edge refinement {edge_refine!r} must be an integer in "
                             f"1 .. {MAX_EDGE_REFINE}")
    try:
        level = mesh_level(mesh)
    except ValueError as err:
        raise HertzCaseError(str(err)) from None
    if not 1 <= level <= MAX_MESH_LEVEL:
        raise HertzCaseError(f"mesh {mesh!r}: levels m1 .. m{MAX_MESH_LEVEL}")
    try:
        parse_layout(layout)
    except ValueError as err:
        raise HertzCaseError(str(err)) from None
    r, e = cyl.radius, cyl.youngs_modulus
    a_g = grading_half_width(cyl.indentation / r)
    # at most uniform radially (d/R above about 0.093 would ask for a coarser surface)
    uniform = (HERTZ_R_OUT - HERTZ_R_IN) / hertz_radial_elements(parse_layout(layout).degree_eta)
    if surface_size is None:
        h_surface = HERTZ_H_SURFACE * (a_g / HERTZ_A_EXP)
    elif not 0.0 < surface_size <= 1.0:
        raise HertzCaseError(f"surface size {surface_size!r} must be in (0, 1] (a fraction "
                             f"of the expected half-width a)")
    else:
        h_surface = surface_size * cyl.half_width / r
    groups = hertz_case(mesh, layout, a_exp=a_g, h_surface=min(h_surface, uniform))
    groups["case"]["title"] = (f"hertz {mesh} {layout}: R = {r:g}, E = {e:g}, "
                               f"nu = {cyl.poisson_ratio:g}, indentation {cyl.indentation:g}")
    body = groups["body"][0]
    groups["case"]["output"] = f"{case_stem(mesh, layout, edge_refine, surface_size)}.h5"
    if edge_refine > 1:
        body["knots_xi"] = edge_refined_knots(body["knots_xi"], cyl.half_width / r, a_g, edge_refine)
        groups["case"]["title"] += f", arc elements at the edge split in {edge_refine}"
    if surface_size is not None:
        groups["case"]["title"] += f", surface element {surface_size:g} a"
    body["youngs_modulus"], body["poisson_ratio"] = float(e), float(cyl.poisson_ratio)
    for d in groups["dirichlet"]:
        if "uy" in d:
            d["uy"] = -float(cyl.indentation)
    contact = groups["contact"][0]
    contact["rigid_point"] = [0.0, -float(r)]
    if penalty_normal == "auto":
        contact.pop("penalty_normal", None)
    elif penalty_normal is not None:
        if not (isinstance(penalty_normal, (int, float)) and 0 < penalty_normal < math.inf):
            raise HertzCaseError(f"penalty_normal {penalty_normal!r} must be > 0 or 'auto'")
        contact["penalty_normal"] = float(penalty_normal)
    elif "penalty_normal" in contact:  # the committed compliance E*/(eps a)
        contact["penalty_normal"] = contact["penalty_normal"] * e / r * (HERTZ_A_EXP / a_g)
    if method is not None:
        contact["method"] = method
    if n_steps is not None:
        if n_steps < 1:
            raise HertzCaseError(f"steps {n_steps} must be >= 1")
        groups["solver"]["n_steps"] = int(n_steps)
    return groups


def cylinder_geometry(radius: float) -> dict[str, Any]:
    """The committed hertz body scaled by ``radius``."""
    scale = radius / HERTZ_R_OUT
    return {"cylinder": annular_sector(HERTZ["centre"], HERTZ_R_IN * scale, HERTZ_R_OUT * scale,
                                       [270, 360], {"xi0": "symmetry", "xi1": "top",
                                                    "eta0": "inner", "eta1": "outer"})}


def write_shared_geometry(folder: Path, write: Callable[[Path], None], cases: list[Path],
                          force: bool = False, other: str = "another cylinder") -> tuple[Path, bool]:
    """Write ``folder/geometry.h5`` with ``write(path)`` (a writer of the whole file) unless
    a file with the same bytes is there (kept: several meshes and layouts share it). The
    ``cases`` that exist, or a geometry file with other contents (``other`` says whose),
    are refused (HertzCaseError, nothing written) unless ``force``. Returns ``(geometry,
    written)``; the caller writes the cases after it."""
    geometry = check_output(folder / GEOMETRY_FILE)
    for case in cases:
        check_output(case)
    tmp = folder / f".{GEOMETRY_FILE}.{os.getpid()}.tmp"
    try:
        write(tmp)
        same = geometry.is_file() and geometry.read_bytes() == tmp.read_bytes()
        clash = [p for p, exists in ([(c, c.exists()) for c in cases]
                                     + [(geometry, geometry.exists() and not same)]) if exists]
        if clash and not force:
            raise HertzCaseError(" and ".join(map(str, clash))
                                 + (" exist" if len(clash) > 1 else " exists")
                                 + (f" (the geometry of {other})" if geometry in clash
                                    else "") + "; nothing written (--force to overwrite)")
        if not same:
            os.replace(tmp, geometry)
    finally:
        tmp.unlink(missing_ok=True)
    return geometry, not same


def write_scene3d_folder(out: str | Path, texts: dict[str, str], bodies: dict[str, Any],
                         geometry_file: Callable[[Path], None], force: bool = False,
                         other: str = "another scene") -> tuple[Path, list[Path], bool]:
    """The 3D scenes' writer: ``out/<stem>.nml`` for every ``texts`` (stem -> namelist
    text) after the shared ``out/geometry.h5`` (``geometry_file(path)`` writes it;
    :func:`write_shared_geometry`), each of ``bodies`` checked first
    (:func:`pre.volume.check_volume`). Refused as that function refuses. Returns
    ``(geometry, cases, geometry written)``."""
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    cases = [folder / f"{stem}.nml" for stem in texts]
    for name, vol in bodies.items():
        check_volume(name, vol)
    geometry, fresh = write_shared_geometry(folder, geometry_file, cases, force, other=other)
    for case, text in zip(cases, texts.values(), strict=True):
        write_text(case, text)
    return geometry, cases, fresh


def write_hertz_case(cyl: Cylinder, mesh: str, layout: str, out: str | Path,
                     force: bool = False, **options: Any) -> tuple[Path, Path, bool]:
    """Write ``out/geometry.h5`` and ``out/<mesh>-<layout>.nml`` (the committed layout).
    An existing case file, or a geometry file with other contents, is refused
    (HertzCaseError) unless ``force``; nothing is written then. A geometry file with the
    same contents is kept (several meshes and layouts of one cylinder share it).
    ``options``: :func:`cylinder_case`'s. Returns ``(geometry, case, geometry written)``."""
    text = to_namelist_text(cylinder_case(cyl, mesh, layout, **options))
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    case = folder / f"{case_stem(mesh, layout, options.get('edge_refine', 1), options.get('surface_size'))}.nml"

    def geometry_file(path: Path) -> None:
        write_geometry(path, "hertz", cylinder_geometry(cyl.radius),
                       generator="voiga pre (python -m pre hertz)")

    geometry, fresh = write_shared_geometry(folder, geometry_file, [case], force)
    write_text(case, text)
    return geometry, case, fresh
