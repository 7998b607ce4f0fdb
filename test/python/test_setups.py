"""Wrong set-ups stopped early with the variable to change (issue 38, item 1): a rigid
line whose normal points into the slave, a rigid curve the wrong way round, an indenter
that starts inside the block (each refused with exit 2 before anything is written,
unless ``--allow-overlap`` or ``&contact allow_overlap``); a step given up after its
budget of Newton iterations with the suggestion of more load steps; a failure that
points back to the warning explaining it; ``post summary`` showing the warnings of a
run that converged no step; the live progress line on a terminal only.

Every case is built from a spec (``pre.spec.write_from_spec``): a 40 x 10 block, an
obstacle above it."""
from __future__ import annotations

import os
import pty
import select
import subprocess
import sys
from pathlib import Path

import h5py
import pytest

from conftest import REPO

BLOCK = """
units = "mm, N"
scene = "{scene}"
[defaults]
layout = "NN2.2"
[[body]]
name = "block"
shape = "rectangle"
x = [0.0, 40.0]
y = [-10.0, 0.0]
contact_edge = "top"
nel = [20, 2]
[[dirichlet]]
body = "block"
edge = "bottom"
fix_x = true
fix_y = true
"""

LINE = """
[solver]
n_steps = [10]
[[contact]]
slave = "block"
master = "rigid"
rigid_point = [0.0, 0.5]
rigid_normal = {normal}
rigid_uy = [-1.0]
penalty_normal = 100.0
friction = 0.2
"""

ARC = """
[[curve]]
name = "roller"
shape = "arc"
centre = [10.0, 5.0]
radius = 5.0
angles = [180.0, 360.0]
side = "{side}"
[solver]
n_steps = [5]
[[contact]]
slave = "block"
master = "rigid"
rigid_curve = "roller"
rigid_uy = [-0.5]
"""

INDENTER = """
[[body]]
name = "indenter"
shape = "rectangle"
x = [15.0, 25.0]
y = [{bottom}, {top}]
contact_edge = "bottom"
nel = [10, 2]
youngs_modulus = 10.0
[solver]
n_steps = [5]
[[dirichlet]]
body = "indenter"
edge = "top"
fix_x = true
fix_y = true
uy = [-0.2]
[[contact]]
slave = "indenter"
master = "block"
"""


def build(folder: Path, name: str, text: str) -> Path:
    """The case of a spec (geometry and case file written by pre)."""
    sys.path.insert(0, str(REPO))
    from pre.spec import write_from_spec

    spec = folder / f"{name}.toml"
    spec.write_text(text)
    done = write_from_spec(spec)
    assert done.written
    return done.case


def line_case(folder: Path, normal: str) -> Path:
    return build(folder, "line", BLOCK.format(scene="line on block") + LINE.format(normal=normal))


def stiff_line_case(folder: Path) -> Path:
    """The line into the block (normal up, 0.5 above the block's top) with a stiff
    penalty: no step converges. With the soft penalty of `line_case` (100) the run
    converges since issue 35's friction changes (22 Newton iterations in step 1, where
    the binary before cut it 13 times): the penalty pulls the block's top up towards the
    line, a solution of the case as given."""
    case = line_case(folder, "[0.0, 1.0]")
    case.write_text(case.read_text().replace("penalty_normal = 100.0", "penalty_normal = 1.0e6"))
    return case


def test_rigid_normal_into_the_slave_is_refused(run, tmp_path: Path) -> None:
    """The line above the block with its normal up: every slave point seems inside.
    Today's code warned and then cut the first step 13 times (exit 3); now the run is
    refused at once, naming rigid_normal and the value to give."""
    case = line_case(tmp_path, "[0.0, 1.0]")
    for args in ((), ("--check",)):
        res = run(case, *args, cwd=tmp_path)
        assert res.returncode == 2, (args, res.stdout, res.stderr)
        (error,) = [x for x in res.stderr.splitlines() if x.startswith("voiga: error: ")]
        assert "most of the slave edge starts inside the master (100 of the 100 slave points that face it, 100 % of " \
               "their length" in error, error
        assert "rigid_normal = (0.0, 1.0) points into the slave" in error, error
        assert "give rigid_normal = 0.0, -1.0" in error and "--allow-overlap" in error, error
        assert "floating-point" not in res.stdout + res.stderr
    assert not (tmp_path / "line.h5").exists() and not list(tmp_path.glob("line.h5*"))
    # the normal the message names is the one that works
    case.write_text(case.read_text().replace("rigid_normal = 0.0, 1.0", "rigid_normal = 0.0, -1.0"))
    res = run(case, "--quiet", cwd=tmp_path)
    assert res.returncode == 0, res.stderr


