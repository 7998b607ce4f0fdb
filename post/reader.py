"""Reading voiga result files (schema: ``docs/hdf5.md``).

This is the only module that opens result files. :func:`read_result` returns
plain dataclasses holding numpy arrays in *natural* order, whatever h5py
shows for the Fortran arrays:

- control points ``(ncp, nsd)``, reactions ``(n_dirichlet, nsd)``, element ranges
  ``(nel, 2 nsd)``, the bulk patch ``(n_eta, n_xi, 2)`` or volume ``(n_zeta, n_eta,
  n_xi, 3)`` (``docs/formats.md``), where nsd is the file's spatial dimension
  (:attr:`Result.dimension`: the root attribute ``dimension``, 2 in files written
  before voiga wrote it); a plane body's boundaries are its ``edges``, a solid's
  its ``faces`` (both read into :attr:`Body.edges`);
- every id is **0-based**: element connectivity, element pointers, edge or face
  control point ids, :attr:`Body.dof_offset` (the index of the body's first
  DOF in a step's global displacement vector);
- byte-string attributes are decoded to ``str`` (trailing blanks and NULs of
  Fortran fixed-length strings removed), scalar attributes to ``int`` /
  ``float``.

Files of runs that are still going (status ``'running'``) or that failed
(``'failed: <reason>'``) are read as well: they hold the converged steps
written so far. Only the steps the root attribute ``n_steps_done`` counts are
read (voiga updates it last, once a step is whole); a step group beyond it or
without its displacement (a run killed while writing it) is skipped with a
warning.

A running result is read safely (docs/hdf5.md, "Writing and reading a running
result"): :func:`open_result` holds a shared ``flock`` on the file while it is
open, so a read waits while voiga writes a step and never sees half of one,
whatever ``HDF5_USE_FILE_LOCKING`` says. A file that is not a readable voiga
result (empty, truncated, not HDF5, a group or dataset missing or malformed)
raises :class:`BadResultError` naming the file and the cause.

Step selection (:meth:`Result.select_step`, :func:`body_displacement`, the
``--step`` option of the command line): ``n >= 1`` is the step *number* (the
``step`` attribute), ``n < 0`` counts converged steps from the end (``-1`` is
the last one), ``0`` is the reference configuration (zero displacement).
"""

from __future__ import annotations

import errno
import fcntl
import os
import time
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from pre.h5io import read_curve, read_patch, read_volume
from pre.nurbs import Curve, Patch
from pre.volume import Volume

from .journal import recover
from .units import Units

LOCK_WAIT: float = 60.0
"""Seconds :func:`open_result` waits for a writer to finish a step."""

READ_ATTEMPTS: int = 3
"""Reads of a file that fail before :func:`read_result` calls it unreadable (voiga
writes a step anyway when a read holds the file longer than 30 s)."""


class BadResultError(ValueError):
    """A file that is not a readable voiga result; the message names it and the cause."""


def finite(values: np.ndarray, dataset: str) -> np.ndarray:
    """``values`` when every one is finite; BadResultError naming the dataset
    otherwise (voiga writes none: a file that holds a NaN displacement is damaged,
    and every figure or table made from it would be wrong)."""
    if not np.all(np.isfinite(values)):
        bad = int(np.size(values) - np.count_nonzero(np.isfinite(values)))
        raise BadResultError(f"{dataset} holds {bad} non-finite value(s) (NaN or Inf): "
                             "not a result voiga wrote")
    return values


def _named(path: Path, err: BadResultError) -> BadResultError:
    """``err`` with the file's name in front, unless it names it already."""
    return err if str(err).startswith(str(path)) else BadResultError(f"{path}: {err}")


AXES: tuple[str, ...] = ("x", "y", "z")
"""The names of the spatial axes; a file of dimension nsd uses ``AXES[:nsd]`` (as
voiga's ``axis_names``)."""

DIMENSIONS: tuple[int, ...] = (2, 3)
"""The spatial dimensions a result file may have (root attribute ``dimension``)."""


def dimension_of(path: Path, attrs: dict[str, Any]) -> int:
    """The spatial dimension of a result file from its root attributes ``attrs``: the
    attribute ``dimension``, 2 when the file has none (written before voiga wrote it,
    always 2D); BadResultError naming the file when it is not one of
    :data:`DIMENSIONS`."""
    nsd = attrs.get("dimension", 2)
    if not (isinstance(nsd, int) and nsd in DIMENSIONS):
        raise BadResultError(f"{path}: root attribute dimension = {nsd!r}: not a spatial "
                             f"dimension ({' or '.join(map(str, DIMENSIONS))})")
    return nsd


