"""The hard-case suite of issue 6 (docs/hard-cases.md).

Every hard case is derived from a committed case (`cases/<scene>/<mesh>-<layout>.nml`)
by a few changes of its namelist (f90nml) and, for bodies that start apart, of its
geometry file; each has the outcome we expect of it:

- ``converges``: exit code 0, status ``converged``, every planned step written;
- ``refused``: exit code 2 (input we refuse), the message naming the reason;
- ``fails``: exit code 3 (numerical failure after the adaptive load stepping), the
  message naming the physical or numerical reason.

``python3 test/python/hard_cases.py`` (``make stress``) runs the full suite one case at
a time and prints the table (case, outcome, steps, cuts, Newton iterations, wall s);
``test_hard.py`` runs the reduced subset (``HardCase.reduced``) under pytest.
"""
from __future__ import annotations

import argparse
import fnmatch
import os
import shutil
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import f90nml
import h5py
import numpy as np

REPO = Path(__file__).resolve().parents[2]
LAYOUTS = ["N2", "N4", "N6", "NN2.1", "NN2.2", "NN2.3", "NN4", "NN6"]
#: E of the ironing slab: the penalties of the suite are multiples of it.
E_SLAB = 1.0

Edit = Callable[[f90nml.Namelist], None]
GeometryEdit = Callable[[h5py.File], None]
#: a check of a converged result file; returns what is wrong (empty: nothing)
Check = Callable[[h5py.File], list[str]]


@dataclass(frozen=True)
class HardCase:
    """One hard case: a committed case, the changes that make it hard, the outcome expected."""

    name: str
    scene: str
    base: str  # "<mesh>-<layout>"
    what: str  # one line for the table
    edits: tuple[Edit, ...] = ()
    geometry_edits: tuple[GeometryEdit, ...] = ()
    expect: str = "converges"  # converges | refused | fails
    #: words the error message must contain (refused / fails)
    words: tuple[str, ...] = ()
    #: words it must not contain (a diagnosis that does not apply)
    absent: tuple[str, ...] = ()
    #: in the reduced subset run by `make test`
    reduced: bool = False
    timeout: float = 3600.0
    #: checks of the result file of a converged run (e.g. where contact starts)
    checks: tuple[Check, ...] = ()


@dataclass
class Outcome:
    """What one run of a hard case gave."""

    case: HardCase
    returncode: int
    outcome: str  # converges | refused | fails | crashed | timeout
    steps: str = ""
    cuts: int | None = None
    iterations: int | None = None
    wall: float = 0.0
    message: str = ""
    #: written steps whose last factorized tangent had det K <= 0 (attribute
    #: tangent_det_sign): an equilibrium that is not stable
    nonpositive_det: int | None = None
    problems: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        """The outcome is the expected one (and its message names the reason)."""
        return not self.problems


# ---------------------------------------------------------------- namelist edits
def contact(**values: object) -> Edit:
    """Set variables of the &contact group."""

    def edit(nml: f90nml.Namelist) -> None:
        for key, value in values.items():
            nml["contact"][key] = value

    return edit


def bodies(**values: object) -> Edit:
    """Set variables of every &body group."""

    def edit(nml: f90nml.Namelist) -> None:
        for body in _groups(nml, "body"):
            for key, value in values.items():
                body[key] = value

    return edit


def body(name: str, **values: object) -> Edit:
    """Set variables of the &body group of body `name`."""

    def edit(nml: f90nml.Namelist) -> None:
        for group in _groups(nml, "body"):
            if group["name"] == name:
                group.update(values)

    return edit


def dirichlet(body_name: str, edge: str, **values: object) -> Edit:
    """Set variables of the &dirichlet group of (`body_name`, `edge`)."""

    def edit(nml: f90nml.Namelist) -> None:
        for group in _groups(nml, "dirichlet"):
            if group["body"] == body_name and group["edge"] == edge:
                group.update(values)

    return edit


def solver(**values: object) -> Edit:
    """Set variables of the &solver group."""

    def edit(nml: f90nml.Namelist) -> None:
        nml["solver"].update(values)

    return edit


def translate(body_name: str, dx: float, dy: float) -> GeometryEdit:
    """Move the coarse patch of body `body_name` by (dx, dy) in the geometry file."""

    def edit(f: h5py.File) -> None:
        cp = f[f"bodies/{body_name}/control_points"]
        data = cp[()]
        data[..., 0] += dx
        data[..., 1] += dy
        cp[...] = data

    return edit


