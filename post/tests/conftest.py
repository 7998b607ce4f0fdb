"""Fixtures: small result files written by the voiga binary in temporary
folders, and synthetic bodies (no binary needed) built with ``pre``.

The binary is ``$VOIGA_BIN``, else ``build/install/bin/voiga`` under the repo
root. Without it the tests that need a result file skip, except under CI
(``CI`` set), where they fail.
"""

from __future__ import annotations

import os
import shutil
import subprocess
from collections.abc import Callable
from pathlib import Path

import h5py
import numpy as np
import pytest

from post.reader import Body
from pre.refine import BodyDiscretization, discretize_case

REPO = Path(__file__).resolve().parents[2]
CASES = REPO / "cases"
TIMEOUT = 120  # seconds per run

NU = 0.3
STRAIN = 0.01  # slab stretch: u_x = STRAIN t x at load time t (right edge: 0.09 t)

SLAB = """&body
  name = 'slab', material = '{material}', youngs_modulus = 1.0, poisson_ratio = 0.3,
  degree_xi = 2, degree_eta = 2, nel_xi = 8, nel_eta = 2, contact_edge = 'top',
  layer_degree = 2, layer_elevations = 2
/
"""

STRETCH = """&case
  title = 'slab stretch', geometry = 'geometry.h5', output = 'stretch.h5', n_bodies = 1
/
""" + SLAB.format(material="linear") + """&solver
  n_steps = 2
/
&dirichlet
  body = 'slab', edge = 'left', fix_x = .true., ux = 0.0
/
&dirichlet
  body = 'slab', edge = 'bottom', fix_y = .true., uy = 0.0
/
&dirichlet
  body = 'slab', edge = 'right', fix_x = .true., ux = 0.09
/
"""

# Two bodies, two load phases: the die (no VO layer, curved, rational) is
# translated rigidly by its inner edge, (0.1, -0.05) then (0.2, -0.1); the
# slab (VO layer) is stretched as above, 0.09 then 0.18 at the right edge.
DIE_SHIFT = (0.2, -0.1)
TWO_BODIES = """&case
  title = 'die shift and slab stretch', scene = 'ironing', mesh = 'm1', layout = 'mixed',
  geometry = 'geometry.h5', output = 'two.h5', n_bodies = 2
/
&body
  name = 'die', material = 'linear', youngs_modulus = 10.0, poisson_ratio = 0.3,
  degree_xi = 2, degree_eta = 2, nel_xi = 6, nel_eta = 1, contact_edge = 'outer',
  layer_degree = 0
/
""" + SLAB.format(material="linear") + """&solver
  n_steps = 2, 1
/
&dirichlet
  body = 'die', edge = 'inner', fix_x = .true., fix_y = .true., ux = 0.1, 0.2, uy = -0.05, -0.1
/
&dirichlet
  body = 'slab', edge = 'left', fix_x = .true., ux = 0.0, 0.0
/
&dirichlet
  body = 'slab', edge = 'bottom', fix_y = .true., uy = 0.0, 0.0
/
&dirichlet
  body = 'slab', edge = 'right', fix_x = .true., ux = 0.09, 0.18
/
"""

# The stretch with its sampled fields (3 x 3 per element, every step).
STRETCH_FIELDS = STRETCH.replace("output = 'stretch.h5'", "output = 'fields.h5'") + """&output
  samples = 3
/
"""

# A rigid line pressed 0.01 into the slab's top in two steps (a rigid motion to magnify).
PRESS_LINE = """&case
  title = 'line press', geometry = 'geometry.h5', output = 'line.h5', n_bodies = 1
/
""" + SLAB.format(material="linear") + """&solver
  n_steps = 2
/
&dirichlet
  body = 'slab', edge = 'bottom', fix_x = .true., fix_y = .true.
/
&contact
  slave = 'slab', master = 'rigid', rigid_point = 0.0, 0.0, rigid_normal = 0.0, -1.0,
  rigid_uy = -0.01, penalty_normal = 100.0
/
"""