def test_rigid_line_through_the_slave_names_rigid_point(run, tmp_path: Path) -> None:
    """A line across the block (x = 30, normal +x): 75 of 100 points behind it, the
    others in front: turning the normal would not help, the message says to move
    rigid_point."""
    case = line_case(tmp_path, "[1.0, 0.0]")
    case.write_text(case.read_text().replace("rigid_point = 0.0, 0.5", "rigid_point = 30.0, 0.5"))
    res = run(case, cwd=tmp_path)
    assert res.returncode == 2, res.stderr
    assert "(75 of the 100 slave points that face it, 75 % of their length" in res.stderr, res.stderr
    assert "the line through rigid_point = (30.0, 0.5) cuts through the slave body (25 of the 100 points " \
           "lie on the side rigid_normal = (1.0, 0.0) points to): move rigid_point" in res.stderr, res.stderr


def test_rigid_curve_the_wrong_way_round_is_refused(run, tmp_path: Path) -> None:
    """A roller whose [[curve]] side is "outside" (the obstacle around the circle):
    the block's points under it seem inside; the message names the curve and its side."""
    text = BLOCK.format(scene="roller") + ARC.format(side="outside")
    case = build(tmp_path, "roller", text)
    res = run(case, cwd=tmp_path)
    assert res.returncode == 2, res.stderr
    assert "the rigid curve 'roller' is the wrong way round" in res.stderr, res.stderr
    assert "'inside' or 'outside' of an arc" in res.stderr, res.stderr
    case = build(tmp_path, "roller2", text.replace('side = "outside"', 'side = "inside"'))
    res = run(case, "--quiet", cwd=tmp_path)
    assert res.returncode == 0, res.stderr