def in_contact(step: int, expected: bool = True) -> Check:
    """The first pair has (or, expected False, has no) slave point in contact after `step`
    (0: the last step)."""

    def check(f: h5py.File) -> list[str]:
        names = sorted(f["steps"])
        name = names[-1] if step == 0 else f"{step:06d}"
        active = int(np.count_nonzero(f[f"steps/{name}/contact/1/state"][()] > 0))
        if (active > 0) != expected:
            return [f"step {name}: {active} points in contact, expected {'some' if expected else 'none'}"]
        return []

    return check


def mortar_zone_whole() -> Check:
    """The first pair is a mortar pair, no substep took the Tresca fixed point (it does
    not apply to mortar pairs), and at every step the contact zone is one run of
    active slave points without holes (the GPTS 1e6 runs break up point by point)."""

    def check(f: h5py.File) -> list[str]:
        problems = []
        names = sorted(f["steps"])
        if f[f"steps/{names[-1]}/contact/1"].attrs["method"].decode().strip() != "mortar":
            problems.append("the pair is not a mortar pair")
        if int(f.attrs.get("tresca_retries", 0)) != 0:
            problems.append(f"{int(f.attrs['tresca_retries'])} Tresca retries in a mortar run")
        for name in names:
            active = np.flatnonzero(f[f"steps/{name}/contact/1/state"][()] > 0)
            if active.size and active[-1] - active[0] + 1 != active.size:
                problems.append(f"step {name}: the contact zone has {active[-1] - active[0] + 1 - active.size} "
                                "open points between active ones")
                break
        return problems

    return check


def alm_softened(given: float, floor: float, forces: tuple[float, float],
                 rel: float = 1e-4) -> Check:
    """An augmented-Lagrangian pair that started at penalty `given` ends at most a
    tenth of it and not below `floor` (the pair's automatic penalty), and the mean die
    forces over the second half of sliding (post.measures) equal `forces` (those of the
    stiffest penalty run that converges, penalty-1e6) to `rel`: the penalty did not
    change the solution."""

    def check(f: h5py.File) -> list[str]:
        from post.measures import ironing_measures
        from post.reader import read_result
        problems = []
        names = sorted(f["steps"])
        last = float(f[f"steps/{names[-1]}/contact/1"].attrs["penalty_normal"])
        if not floor * (1 - 1e-9) <= last <= 0.1 * given:
            problems.append(f"penalty_normal at the end {last:g}: not softened into "
                            f"[{floor:g}, {0.1 * given:g}]")
        m = ironing_measures(read_result(f.filename))
        for key, want in zip(("mean_px", "mean_py"), forces, strict=True):
            if abs(m[key] / want - 1) > rel:
                problems.append(f"{key} {m[key]:.7g} differs from {want:.7g} by more than {rel:g}")
        return problems

    return check


def reaches_master_end(step: int = 0, xi: float = 0.99) -> Check:
    """A point in contact projects beyond `xi` on the master curve (parameter 0..1) after
    `step` (0: the last step; -1: any step)."""

    def check(f: h5py.File) -> list[str]:
        names = sorted(f["steps"])
        chosen = names if step == -1 else [names[-1] if step == 0 else f"{step:06d}"]
        best = 0.0
        for name in chosen:
            c = f[f"steps/{name}/contact/1"]
            active = c["state"][()] > 0
            if active.any():
                best = max(best, float(c["xi_master"][()][active].max()))
        return [] if best >= xi else [f"no contact point beyond xi = {xi} on the master (max {best:.4f})"]

    return check


def _groups(nml: f90nml.Namelist, name: str) -> list:
    """The groups `name` of a namelist as a list (one group or a cogroup)."""
    groups = nml[name]
    return list(groups) if isinstance(groups, list) else [groups]