# A neo-Hookean slab pushed to less than nothing in phase 2: step 1 converges,
# step 2 inverts the elements, the run fails with exit code 3.
CRUSH = """&case
  title = 'slab crush', geometry = 'geometry.h5', output = 'crush.h5', n_bodies = 1
/
""" + SLAB.format(material="neo-hookean") + """&solver
  n_steps = 1, 1, max_iterations = 5
/
&dirichlet
  body = 'slab', edge = 'left', fix_x = .true., ux = 0.0, 0.0
/
&dirichlet
  body = 'slab', edge = 'bottom', fix_y = .true., uy = 0.0, 0.0
/
&dirichlet
  body = 'slab', edge = 'right', fix_x = .true., ux = 0.01, -10.0
/
"""


def exact_stretch(x: np.ndarray, time: float) -> np.ndarray:
    """Exact displacement of the linear (plane strain) slab stretch at ``x`` (..., 2)."""
    x = np.asarray(x, dtype=float)
    ux = STRAIN * time * x[..., 0]
    uy = -NU / (1 - NU) * STRAIN * time * (x[..., 1] + 3.0)
    return np.stack([ux, uy], axis=-1)


def _voiga_bin() -> Path | None:
    env = os.environ.get("VOIGA_BIN")
    path = Path(env) if env else REPO / "build" / "install" / "bin" / "voiga"
    return path if path.is_file() and os.access(path, os.X_OK) else None


@pytest.fixture(scope="session")
def voiga() -> Path:
    """The voiga binary (skip without it; fail under CI)."""
    path = _voiga_bin()
    if path is None:
        where = os.environ.get("VOIGA_BIN") or "build/install/bin/voiga"
        _skip_or_fail(f"voiga binary not found ({where}); run `make build` or set VOIGA_BIN")
    return path


def _skip_or_fail(msg: str) -> None:
    if os.environ.get("CI"):
        pytest.fail(msg)
    pytest.skip(msg)


def run_case(voiga: Path, folder: Path, text: str, output: str, expect: int = 0,
             geometry: Callable[[Path], object] | None = None) -> Path:
    """Write ``case.nml`` and the geometry (the ironing scene's, or what ``geometry``
    writes at the path it is given) into ``folder``, run ``voiga case.nml --quiet``
    there, check the exit code; returns the result file. A binary built before the
    solver existed skips (fails under CI)."""
    folder.mkdir(parents=True, exist_ok=True)
    if geometry is None:
        shutil.copy(CASES / "ironing" / "geometry.h5", folder / "geometry.h5")
    else:
        geometry(folder / "geometry.h5")
    (folder / "case.nml").write_text(text)
    run = subprocess.run([str(voiga), "case.nml", "--quiet"], cwd=folder, capture_output=True,
                         text=True, timeout=TIMEOUT, stdin=subprocess.DEVNULL)
    if run.returncode != expect and "solving is not available" in run.stdout + run.stderr:
        _skip_or_fail(f"{voiga} has no solver (stale build): run `make build` or set VOIGA_BIN")
    if run.returncode != expect:
        pytest.fail(f"voiga exit code {run.returncode} (expected {expect}) in {folder}:\n"
                    f"{run.stdout[-2000:]}\n{run.stderr[-2000:]}")
    path = folder / output
    assert path.is_file(), f"voiga wrote no {output} in {folder}"
    return path