def test_indenter_inside_the_block(run, tmp_path: Path) -> None:
    """An indenter whose bottom starts 1 below the block's top: refused, naming both
    contact edges; with --allow-overlap (or the case variable) it runs, the warning
    kept (the penalty pushes the bodies apart in the first step and it converges)."""
    text = BLOCK.format(scene="indenter") + INDENTER.format(bottom=-1.0, top=4.0)
    case = build(tmp_path, "inside", text)
    res = run(case, cwd=tmp_path)
    assert res.returncode == 2, res.stderr
    assert "check contact_edge of the slave 'indenter' (now 'bottom') and of the master 'block' (now " \
           "'top'), or move the bodies apart" in res.stderr, res.stderr
    res = run(case, "--allow-overlap", "--quiet", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert "voiga: warning: contact 'indenter' on 'block': the bodies overlap at the start" in res.stderr
    case.write_text(case.read_text().replace("slave = 'indenter'", "allow_overlap = .true.\n  slave = 'indenter'"))
    res = run(case, "--quiet", "--overwrite", cwd=tmp_path)
    assert res.returncode == 0, res.stderr


def test_failure_points_back_to_the_warning(run, tmp_path: Path) -> None:
    """The line into the block, allowed: no step converges. The error names the overlap
    warning; voiga says that no step converged (not "results of the converged steps are
    in"); `post summary` of the file shows the warning (today's summary stopped at the
    status line when no step was written)."""
    case = stiff_line_case(tmp_path)
    res = run(case, "--allow-overlap", "--quiet", cwd=tmp_path)
    assert res.returncode == 3, res.stderr
    assert "floating-point" not in res.stdout + res.stderr
    error = res.stderr.split("voiga: error: ")[1]
    assert "It may follow from the warning reported before (stderr, and in the result file: post summary): " \
           "contact 'block' on 'rigid': the bodies overlap at the start" in error, error
    assert "voiga: no step converged; " in res.stderr and "keeps the status and the warnings" in res.stderr
    assert "results of the converged steps" not in res.stderr
    summary = subprocess.run([sys.executable, "-m", "post", "summary", str(tmp_path / "line.h5")],
                             capture_output=True, text=True, cwd=REPO, timeout=120,
                             env={**os.environ, "PYTHONPATH": str(REPO)})
    assert summary.returncode == 0, summary.stderr
    lines = summary.stdout.splitlines()
    assert lines[0].startswith("line on block: failed: step 1"), lines
    assert "0 of 10 steps" in lines[0] and " 0 Newton iterations" not in lines[0], lines
    assert any(x.startswith("warning: contact 'block' on 'rigid': the bodies overlap at the start") for x in lines)


def test_touching_and_apart_bodies_are_not_refused(run, tmp_path: Path) -> None:
    """The indenter on the block (touching) and 0.1 above it: no refusal, no overlap."""
    for bottom in (0.0, 0.1):
        case = build(tmp_path, f"apart{bottom}", BLOCK.format(scene="indenter") +
                     INDENTER.format(bottom=bottom, top=bottom + 5.0))
        res = run(case, "--check", cwd=tmp_path)
        assert res.returncode == 0 and "overlap" not in res.stderr, res.stderr


def test_hopeless_step_is_given_up_with_more_load_steps(run, tmp_path: Path) -> None:
    """The line into the block with --allow-overlap fails from the first attempt on;
    with a budget of 100 Newton iterations the step is given up after a few cuts (not
    the 13 it took to reach min_step_fraction), the message suggesting more load steps."""
    case = stiff_line_case(tmp_path)
    case.write_text(case.read_text().replace("n_steps = 10", "n_steps = 10\n  max_stalled_iterations = 100"))
    res = run(case, "--allow-overlap", "--quiet", cwd=tmp_path)
    assert res.returncode == 3, res.stderr
    error = res.stderr.split("voiga: error: ")[1]
    assert "gave the step up: its attempts since the last converged substep took" in error, error
    assert "max_stalled_iterations = 100" in error, error
    assert "give more load steps (&solver n_steps, now 10)" in error, error
    with h5py.File(tmp_path / "line.h5") as f:
        cuts = int(f.attrs["n_cuts"])
        iterations = int(f.attrs["newton_iterations"])
    assert 1 <= cuts < 13 and 100 <= iterations < 200, (cuts, iterations)


def test_budget_is_validated(run, tmp_path: Path) -> None:
    case = line_case(tmp_path, "[0.0, -1.0]")
    case.write_text(case.read_text().replace("n_steps = 10", "n_steps = 10\n  max_stalled_iterations = -1"))
    res = run(case, "--check", cwd=tmp_path)
    assert res.returncode == 2 and "&solver: max_stalled_iterations must be >= 0" in res.stderr, res.stderr


def _on_terminal(voiga: Path, case: Path) -> tuple[int, str]:
    """Run voiga with its stdout on a pseudo-terminal; its exit code and output."""
    master, slave = pty.openpty()
    proc = subprocess.Popen([str(voiga), str(case)], stdout=slave, stderr=subprocess.DEVNULL,
                            cwd=case.parent)
    os.close(slave)
    chunks = []
    while True:
        ready, _, _ = select.select([master], [], [], 120)
        if not ready:
            proc.kill()
            pytest.fail("voiga wrote nothing for 120 s")
        try:
            data = os.read(master, 4096)
        except OSError:  # the terminal closed with the program
            break
        if not data:
            break
        chunks.append(data)
    os.close(master)
    return proc.wait(timeout=120), b"".join(chunks).decode(errors="replace")


def test_live_progress_line_on_a_terminal_only(voiga_bin: Path, run, tmp_path: Path) -> None:
    """On a terminal each attempt rewrites one line in place (step, substep, cuts,
    iteration, elapsed) and wipes it before the step's own line; through a pipe there is
    no such line. (At least one update per attempt is written whatever the timing.)"""
    case = line_case(tmp_path, "[0.0, -1.0]")
    code, text = _on_terminal(voiga_bin, case)
    assert code == 0, text
    live = [part for part in text.split("\r") if part.startswith("  step ")]
    assert len(live) >= 10, text
    assert "  step 1/10  substep 1  cuts 0 (run 0)  t=0.1000  increment 1.0E+00  iteration 0  elapsed " in text
    assert "\r\x1b[Kstep 1/10  t=" in text.replace("\r\n", "\n"), text
    res = run(case, "--overwrite", cwd=tmp_path)
    assert res.returncode == 0 and "\r" not in res.stdout and "substep 1" not in res.stdout, res.stdout