# ---------------------------------------------------------------- the suite
def suite() -> list[HardCase]:
    """Every hard case of issue 6, item 4."""
    cases: list[HardCase] = []
    # ironing-deep on m1..m4, every layout, as committed
    for mesh in ["m1", "m2", "m3", "m4"]:
        for layout in LAYOUTS:
            cases.append(HardCase(f"deep-{mesh}-{layout}", "ironing-deep", f"{mesh}-{layout}",
                                  "ironing-deep as committed"))
    # penalties 1e1 .. 1e6 x E (the committed cases use 1e2, GPTS with 16 slave points
    # per element). Up to 1e5 GPTS converges. At 1e6 GPTS with 16 points locks
    # (docs/robustness.md, "Over-constrained contact zones": about 22 points press on 6
    # to 9 control points of the slave edge, the zone breaks up point by point, the
    # slip bounds mu p_N jump); the 1e6 cases therefore run with the mortar-type
    # penalty (one constraint per slave control point, the same 16 points as its
    # quadrature) and natural damping (with the residual rule they fail at steps 39
    # and 28, creeping with steps of 1/16).
    for exponent in range(1, 7):
        eps = 10.0**exponent * E_SLAB
        mortar = exponent >= 6
        cases.append(HardCase(f"penalty-1e{exponent}", "ironing", "m1-NN2.2",
                              f"penalty_normal = penalty_tangent = 1e{exponent} x E"
                              + (", mortar, natural damping" if mortar else ""),
                              (contact(penalty_normal=eps, penalty_tangent=eps),)
                              + ((contact(method="mortar"), solver(damping="natural")) if mortar else ()),
                              checks=(mortar_zone_whole(),) if mortar else ()))
    # the same penalties with the augmented Lagrangian: its solution does not depend on
    # them, so a failed substep makes them softer (down to the automatic penalty, 26.35
    # x E here) instead of cutting; the mean die forces are penalty-1e6's (mortar,
    # 20095 Newton iterations: mean Px 0.17722794, Py -0.59888704) to 1e-5
    for exponent in (4, 5, 6):
        eps = 10.0**exponent * E_SLAB
        cases.append(HardCase(f"alm-1e{exponent}", "ironing", "m1-NN2.2",
                              f"augmented Lagrangian, penalty_normal = penalty_tangent = 1e{exponent} x E",
                              (contact(method="alm", penalty_normal=eps, penalty_tangent=eps),),
                              checks=(alm_softened(eps, 26.35, (0.17722794, -0.59888704), 1e-5),),
                              reduced=exponent == 6))
    # which of the two penalties: the normal one alone stiff (tangential 1e2 x E)
    for exponent in (4, 6):
        eps = 10.0**exponent * E_SLAB
        mortar = exponent >= 6
        cases.append(HardCase(f"penalty-n1e{exponent}-t1e2", "ironing", "m1-NN2.2",
                              f"penalty_normal 1e{exponent} x E, penalty_tangent 1e2 x E"
                              + (", mortar, natural damping" if mortar else ""),
                              (contact(penalty_normal=eps, penalty_tangent=100.0 * E_SLAB),)
                              + ((contact(method="mortar"), solver(damping="natural")) if mortar else ()),
                              checks=(mortar_zone_whole(),) if mortar else (), reduced=mortar))
    # the limit of GPTS the 1e6 cases avoid, kept to check its diagnosis: the same two
    # with GPTS and 16 points fail, and the message names the locking and the remedies.
    # penalty 1e6 both: folds from step 20, passed by the Tresca fixed point up to step
    # 58, then step 59 (load time 1.2441) fails with contact states switching in the
    # Tresca solves too (docs/robustness.md, "Folds of the incremental problem",
    # "Tresca fixed point"); normal 1e6 alone: the slip limit mu p_N is as stiff as a
    # tangential penalty of 3e5 x E; it folds at step 22, and there the Tresca fixed
    # point diverges (each successive approximation multiplies the bound change by up
    # to 1.28: the map g -> mu p_N(g) is not a contraction)
    cases.append(HardCase("gpts-locking-1e6", "ironing", "m1-NN2.2",
                          "GPTS limit, 16 points: penalty_normal = penalty_tangent = 1e6 x E",
                          (contact(penalty_normal=1e6 * E_SLAB, penalty_tangent=1e6 * E_SLAB),),
                          expect="fails",
                          words=("contact states still switched", "retried with the Tresca fixed point",
                                 "is broken up", "lock", "method = 'mortar'")))
    cases.append(HardCase("gpts-locking-n1e6-t1e2", "ironing", "m1-NN2.2",
                          "GPTS limit, 16 points: penalty_normal 1e6 x E, penalty_tangent 1e2 x E",
                          (contact(penalty_normal=1e6 * E_SLAB, penalty_tangent=100.0 * E_SLAB),),
                          expect="fails", words=("folds", "not a contraction", "is broken up", "lock",
                                                 "method = 'mortar'"), reduced=True))
    # GPTS with 4 slave points per element instead of 16: about as many active points
    # as control points, a zone without holes; natural damping for the stiff penalty's
    # curvature (with the residual rule they fail at steps 31 and 43)
    for name, tangent in (("penalty-1e6-g4", 6), ("penalty-n1e6-t1e2-g4", 2)):
        cases.append(HardCase(name, "ironing", "m1-NN2.2",
                              f"penalty_normal 1e6 x E, penalty_tangent 1e{tangent} x E, "
                              "GPTS, 4 slave points per element, natural damping",
                              (contact(penalty_normal=1e6 * E_SLAB, penalty_tangent=10.0**tangent * E_SLAB,
                                       n_gauss=4), solver(damping="natural"))))
    cases.append(HardCase("penalty-1e6-mu0", "ironing", "m1-NN2.2", "penalty 1e6 x E, frictionless",
                          (contact(penalty_normal=1e6 * E_SLAB, friction=0.0),)))
    # the same on the hertz cylinder (E = 1, rigid plane): 1e9 x E converges on the
    # round-off floor, 1e12 x E (the largest accepted) fails: the floor lies above the
    # first residual at every increment (cuts down to 1/16 of a step show it as well
    # as the default 1e-4 and cost a fifth)
    cases.append(HardCase("penalty-hertz-1e9", "hertz", "m1-NN2.2", "hertz, penalty 1e9 x E",
                          (contact(penalty_normal=1e9),)))
    cases.append(HardCase("penalty-hertz-1e12", "hertz", "m1-NN2.2", "hertz, penalty 1e12 x E",
                          (contact(penalty_normal=1e12), solver(min_step_fraction=0.0625)), expect="fails",
                          words=("round-off level", "too large for double precision"), reduced=True))
    cases.append(HardCase("penalty-1e14", "ironing", "m1-NN2.2",
                          "penalty 1e14 x E (1e13 x the die's E): beyond the conditioning limit",
                          (contact(penalty_normal=1e14, penalty_tangent=1e14),), expect="refused",
                          words=("&contact", "penalty_normal", "significant digits"), reduced=True))
    # stiffness ratio 1e3
    cases.append(HardCase("ratio-1e3-ironing", "ironing", "m1-NN2.2", "die E = 1e3 x slab E (shallow)",
                          (body("die", youngs_modulus=1000.0),)))
    cases.append(HardCase("ratio-1e3-rings", "rings", "m1-N2", "upper ring E = 1e3 x lower E",
                          (body("upper", youngs_modulus=1000.0),), reduced=True))
    # friction up to 1
    for mu in (0.5, 1.0):
        cases.append(HardCase(f"mu-{mu}", "ironing", "m1-NN2.2", f"friction mu = {mu}",
                              (contact(friction=mu),)))
    # (with mu = 1 the deep die drags the slab's top. Until a point that touches in a
    # step counted only its slip after the touch, the path ended at load time 1.92110
    # with every smallest increment down to 1e-8 of a step (det K <= 0 in most iterations
    # after it, slab element 1 inverted): the leading points' spurious stick traction
    # drove it there. Now all 160 steps converge without a cut (366 iterations); with
    # twice the steps the die force agrees to 1e-4 (2e-3 near t = 1.92), so the path is
    # the converged quasi-static one)
    cases.append(HardCase("mu-1.0-deep", "ironing-deep", "m1-NN4",
                          "ironing-deep with mu = 1.0, increments down to 1e-8 of a step",
                          (contact(friction=1.0), solver(min_step_fraction=1e-8, max_cuts=60)),
                          absent=("is broken up",),
                          reduced=True))
    # nearly incompressible
    cases.append(HardCase("nu-0.49", "ironing", "m1-NN2.2", "Poisson ratio 0.49, both bodies",
                          (bodies(poisson_ratio=0.49),)))
    cases.append(HardCase("nu-0.49-hertz", "hertz", "m1-NN2.2", "hertz, Poisson ratio 0.49",
                          (bodies(poisson_ratio=0.49),), reduced=True))
    # the die sliding off the end of the slab (x = 9): its centre ends at x = 10.5
    cases.append(HardCase("slide-off", "ironing", "m1-NN2.2", "die slides 8.0, off the slab's end",
                          (dirichlet("die", "inner", ux=[0.0, 8.0]),)))
    # grazing: a die pressed 0.02 slides 6.5, its lowest point ends on the slab's corner,
    # the end of the master curve; and 7.0, past it
    for ux, tag in ((6.5, "end"), (7.0, "past")):
        cases.append(HardCase(f"grazing-{tag}", "ironing", "m1-NN2.2",
                              f"die pressed 0.02, slides {ux}: lowest point at x = {2.5 + ux}",
                              (dirichlet("die", "inner", ux=[0.0, ux], uy=[-0.02, -0.02]),
                               solver(n_steps=[2, 50])), reduced=tag == "end",
                              checks=(reaches_master_end(0),) if tag == "end"
                              else (reaches_master_end(-1, 0.99), in_contact(0, False))))
    # bodies that start apart: the die lifted by 0.2, then pressed 0.7 (contact starts at
    # load time 0.29) and slid; the hertz cylinder 0.005 above the plane, pressed 0.01
    cases.append(HardCase("apart-ironing", "ironing", "m1-NN2.2",
                          "die starts 0.2 above the slab, pressed 0.7, slid 4",
                          (dirichlet("die", "inner", uy=[-0.7, -0.7]),),
                          (translate("die", 0.0, 0.2),), checks=(in_contact(1, False), in_contact(10))))
    cases.append(HardCase("apart-hertz", "hertz", "m1-NN2.2",
                          "cylinder starts 0.005 above the plane, pressed 0.01",
                          (contact(rigid_point=[0.0, -1.005]), solver(n_steps=[10])), reduced=True,
                          checks=(in_contact(4, False), in_contact(6))))
    cases.append(HardCase("apart-ironing-lift", "ironing", "m1-N2",
                          "die pressed, lifted 0.3 off the slab, pressed again, slid",
                          (dirichlet("die", "inner", ux=[0.0, 0.0, 0.0, 2.0], uy=[-0.5, 0.3, -0.5, -0.5]),
                           solver(n_steps=[5, 5, 5, 50])), reduced=True,
                          checks=(in_contact(5), in_contact(10, False), in_contact(15))))
    return cases