@pytest.fixture(scope="session")
def stretch_h5(voiga: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Result of the one-body slab stretch (VO layer, 2 steps, converged)."""
    return run_case(voiga, tmp_path_factory.mktemp("stretch"), STRETCH, "stretch.h5")


@pytest.fixture(scope="session")
def fields_h5(voiga: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The slab stretch with stress, strain and von Mises at 3 x 3 points per element."""
    return run_case(voiga, tmp_path_factory.mktemp("fields"), STRETCH_FIELDS, "fields.h5")


@pytest.fixture(scope="session")
def line_h5(voiga: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A rigid line moved 0.01 down into the slab (2 steps)."""
    return run_case(voiga, tmp_path_factory.mktemp("line"), PRESS_LINE, "line.h5")


@pytest.fixture(scope="session")
def two_h5(voiga: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Result of the two-body case (die without layer, slab with one; 3 steps)."""
    return run_case(voiga, tmp_path_factory.mktemp("two"), TWO_BODIES, "two.h5")


@pytest.fixture(scope="session")
def crush_h5(voiga: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Result of a run that fails at step 2 (status 'failed: ...', 1 step)."""
    return run_case(voiga, tmp_path_factory.mktemp("crush"), CRUSH, "crush.h5", expect=3)


@pytest.fixture()
def running_h5(two_h5: Path, tmp_path: Path) -> Path:
    """The two-body result as a run still going after step 1 would leave it
    (status 'running', steps 2 and 3 not written yet, n_steps_done = 1)."""
    path = tmp_path / "running.h5"
    shutil.copy(two_h5, path)
    with h5py.File(path, "r+") as f:
        f.attrs["status"] = np.bytes_(b"running")
        f.attrs["n_steps_done"] = np.int32(1)
        del f["steps/000002"], f["steps/000003"]
    return path


def synthetic_body(name: str, disc: BodyDiscretization) -> Body:
    """A :class:`Body` from a ``pre`` discretization, numbered as voiga does
    (bulk rows xi fastest, the last row replaced by the layer when there is
    one); no elements or edges."""
    bulk, layer = disc.bulk, disc.layer
    rows = bulk.shape[0] - (layer is not None)
    cp = bulk.control_points[:rows].reshape(-1, 2)
    w = bulk.weights[:rows].reshape(-1)
    if layer is not None:
        cp = np.concatenate([cp, layer.control_points])
        w = np.concatenate([w, layer.weights])
    return Body(name=name, material="linear", youngs_modulus=1.0, poisson_ratio=0.3,
                dof_offset=0, control_points=cp, weights=w,
                element_ptr=np.zeros(1, dtype=np.int64), element_conn=np.zeros(0, dtype=np.int64),
                element_ranges=np.zeros((0, 4)), element_vo=np.zeros(0, dtype=bool), edges={},
                bulk=bulk, layer=layer)


SYNTHETIC_CASES = ["ironing/m1-NN2.2.nml", "ironing/m1-N2.nml", "ironing/m2-NN4.nml",
                   "hertz/m1-NN3.2.nml", "hertz/m1-L1.nml", "rings/m1-NN2.1.nml"]
"""Committed cases whose bodies the field tests use (layered and not)."""


@pytest.fixture(scope="session")
def synthetic_bodies() -> dict[str, Body]:
    """``'<case>:<body>'`` -> synthetic body, for every body of SYNTHETIC_CASES."""
    out = {}
    for case in SYNTHETIC_CASES:
        path = CASES / case
        if not path.is_file():
            pytest.skip(f"{path} missing: run `python -m pre cases`")
        for name, b in discretize_case(path).bodies.items():
            out[f"{case}:{name}"] = synthetic_body(name, b)
    return out


# The ironing die pressed 0.3 into the slab and slid 0.3 (2 + 2 steps, m1 N2, friction):
# contact with a NURBS master whose points slip in the last step.
PRESS_SLIDE = """&case
  title = 'die press and slide', scene = 'ironing', geometry = 'geometry.h5',
  output = 'press.h5', n_bodies = 2
/
&body
  name = 'die', material = 'neo-hookean', youngs_modulus = 10.0, poisson_ratio = 0.3,
  degree_xi = 2, degree_eta = 2, nel_xi = 6, nel_eta = 1, contact_edge = 'outer',
  layer_degree = 0
/
&body
  name = 'slab', material = 'neo-hookean', youngs_modulus = 1.0, poisson_ratio = 0.3,
  degree_xi = 2, degree_eta = 2, nel_xi = 8, nel_eta = 2, contact_edge = 'top',
  layer_degree = 2, layer_elevations = 2
/
&solver
  n_steps = 2, 2
/
&dirichlet
  body = 'die', edge = 'inner', fix_x = .true., fix_y = .true., ux = 0.0, 0.3, uy = -0.3, -0.3
/
&dirichlet
  body = 'slab', edge = 'bottom', fix_x = .true., fix_y = .true.
/
&contact
  slave = 'die', master = 'slab', penalty_normal = 100.0, penalty_tangent = 100.0,
  friction = 0.3, n_gauss = 6
/
"""


@pytest.fixture(scope="session")
def press_h5(voiga: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Die pressed and slid on the slab (NURBS master, friction; 4 steps)."""
    return run_case(voiga, tmp_path_factory.mktemp("press"), PRESS_SLIDE, "press.h5")


@pytest.fixture(scope="session")
def hertz_h5(voiga: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The committed hertz m1 NN2.2 case (rigid master line), run in a temporary folder."""
    folder = tmp_path_factory.mktemp("hertz")
    shutil.copy(CASES / "hertz" / "geometry.h5", folder / "geometry.h5")
    shutil.copy(CASES / "hertz" / "m1-NN2.2.nml", folder / "case.nml")
    run = subprocess.run([str(voiga), "case.nml", "--quiet"], cwd=folder, capture_output=True,
                         text=True, timeout=TIMEOUT, stdin=subprocess.DEVNULL)
    if run.returncode != 0:
        pytest.fail(f"hertz m1 NN2.2: exit {run.returncode}\n{run.stdout[-2000:]}{run.stderr[-2000:]}")
    return folder / "m1-NN2.2.h5"


# Solids (dimension 3). The box [0, 3] x [0, 2] x [0, 1] pulled by a traction SIGMA on
# x = 3 and held by its symmetry planes (test/python/test_solid_case.py's case): the
# exact field u = t SIGMA/E (x, -nu y, -nu z) lies in the NURBS space, stress
# (SIGMA t, 0, 0, 0, 0, 0). NN3.1 layer on the contact face.
SIGMA, E_SOLID = 0.02, 2.0

SOLID = """&case
  title = 'box', geometry = 'geometry.h5', output = '{output}', n_bodies = 1
/
&body
  name = 'block', material = 'linear', youngs_modulus = 2.0, poisson_ratio = 0.3,
  degree_xi = 2, degree_eta = 2, degree_zeta = 2, nel_xi = 3, nel_eta = 2, nel_zeta = 2,
  contact_face = '{contact}', layer_degree = 3, layer_elevations = 1
/
&solver
  n_steps = 2
/
&dirichlet
  body = 'block', face = 'left', fix_x = .true.
/
&dirichlet
  body = 'block', face = 'front', fix_y = .true.
/
&dirichlet
  body = 'block', face = 'bottom', fix_z = .true.
/
&pressure
  body = 'block', face = 'right', p = -0.02
/
&output
  samples = {samples}
/
"""

# A thick quarter cylinder (rational, r from 1 to 2, z from 0 to 1) with a layer on its
# outer face, held at its bottom and pressed on its outer face.
CYLINDER = """&case
  title = 'quarter cylinder', geometry = 'geometry.h5', output = 'cylinder.h5', n_bodies = 1
/
&body
  name = 'tube', material = 'linear', youngs_modulus = 10.0, poisson_ratio = 0.3,
  degree_xi = 2, degree_eta = 2, degree_zeta = 2, nel_xi = 2, nel_eta = 2, nel_zeta = 2,
  contact_face = 'outer', layer_degree = 3, layer_elevations = 0
/
&solver
  n_steps = 1
/
&dirichlet
  body = 'tube', face = 'bottom', fix_x = .true., fix_y = .true., fix_z = .true.
/
&pressure
  body = 'tube', face = 'outer', p = 0.01
/
"""


def exact_box(x: np.ndarray, time: float) -> np.ndarray:
    """The exact displacement of the box case at ``x`` (..., 3) and load time ``time``."""
    return time * SIGMA / E_SOLID * np.asarray(x, dtype=float) * np.array([1.0, -NU, -NU])


def _box_geometry(path: Path) -> None:
    from pre.solids import box, write_volumes

    write_volumes(path, {"block": box((0.0, 3.0), (0.0, 2.0), (0.0, 1.0))})


def _cylinder_geometry(path: Path) -> None:
    from pre.solids import cylinder_sector, write_volumes

    write_volumes(path, {"tube": cylinder_sector(1.0, 2.0)})


@pytest.fixture(scope="session")
def box_h5(voiga: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The box case (contact face 'top', fields at 2 x 2 x 2 points per element)."""
    return run_case(voiga, tmp_path_factory.mktemp("box"),
                    SOLID.format(output="box.h5", contact="top", samples=2), "box.h5",
                    geometry=_box_geometry)


@pytest.fixture(scope="session")
def turned_box_h5(voiga: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The box case with the contact face 'back' (y = 2): the solver turns the patch so
    that it is zeta = 1; fields at 3 x 3 x 3 points per element."""
    return run_case(voiga, tmp_path_factory.mktemp("turned"),
                    SOLID.format(output="turned.h5", contact="back", samples=3), "turned.h5",
                    geometry=_box_geometry)


@pytest.fixture(scope="session")
def cylinder_h5(voiga: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The quarter cylinder (rational map, layer on the outer face)."""
    return run_case(voiga, tmp_path_factory.mktemp("cylinder"), CYLINDER, "cylinder.h5",
                    geometry=_cylinder_geometry)