COUNTERS: tuple[str, ...] = ("n_steps_done", "n_steps_planned", "n_dofs", "n_cuts")
"""Root attributes that count something: never negative."""


def check_counters(path: Path, attrs: dict[str, Any]) -> None:
    """The root's counters are possible: integers >= 0, at most as many steps done
    as planned; BadResultError naming the attribute otherwise."""
    for key in COUNTERS:
        if key in attrs and not (isinstance(attrs[key], int) and attrs[key] >= 0):
            raise BadResultError(f"{path}: root attribute {key} = {attrs[key]!r}: not a count")
    done, planned = attrs.get("n_steps_done"), attrs.get("n_steps_planned")
    if done is not None and planned is not None and done > planned:
        raise BadResultError(f"{path}: root attribute n_steps_done = {done} exceeds "
                             f"n_steps_planned = {planned}")


STAGES: tuple[str, ...] = ("assembly", "contact", "factorization", "solve", "output")
"""Stages whose wall-clock seconds each step records (attrs ``seconds_<stage>``)."""


def decode(value: Any) -> Any:
    """An HDF5 attribute value as a Python ``str`` / ``int`` / ``float`` (or array)."""
    if isinstance(value, (bytes, np.bytes_)):
        return value.decode("ascii", errors="replace").rstrip("\x00 ")
    if isinstance(value, str):
        return value.rstrip("\x00 ")
    if isinstance(value, np.ndarray):
        if value.shape in ((), (1,)):
            return decode(value.reshape(-1)[0])
        if value.dtype.kind in "SO":
            return [decode(v) for v in value.reshape(-1)]
        return value
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.floating):
        return float(value)
    return value


def _attrs(obj: h5py.HLObject) -> dict[str, Any]:
    return {k: decode(v) for k, v in obj.attrs.items()}


@dataclass
class Surface:
    """A NURBS surface in space: the VO layer of a solid (``/bodies/<name>/layer`` of a
    file of dimension 3), over the bulk's first two directions (xi, eta)."""

    degree: tuple[int, int]
    knots_xi: np.ndarray
    knots_eta: np.ndarray
    control_points: np.ndarray
    """(n_eta n_xi, 3), xi fastest (the body's numbering of its layer points)."""
    weights: np.ndarray
    """(n_eta n_xi,)"""

    def __post_init__(self) -> None:
        self.degree = (int(self.degree[0]), int(self.degree[1]))
        self.knots_xi = np.asarray(self.knots_xi, dtype=float).reshape(-1)
        self.knots_eta = np.asarray(self.knots_eta, dtype=float).reshape(-1)
        self.control_points = np.asarray(self.control_points, dtype=float)
        self.weights = np.asarray(self.weights, dtype=float).reshape(-1)
        n_eta, n_xi = self.shape
        if n_xi < 1 or n_eta < 1 or self.control_points.shape != (n_xi * n_eta, 3) \
                or len(self.weights) != n_xi * n_eta:
            raise ValueError(f"layer surface: control_points {self.control_points.shape}, weights "
                             f"{self.weights.shape}, knots for {n_xi} x {n_eta} points")

    @property
    def shape(self) -> tuple[int, int]:
        """``(n_eta, n_xi)`` from the knot vectors."""
        return (len(self.knots_eta) - self.degree[1] - 1, len(self.knots_xi) - self.degree[0] - 1)


def _read_surface(g: h5py.Group) -> Surface:
    return Surface(degree=tuple(np.asarray(g["degree"][()]).reshape(-1)),  # type: ignore[arg-type]
                   knots_xi=g["knots_xi"][()], knots_eta=g["knots_eta"][()],
                   control_points=g["control_points"][()], weights=g["weights"][()])