# ---------------------------------------------------------------- running
def prepare(case: HardCase, directory: Path) -> Path:
    """Write the case file (and geometry) of `case` into `directory`; return the case file."""
    directory.mkdir(parents=True, exist_ok=True)
    source = REPO / "cases" / case.scene
    nml = f90nml.read(source / f"{case.base}.nml")
    geometry = directory / "geometry.h5"
    shutil.copy(source / nml["case"]["geometry"], geometry)
    with h5py.File(geometry, "r+") as f:
        for edit in case.geometry_edits:
            edit(f)
    nml["case"]["geometry"] = "geometry.h5"
    nml["case"]["output"] = "result.h5"
    nml["case"]["title"] = f"hard case {case.name}"
    for edit in case.edits:
        edit(nml)
    path = directory / "case.nml"
    nml.write(path, force=True)
    return path


def run_case(case: HardCase, directory: Path, voiga: Path) -> Outcome:
    """Run `case` in `directory` with the program `voiga` and judge the outcome."""
    path = prepare(case, directory)
    result = directory / "result.h5"
    result.unlink(missing_ok=True)
    start = time.perf_counter()
    try:
        proc = subprocess.run([str(voiga), path.name, "--quiet"], cwd=directory, capture_output=True,
                              text=True, timeout=case.timeout)
    except subprocess.TimeoutExpired:
        out = Outcome(case, -1, "timeout", wall=time.perf_counter() - start)
        out.problems.append(f"no result within {case.timeout:.0f} s")
        return out
    wall = time.perf_counter() - start
    kind = {0: "converges", 2: "refused", 3: "fails"}.get(proc.returncode, "crashed")
    # a Fortran runtime error also exits with 2 (or 3 is possible in principle), without
    # voiga's own message
    if kind in ("refused", "fails") and "voiga: error:" not in proc.stderr:
        kind = "crashed"
    message = " ".join(line.removeprefix("voiga: error: ").strip()
                       for line in proc.stderr.splitlines() if "error" in line)
    out = Outcome(case, proc.returncode, kind, wall=wall, message=message)
    if result.exists() and kind != "refused":
        _read_result(result, out)
    if kind != case.expect:
        out.problems.append(f"expected {case.expect}, got {kind} (exit {proc.returncode}): "
                            f"{message or proc.stderr.strip()[-300:]}")
    for word in case.words:
        if word not in message:
            out.problems.append(f"the message does not name {word!r}: {message}")
    for word in case.absent:
        if word in message:
            out.problems.append(f"the message names {word!r}, which does not apply: {message}")
    return out