@dataclass
class Body:
    """One body: its material, numbering, elements, edges (or faces) and discretization."""

    name: str
    material: str
    youngs_modulus: float
    poisson_ratio: float
    dof_offset: int
    """0-based index of the body's first DOF in the global displacement vector."""
    control_points: np.ndarray
    """(ncp, nsd) reference control points, body-local numbering (0-based row = id)."""
    weights: np.ndarray
    """(ncp,)"""
    element_ptr: np.ndarray
    """(nel + 1,) 0-based: element k uses ``element_conn[element_ptr[k]:element_ptr[k+1]]``."""
    element_conn: np.ndarray
    """0-based control point ids; per element: bulk tensor products (xi fastest), then layer."""
    element_ranges: np.ndarray
    """(nel, 2 nsd): xi_a, xi_b, eta_a, eta_b (, zeta_a, zeta_b) of each element."""
    element_vo: np.ndarray
    """(nel,) bool: True for a varying-order (contact row or layer) element."""
    edges: dict[str, np.ndarray]
    """Boundary name -> 0-based control point ids on it: the edges of a plane body,
    the faces of a solid (also :attr:`faces`)."""
    bulk: Patch | Volume
    """The refined bulk patch (contact edge at eta = 1), or of a solid the refined
    volume (contact face at zeta = 1)."""
    layer: Curve | Surface | None
    """The VO layer: a curve (plane body), a surface (solid), or None."""
    attrs: dict[str, Any] = field(default_factory=dict)
    """Every attribute of ``/bodies/<name>`` (decoded)."""
    nsd: int = 2
    """Spatial dimension: DOFs per control point (the file's ``dimension``)."""

    @property
    def ncp(self) -> int:
        """Number of control points."""
        return len(self.weights)

    @property
    def faces(self) -> dict[str, np.ndarray]:
        """A solid's faces (face name -> 0-based control point ids): :attr:`edges`."""
        return self.edges

    @property
    def boundary(self) -> str:
        """What a boundary of the body is called: ``'edge'`` or ``'face'``."""
        return "edge" if self.nsd == 2 else "face"

    @property
    def n_elements(self) -> int:
        """Number of elements."""
        return len(self.element_ptr) - 1

    @property
    def dofs(self) -> slice:
        """The body's DOFs in the global vector (the axes interleaved: x, y, (z,) x, y, ...)."""
        return slice(self.dof_offset, self.dof_offset + self.nsd * self.ncp)

    def element(self, k: int) -> np.ndarray:
        """0-based control point ids of element ``k`` (0-based)."""
        return self.element_conn[self.element_ptr[k]:self.element_ptr[k + 1]]


@dataclass
class Dirichlet:
    """A Dirichlet condition (``/dirichlet/<k>``), in case-file order."""

    body: str
    edge: str
    """The boundary it holds: an edge of a plane body, a face of a solid (voiga writes
    the face's name in the attribute ``edge`` too)."""


@dataclass
class ContactOutput:
    """Per-slave-point output of one contact pair at one step (``/steps/<k>/contact/<i>``)."""

    slave: str
    master: str
    force: np.ndarray
    """(nsd,) resultant contact force on the slave."""
    xi_slave: np.ndarray
    """(n,) slave points' parameters along the slave's contact edge."""
    x_ref: np.ndarray
    """(n, nsd) reference position of each slave point."""
    x: np.ndarray
    """(n, nsd) current position."""
    gap: np.ndarray
    """(n,) normal gap (negative: penetration), NaN where there is no projection."""
    p_n: np.ndarray
    """(n,) contact pressure (>= 0)."""
    p_t: np.ndarray
    """(n,) tangential traction along the master tangent."""
    xi_master: np.ndarray
    state: np.ndarray
    """(n,) 0 inactive, 1 stick (or frictionless contact), 2 slip."""
    attrs: dict[str, Any] = field(default_factory=dict)
    """Every attribute of the group (penalty_normal, penalty_tangent, friction, ...)."""
    rigid_point: np.ndarray | None = None
    """(2,) a point of a rigid master line (None for a deformable master)."""
    rigid_normal: np.ndarray | None = None
    """(2,) the rigid master line's unit outward normal."""
    rigid_curve: Curve | None = None
    """A rigid master bounded by a curve: the curve where it is at this step (the
    obstacle on its left, outward normal ``(a_y, -a_x)/|a|``; None otherwise)."""
    rigid_offset: np.ndarray | None = None
    """(2,) that curve's translation from its position at load time 0."""
    p_n_nominal: np.ndarray | None = None
    """(n,) contact pressure per *reference* length of the slave edge (``p_n`` times
    ``stretch``); None in files written before voiga wrote it."""
    p_t_nominal: np.ndarray | None = None
    """(n,) tangential traction per reference length; None in older files."""
    stretch: np.ndarray | None = None
    """(n,) current over reference length of the slave edge at each point; None in
    older files."""
    accuracy: dict[str, Any] | None = None
    """The contact-zone indicator voiga wrote (the ``accuracy`` group: its attributes and
    datasets by name, docs/hdf5.md); None in files written before it and on faces."""
    area_ref: np.ndarray | None = None
    """(n,) a solid's slave points: the reference area each point integrates (Gauss
    weight x reference surface Jacobian); None where the file has none (plane bodies)."""

    @property
    def active(self) -> np.ndarray:
        """(n,) bool: in contact."""
        return self.state > 0


_LAZY_FIELDS: tuple[str, ...] = ("time", "substeps", "residual_norms", "energy_norms",
                                  "displacement", "contact", "fields", "field_info")
"""The fields of a :class:`Step` that ``read_result(..., lazy=True)`` reads on first use."""


@dataclass(eq=False)
class Step:
    """One converged load step.

    ``step``, ``iterations``, ``cuts``, ``seconds`` and ``reactions`` are always read
    (they are what a sweep summary needs from every step); the other fields
    (``_LAZY_FIELDS``) are read with them by default, or on first access when the
    file was read with ``lazy=True`` (then all of them at once, from one reopening of
    the file).
    """

    step: int
    iterations: int
    reactions: np.ndarray
    """(n_dirichlet, nsd) resultant reaction (x, y, ...) of each Dirichlet condition."""
    seconds: dict[str, float]
    """stage (``STAGES``) -> wall-clock seconds."""
    cuts: int = 0
    """Times the step was cut (halved) before it converged."""
    iterations_total: int | None = None
    """Newton iterations of all substeps and failed attempts (None in older files)."""
    _data: dict[str, Any] = field(default_factory=dict, repr=False)
    """The lazy fields read so far."""
    _source: tuple[Path, str, int, int] | None = field(default=None, repr=False)
    """(file, step group name, n_dofs, spatial dimension) to read the lazy fields from."""

    def _get(self, key: str) -> Any:
        if key not in self._data:
            if self._source is None:
                raise AttributeError(f"step {self.step}: no {key} read and no file to read it from")
            path, name, n_dofs, nsd = self._source
            with _open(path) as f:
                try:
                    self._data.update(_read_step_details(f["steps"][name], name, nsd))
                except BadResultError as err:
                    raise _named(path, err) from None
            if len(self._data["displacement"]) != n_dofs:
                raise ValueError(f"{path}: step {self.step} displacement has "
                                 f"{len(self._data['displacement'])} entries, n_dofs = {n_dofs}")
        return self._data[key]

    @property
    def time(self) -> float:
        """Load time (phase k ends at time k)."""
        return float(self._get("time"))

    @property
    def substeps(self) -> int:
        """Substeps the adaptive load stepping used for this step."""
        return int(self._get("substeps"))

    @property
    def residual_norms(self) -> np.ndarray:
        """(iterations + 1,) ||r|| on free DOFs before each iteration and after the last."""
        return self._get("residual_norms")

    @property
    def energy_norms(self) -> np.ndarray:
        """(iterations,) |du . r| of each iteration."""
        return self._get("energy_norms")

    @property
    def displacement(self) -> np.ndarray:
        """(n_dofs,) control point displacements, global numbering, the axes interleaved
        (x, y, x, y, ... in 2D)."""
        return self._get("displacement")

    @property
    def contact(self) -> list[ContactOutput]:
        """One entry per contact pair, in case-file order."""
        return self._get("contact")

    @property
    def fields(self) -> dict[str, dict[str, np.ndarray]]:
        """Sampled solver fields: body -> dataset name -> array (``xi``, ``eta`` (and a
        solid's ``zeta``) (n,), ``element`` (n,) 0-based, ``stress`` and ``strain`` (n, 4)
        as [xx, yy, zz, xy], of a solid (n, 6) as [xx, yy, zz, xy, yz, xz], ``von_mises``
        (n,)), from ``/steps/<k>/fields/<body>``; empty at the steps without
        (``&output``; docs/hdf5.md)."""
        return self._get("fields")

    @property
    def field_info(self) -> dict[str, dict[str, Any]]:
        """The attributes of each body's sampled fields (``samples``, ``components``,
        ``stress_measure``, ``strain_measure``); empty at steps without fields."""
        return self._get("field_info")