def _read_result(path: Path, out: Outcome) -> None:
    """Steps, cuts and Newton iterations of a result file; check a converged one."""
    with h5py.File(path, "r") as f:
        status = f.attrs["status"].decode()
        done, planned = int(f.attrs["n_steps_done"]), int(f.attrs["n_steps_planned"])
        out.steps = f"{done}/{planned}"
        out.cuts = int(f.attrs.get("n_cuts", 0))
        steps = f.get("steps", {})
        out.iterations = sum(int(steps[name].attrs["iterations_total"]) for name in steps)
        out.nonpositive_det = sum(int(steps[name].attrs["tangent_det_sign"]) <= 0 for name in steps)
        if out.outcome == "converges":
            if status != "converged" or done != planned:
                out.problems.append(f"exit 0 but status {status!r}, {done}/{planned} steps")
                return
            for check in out.case.checks:
                out.problems.extend(check(f))
            for name in steps:
                u = steps[name]["displacement"][()]
                if not np.all(np.isfinite(u)):
                    out.problems.append(f"step {name}: displacement not finite")


def table(outcomes: list[Outcome]) -> str:
    """The suite's table in markdown."""
    lines = ["| case | what | expected | outcome | steps | cuts | Newton it. | det K <= 0 steps | wall s |",
             "|---|---|---|---|---|---|---|---|---|"]
    for o in outcomes:
        result = o.outcome if o.ok else f"**{o.outcome}** (unexpected)"
        if o.outcome in ("fails", "refused") and o.message:
            # what failed and, when the solver diagnosed a limit point, that diagnosis
            result += f": {o.message[:140]}"
            fold = o.message.find("; the determinant")
            if fold >= 0:
                result += f" ... {o.message[fold + 2:fold + 2 + 220]}"
        lines.append(f"| {o.case.name} | {o.case.what} | {o.case.expect} | {result} | {o.steps} | "
                     f"{'' if o.cuts is None else o.cuts} | "
                     f"{'' if o.iterations is None else o.iterations} | "
                     f"{'' if o.nonpositive_det is None else o.nonpositive_det} | {o.wall:.1f} |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """Run the hard-case suite; print the table; exit 1 if an outcome is not the expected one."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reduced", action="store_true", help="only the subset run by make test")
    parser.add_argument("--only", nargs="*", default=None, help="case name patterns (fnmatch)")
    parser.add_argument("--out", type=Path, default=REPO / "build" / "stress", help="work directory")
    parser.add_argument("--markdown", type=Path, default=None, help="also write the table here")
    parser.add_argument("--list", action="store_true", help="list the cases and exit")
    args = parser.parse_args(argv)
    voiga = Path(os.environ.get("VOIGA_BIN", REPO / "build" / "install" / "bin" / "voiga"))
    cases = [c for c in suite() if (c.reduced or not args.reduced)
             and (args.only is None or any(fnmatch.fnmatch(c.name, p) for p in args.only))]
    if args.list:
        for c in cases:
            print(f"{c.name:22s} {c.expect:10s} {'reduced' if c.reduced else '':8s} {c.what}")
        return 0
    outcomes = []
    start = time.perf_counter()
    for case in cases:
        o = run_case(case, args.out / case.name, voiga)
        outcomes.append(o)
        flag = "ok " if o.ok else "BAD"
        print(f"{flag} {case.name:22s} {o.outcome:10s} steps {o.steps:9s} cuts {o.cuts!s:5s} "
              f"it {o.iterations!s:6s} {o.wall:8.1f} s", flush=True)
        for problem in o.problems:
            print(f"    {problem}", flush=True)
    text = table(outcomes)
    total = time.perf_counter() - start
    print()
    print(text)
    print(f"\n{len(outcomes)} cases, {sum(not o.ok for o in outcomes)} unexpected, {total:.0f} s")
    if args.markdown:
        args.markdown.write_text(text + f"\n\n{len(outcomes)} cases, {total:.0f} s in all\n")
    return 0 if all(o.ok for o in outcomes) else 1


if __name__ == "__main__":
    sys.exit(main())