@dataclass(eq=False)
class Result:
    """Everything in one result file. Compared and hashed by identity (a result
    can key a cache of values derived from it)."""

    path: Path
    attrs: dict[str, Any]
    """Every root attribute (decoded)."""
    bodies: dict[str, Body]
    """Bodies in global DOF order (increasing ``dof_offset``)."""
    dirichlet: list[Dirichlet]
    steps: list[Step]
    """Converged steps sorted by step number."""

    def _attr(self, key: str, default: Any = "") -> Any:
        return self.attrs.get(key, default)

    @property
    def title(self) -> str:
        return str(self._attr("title"))

    @property
    def status(self) -> str:
        """``'running'``, ``'converged'`` or ``'failed: <reason>'``."""
        return str(self._attr("status"))

    @property
    def scene(self) -> str:
        return str(self._attr("scene"))

    @property
    def mesh(self) -> str:
        return str(self._attr("mesh"))

    @property
    def layout(self) -> str:
        return str(self._attr("layout"))

    @property
    def case_file(self) -> str:
        return str(self._attr("case_file"))

    @property
    def voiga_version(self) -> str:
        return str(self._attr("voiga_version"))

    @property
    def n_dofs(self) -> int:
        return int(self._attr("n_dofs", 0))

    @property
    def dimension(self) -> int:
        """Spatial dimension (root attribute ``dimension``; 2 for files without it):
        the length of every spatial axis of the file's arrays."""
        return dimension_of(self.path, self.attrs)

    @property
    def axes(self) -> tuple[str, ...]:
        """Names of the spatial axes, ``('x', 'y')`` in 2D."""
        return AXES[:self.dimension]

    @property
    def n_steps_planned(self) -> int:
        return int(self._attr("n_steps_planned", 0))

    @property
    def n_steps_done(self) -> int:
        return int(self._attr("n_steps_done", 0))

    @property
    def wall_time(self) -> float:
        return float(self._attr("wall_time", 0.0))

    @property
    def units(self) -> Units:
        """The length and force units the root attribute ``units`` names (generic
        ``length`` / ``force`` when it names none; :mod:`post.units`)."""
        return Units.parse(str(self._attr("units")))

    @property
    def converged(self) -> bool:
        return self.status == "converged"

    @property
    def failed(self) -> bool:
        return self.status.startswith("failed")

    @property
    def failure_reason(self) -> str | None:
        """The reason after ``'failed: '``, or None when the run did not fail."""
        return self.status.partition(":")[2].strip() if self.failed else None

    def body(self, name: str | Body) -> Body:
        """The body called ``name`` (a :class:`Body` is returned as is)."""
        if isinstance(name, Body):
            return name
        try:
            return self.bodies[name]
        except KeyError:
            raise KeyError(f"no body {name!r} in {self.path} "
                           f"(bodies: {list(self.bodies)})") from None

    def select_step(self, step: int) -> Step | None:
        """Step ``step`` (>= 1: step number; < 0: from the end; 0: None = reference)."""
        if step == 0:
            return None
        if step < 0:
            if -step > len(self.steps):
                raise IndexError(f"{self.path}: step index {step} but only "
                                 f"{len(self.steps)} converged step(s) (status {self.status!r})")
            return self.steps[step]
        for s in self.steps:
            if s.step == step:
                return s
        raise IndexError(f"{self.path}: no converged step {step} ({_steps_text(self.steps)}, "
                         f"status {self.status!r}; -1 is the last)")

    def dirichlet_index(self, body: str, edge: str) -> int:
        """0-based index of the Dirichlet condition on ``body``'s ``edge``."""
        for k, d in enumerate(self.dirichlet):
            if d.body == body and d.edge == edge:
                return k
        raise KeyError(f"no Dirichlet condition on {body}/{edge}")


def _steps_text(steps: list[Step]) -> str:
    """Which steps a result has, in a few words: 'steps 1 to 25', 'steps 2, 5, 9'."""
    numbers = [s.step for s in steps]
    if not numbers:
        return "no converged step"
    if numbers == list(range(numbers[0], numbers[-1] + 1)):
        return f"steps {numbers[0]} to {numbers[-1]}" if len(numbers) > 1 else f"step {numbers[0]}"
    shown = ", ".join(map(str, numbers[:8]))
    return f"steps {shown}" + (f", ... {numbers[-1]}" if len(numbers) > 8 else "")


@contextmanager
def open_result(path: str | Path) -> Iterator[h5py.File]:
    """Open a result file read-only while holding a shared ``flock`` on it: voiga
    holds an exclusive one while it writes a step, so the file is read between
    steps, whole (waits at most :data:`LOCK_WAIT` seconds). Use it for your own
    h5py reads of a running result::

        with open_result("run.h5") as f:
            done = int(f.attrs["n_steps_done"])
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no result file {path}")
    recover(path)  # a flush its killed writer left half done (docs/hdf5.md)
    fd = os.open(path, os.O_RDONLY)
    try:
        deadline = time.monotonic() + LOCK_WAIT
        while True:
            try:
                fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
                break
            except OSError as err:
                if err.errno not in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EINTR):
                    break  # no locks on this file system: read as it is
                if time.monotonic() > deadline:
                    raise BadResultError(f"{path}: a writer has held the file for more than "
                                         f"{LOCK_WAIT:g} s") from None
                time.sleep(0.01)
        try:
            f = h5py.File(path, "r")
        except OSError as err:
            raise BadResultError(f"{path}: not a readable HDF5 file ({_cause(err)})") from None
        with f:
            yield f
    finally:
        os.close(fd)


def _cause(err: BaseException) -> str:
    """The useful part of an h5py/HDF5 error message (its first line)."""
    text = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
    return text.removeprefix("Unable to synchronously open file ").strip("() ") or text


_open = open_result


def _read_body(name: str, g: h5py.Group, nsd: int) -> Body:
    attrs = _attrs(g)
    cp = finite(np.asarray(g["control_points"][()], dtype=float), f"/bodies/{name}/control_points")
    if cp.ndim != 2 or cp.shape[1] != nsd:
        raise ValueError(f"/bodies/{name}/control_points: shape {cp.shape}, expected (ncp, {nsd})")
    ncp = len(cp)
    e = g["elements"]
    ptr = np.asarray(e["ptr"][()], dtype=np.int64) - 1
    conn = np.asarray(e["conn"][()], dtype=np.int64) - 1
    ranges = np.asarray(e["range"][()], dtype=float).reshape(-1, 2 * nsd)
    vo = np.asarray(e["vo"][()]).astype(bool)
    nel = len(ptr) - 1
    if ptr[0] != 0 or ptr[-1] != len(conn) or np.any(np.diff(ptr) <= 0):
        raise ValueError(f"/bodies/{name}/elements/ptr is not a valid 1-based pointer array")
    if len(ranges) != nel or len(vo) != nel:
        raise ValueError(f"/bodies/{name}/elements: {nel} elements in ptr but range "
                         f"{len(ranges)}, vo {len(vo)}")
    if len(conn) and (conn.min() < 0 or conn.max() >= ncp):
        raise ValueError(f"/bodies/{name}/elements/conn: ids outside 1..{ncp}")
    where = "edges" if nsd == 2 else "faces"  # a plane body's boundaries, a solid's
    edges = {k: np.asarray(v[()], dtype=np.int64).reshape(-1) - 1 for k, v in g[where].items()} \
        if where in g else {}
    if nsd == 2:
        bulk: Patch | Volume = read_patch(g["bulk"])
        layer: Curve | Surface | None = read_curve(g["layer"]) if "layer" in g else None
    else:
        bulk = read_volume(g["bulk"])
        layer = _read_surface(g["layer"]) if "layer" in g else None
    return Body(name=name, material=str(attrs.get("material", "")),
                youngs_modulus=float(attrs.get("youngs_modulus", np.nan)),
                poisson_ratio=float(attrs.get("poisson_ratio", np.nan)),
                dof_offset=int(attrs.get("dof_offset", 0)),
                control_points=cp,
                weights=finite(np.asarray(g["weights"][()], dtype=float).reshape(-1), f"/bodies/{name}/weights"),
                element_ptr=ptr, element_conn=conn, element_ranges=ranges, element_vo=vo,
                edges=edges, bulk=bulk, layer=layer, attrs=attrs, nsd=nsd)


_STEP_SCALARS: tuple[str, ...] = ("iterations", "iterations_total", "cuts") + \
    tuple(f"seconds_{k}" for k in STAGES)
"""The step attributes every read needs (the sweep summary's)."""

_INT_ATTRS = frozenset({"step", "iterations", "iterations_total", "cuts", "substeps"})
"""Integer step attributes (the others :func:`_scalar_attrs` reads are floats)."""


def _scalar_attrs(gid: h5py.h5g.GroupID, names: tuple[str, ...]) -> dict[str, int | float]:
    """The scalar numeric attributes ``names`` of a group (missing ones left out),
    read through h5py's low-level API into buffers of a fixed type: about 15 us an
    attribute, against about 100 us through ``Group.attrs`` (which builds a numpy
    dtype from the file's type for every attribute). This is most of the time of a
    sweep summary, which reads seven attributes of each of some 10^4 steps."""
    out: dict[str, int | float] = {}
    for name in names:
        try:
            aid = h5py.h5a.open(gid, name.encode())
        except KeyError:
            continue
        if name in _INT_ATTRS:
            ibuf = np.empty((), dtype=np.int64)
            aid.read(ibuf, mtype=h5py.h5t.NATIVE_INT64)
            out[name] = int(ibuf)
        else:
            fbuf = np.empty((), dtype=np.float64)
            aid.read(fbuf, mtype=h5py.h5t.NATIVE_DOUBLE)
            out[name] = float(fbuf)
    return out


def _read_array(gid: h5py.h5g.GroupID, name: str) -> np.ndarray | None:
    """A float dataset of a group as read by h5py (None when absent), through the
    low-level API (a fraction of the cost of ``group[name][()]``)."""
    if not gid.links.exists(name.encode()):
        return None
    did = h5py.h5d.open(gid, name.encode())
    buf = np.empty(did.shape, dtype=np.float64)
    did.read(h5py.h5s.ALL, h5py.h5s.ALL, buf, mtype=h5py.h5t.NATIVE_DOUBLE)
    return buf


def _read_step(name: str, gid: h5py.h5g.GroupID, n_dirichlet: int, path: Path, n_dofs: int,
               nsd: int, lazy: bool) -> Step | None:
    if not gid.links.exists(b"displacement"):
        warnings.warn(f"step group /steps/{name} has no displacement (incomplete); skipped",
                      stacklevel=3)
        return None
    a = _scalar_attrs(gid, _STEP_SCALARS)
    reactions = _read_array(gid, "reactions")
    reactions = np.zeros((0, nsd)) if reactions is None else finite(reactions.reshape(-1, nsd),
                                                                      f"/steps/{name}/reactions")
    if len(reactions) != n_dirichlet:
        raise ValueError(f"/steps/{name}/reactions: {len(reactions)} rows for "
                         f"{n_dirichlet} Dirichlet conditions")
    step = Step(step=int(name), iterations=int(a.get("iterations", 0)), reactions=reactions,
                seconds={k[len("seconds_"):]: float(v) for k, v in a.items()
                         if k.startswith("seconds_")},
                cuts=int(a.get("cuts", 0)),
                iterations_total=int(a["iterations_total"]) if "iterations_total" in a else None,
                _source=(path, name, n_dofs, nsd))
    if not lazy:
        step._data = _read_step_details(h5py.Group(gid), name, nsd)
    return step


def _read_step_details(g: h5py.Group, name: str, nsd: int) -> dict[str, Any]:
    """The lazy fields of a step (``_LAZY_FIELDS``) from its group (of a file of
    dimension ``nsd``)."""
    gid = g.id
    a = _scalar_attrs(gid, ("time", "substeps"))

    def vec(key: str) -> np.ndarray:
        return np.asarray(g[key][()], dtype=float).reshape(-1) if gid.links.exists(key.encode()) \
            else np.zeros(0)

    return {"time": float(a.get("time", np.nan)), "substeps": int(a.get("substeps", 1)),
            "residual_norms": vec("residual_norms"), "energy_norms": vec("energy_norms"),
            "displacement": finite(vec("displacement"), f"/steps/{name}/displacement"),
            "contact": [_read_contact(g["contact"][k], nsd) for k in sorted(g["contact"], key=int)]
            if gid.links.exists(b"contact") else [],
            "fields": {body: {k: _field_array(v) for k, v in fg.items()}
                       for body, fg in g["fields"].items()}
            if gid.links.exists(b"fields") else {},
            "field_info": {body: _attrs(fg) for body, fg in g["fields"].items()}
            if gid.links.exists(b"fields") else {}}


def _field_array(d: h5py.Dataset) -> np.ndarray:
    """A sampled-field dataset: ``element`` as 0-based ints, the rest as floats."""
    if d.name.rsplit("/", 1)[-1] == "element":
        return np.asarray(d[()], dtype=np.int64) - 1
    return np.asarray(d[()], dtype=float)


def _read_contact(g: h5py.Group, nsd: int) -> ContactOutput:
    a = _attrs(g)

    def vec(key: str) -> np.ndarray:
        return np.asarray(g[key][()], dtype=float).reshape(-1)

    def pts(key: str) -> np.ndarray:
        return finite(np.asarray(g[key][()], dtype=float).reshape(-1, nsd), f"{g.name}/{key}")

    # (the gap is NaN where a point has no projection onto its master: not checked)
    for key in ("force", "p_n", "p_t"):
        finite(vec(key), f"{g.name}/{key}")

    return ContactOutput(slave=str(a.get("slave", "")), master=str(a.get("master", "")),
                         force=vec("force"), xi_slave=vec("xi_slave"), x_ref=pts("x_ref"),
                         x=pts("x"), gap=vec("gap"), p_n=vec("p_n"), p_t=vec("p_t"),
                         xi_master=vec("xi_master"),
                         state=np.asarray(g["state"][()], dtype=int).reshape(-1), attrs=a,
                         rigid_point=vec("rigid_point") if "rigid_point" in g else None,
                         rigid_normal=vec("rigid_normal") if "rigid_normal" in g else None,
                         rigid_curve=read_curve(g["rigid_curve"]) if "rigid_curve" in g else None,
                         rigid_offset=vec("rigid_offset") if "rigid_offset" in g else None,
                         accuracy=_read_accuracy(g["accuracy"]) if "accuracy" in g else None,
                         **{k: vec(k) for k in ("p_n_nominal", "p_t_nominal", "stretch", "area_ref")
                            if k in g})


def _read_accuracy(g: h5py.Group) -> dict[str, Any]:
    """The ``accuracy`` group of a pair at a step: attributes and datasets by name."""
    out: dict[str, Any] = _attrs(g)
    out.update({k: np.asarray(v[()]) for k, v in g.items()})
    return out


def read_result(path: str | Path, lazy: bool = False) -> Result:
    """Read a result file (any status) into a :class:`Result`.

    ``lazy``: read of every step only what a sweep summary needs (step number,
    iterations, cuts, stage seconds, reactions) and the rest of a step (displacement,
    contact output, norms, load time, substeps) when it is first used, reopening the
    file then. The values are the same either way; a lazy step of a file that has
    changed since (a run still going) reads the changed file. A file that is not a
    readable result raises :class:`BadResultError` (or FileNotFoundError).
    """
    path = Path(path)
    for attempt in range(READ_ATTEMPTS):
        try:
            return _read_result(path, lazy)
        except BadResultError as err:
            raise _named(path, err) from None
        except FileNotFoundError:
            raise
        except (OSError, RuntimeError, KeyError, ValueError, TypeError, IndexError, AttributeError) as err:
            # a writer that had to stop waiting for a slow read changes the file
            # under it: read again; a damaged file fails every time
            if attempt + 1 == READ_ATTEMPTS:
                raise BadResultError(f"{path}: not a readable voiga result ({type(err).__name__}: "
                                     f"{_cause(err)})") from err
            time.sleep(0.2)
    raise AssertionError("unreachable")


def _read_result(path: Path, lazy: bool) -> Result:
    with _open(path) as f:
        attrs = _attrs(f)
        if "status" not in attrs:
            raise BadResultError(f"{path}: not a voiga result (no root attribute 'status')")
        check_counters(path, attrs)
        nsd = dimension_of(path, attrs)
        bodies = [_read_body(name, g, nsd) for name, g in f["bodies"].items()] if "bodies" in f else []
        bodies.sort(key=lambda b: b.dof_offset)
        n_dofs = int(attrs.get("n_dofs", 0)) or sum(nsd * b.ncp for b in bodies)
        dirichlet = []
        if "dirichlet" in f:
            for key in sorted(f["dirichlet"], key=int):
                a = _attrs(f["dirichlet"][key])
                dirichlet.append(Dirichlet(body=str(a.get("body", "")),
                                           edge=str(a.get("edge", ""))))
        done = int(attrs["n_steps_done"]) if "n_steps_done" in attrs else None
        steps = []
        if "steps" in f:
            sid = f["steps"].id
            for key in f["steps"]:
                if done is not None and int(key) > done:
                    warnings.warn(f"step group /steps/{key} is beyond n_steps_done = {done} "
                                  "(a step being or half written); skipped", stacklevel=3)
                    continue
                s = _read_step(key, h5py.h5g.open(sid, key.encode()), len(dirichlet), path,
                               n_dofs, nsd, lazy)
                if s is not None:
                    steps.append(s)
        steps.sort(key=lambda s: s.step)
    result = Result(path=path, attrs=attrs, bodies={b.name: b for b in bodies},
                    dirichlet=dirichlet, steps=steps)
    for b in bodies:
        if b.dof_offset < 0 or b.dofs.stop > n_dofs:
            raise ValueError(f"{path}: body {b.name!r} DOFs {b.dofs.start}..{b.dofs.stop - 1} "
                             f"outside 0..{n_dofs - 1}")
    if not lazy:
        for s in steps:
            if len(s.displacement) != n_dofs:
                raise ValueError(f"{path}: step {s.step} displacement has {len(s.displacement)} "
                                 f"entries, n_dofs = {n_dofs}")
    return result


def body_displacement(result: Result, body: str | Body, step: int = -1) -> np.ndarray:
    """(ncp, nsd) displacement of the control points of ``body`` at ``step``
    (step selection as in :meth:`Result.select_step`; 0 gives zeros)."""
    b = result.body(body)
    s = result.select_step(step)
    if s is None:
        return np.zeros((b.ncp, b.nsd))
    return s.displacement[b.dofs].reshape(b.ncp, b.nsd).copy()


def reaction_history(result: Result, k: int) -> tuple[np.ndarray, np.ndarray]:
    """``(times (n_steps,), reactions (n_steps, nsd))`` of Dirichlet condition
    ``k`` (0-based index into ``result.dirichlet``) over the converged steps."""
    if not -len(result.dirichlet) <= k < len(result.dirichlet):
        raise IndexError(f"Dirichlet index {k}: the file has {len(result.dirichlet)} condition(s)")
    times = np.array([s.time for s in result.steps], dtype=float)
    forces = np.array([s.reactions[k] for s in result.steps], dtype=float).reshape(-1, result.dimension)
    return times, forces
