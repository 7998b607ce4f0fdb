"""The attack classes of issue 36 (`attack.py`, docs/attack.md): the files around a
run rather than its inputs' contents.

- **link**: the lock file, the `.part` file, the dump and its `.part`, outputs as
  symbolic or hard links to the case, the geometry or another file; lock files a
  killed run left, and ones that are not ours;
- **special**: FIFOs and private device nodes (made with mknod in the work folder;
  never /dev) as outputs (with and without `--overwrite`), as their `.part` and
  `.lock`, as the case, the geometry, the restart file, and as a dataset's external
  raw storage;
- **swap**: a running writer stopped after its first step while its result file is
  replaced, moved or removed, its lock file removed (and a second run started) or
  replaced, or its folder removed;
- **huge**: geometry datasets that claim sizes far beyond the limits (chunked, never
  written: the files are small), values kept outside the file, a restart file whose
  displacement claims 2^31 values, case files with tens of thousands of groups.

Each is judged by `attack.py`'s oracles; what must not change is protected (by
content, link target or kind), what must not appear is `absent`.
"""
from __future__ import annotations

import os
import shutil
import stat
import subprocess
from collections.abc import Callable
from pathlib import Path

import h5py

from attack_inputs import BASE, GEOMETRY, REFUSED, RUNS, Attack, Setup, stage
from test_restart import truncate

ROOT = os.geteuid() == 0
"""Device nodes can be made (mknod) only as root; without, those attacks are left out."""

LONG = BASE.replace("n_steps = 2, 2", "n_steps = 200, 200")
"""The base case in 400 steps: a run still going when its files are changed."""

FAILS = frozenset({1})


def device(path: Path) -> None:
    """A private character device node with /dev/null's numbers (1, 3)."""
    os.mknod(path, stat.S_IFCHR | 0o666, os.makedev(1, 3))


def make(kind: str, path: Path) -> None:
    """A FIFO or a device node at `path`."""
    if kind == "fifo":
        os.mkfifo(path)
    else:
        device(path)


def staged(text: str = BASE, *args: str, prep: Callable[[Path], None] | None = None) -> Setup:
    def setup(work: Path) -> list[str]:
        case = stage(work, text)
        shutil.copy(GEOMETRY, work / "other.h5")
        if prep:
            prep(work)
        return [case.name, *args]
    return setup


def interrupted(work: Path, keep: int = 2) -> None:
    """out.h5: the result of case.nml cut back to `keep` steps, as a killed run leaves it."""
    subprocess.run([os.environ["ATTACK_VOIGA"], "case.nml", "--quiet"], cwd=work, capture_output=True,
                   timeout=300, check=True)
    truncate(work / "out.h5", keep)


# --- link ---------------------------------------------------------------------------------


def link_attacks() -> list[Attack]:
    out = []

    def symlink(name: str, target: str) -> Callable[[Path], None]:
        return lambda work: (work / name).symlink_to(target)

    def hardlink(name: str, target: str) -> Callable[[Path], None]:
        return lambda work: os.link(work / target, work / name)

    for companion in ("out.h5.lock", "out.h5.part"):
        short = companion.split(".")[-1]
        for target in ("geometry.h5", "case.nml", "other.h5"):
            out.append(Attack("link", f"{short}/symlink-{target}", staged(BASE, "--quiet",
                              prep=symlink(companion, target)), REFUSED, (companion, "symbolic link"),
                              protect=("other.h5", companion), example=target == "geometry.h5"))
            out.append(Attack("link", f"{short}/hardlink-{target}", staged(BASE, "--quiet",
                              prep=hardlink(companion, target)), REFUSED, (companion, "a second name"),
                              protect=("other.h5",), example=target == "case.nml"))
        out.append(Attack("link", f"{short}/dangling", staged(BASE, "--quiet", prep=symlink(companion, "new.h5")),
                          REFUSED, (companion, "symbolic link"), absent=("new.h5",)))
        out.append(Attack("link", f"{short}/loop", staged(BASE, "--quiet", prep=symlink(companion, companion)),
                          REFUSED, (companion,)))
    # the lock file of a restart (taken before the case is known)
    for target in ("geometry.h5", "case.nml"):
        def restart(work: Path, target: str = target) -> list[str]:
            stage(work)
            interrupted(work)
            (work / "out.h5.lock").symlink_to(target)
            return ["--restart", "out.h5"]
        out.append(Attack("link", f"restart-lock/symlink-{target}", restart, REFUSED,
                          ("out.h5.lock", "symbolic link"), protect=("out.h5", "out.h5.lock"),
                          example=target == "geometry.h5"))
    # lock files nobody holds: a killed run's (replaced), anything else (refused, kept)
    for name, content, allowed, words in (("pid", "4242\n", RUNS, ()), ("empty", "", RUNS, ()),
                                           ("notes", "my notes\n", REFUSED, ("not a lock file of voiga",)),
                                           ("long", "1" * 100, REFUSED, ("not a lock file of voiga",))):
        out.append(Attack("link", f"stale-lock/{name}", staged(BASE, "--quiet", prep=lambda w, c=content: (
            w / "out.h5.lock").write_text(c)), allowed, words, protect=("out.h5.lock",) if allowed == REFUSED
            else (), same=allowed == RUNS))
    # --dump: its .part, an existing file, a link to one
    for name, prep, args, allowed, words, protect in (
            ("part-symlink-geometry", symlink("d.h5.part", "geometry.h5"), (), REFUSED, ("d.h5.part", "symbolic"),
             ()),
            ("part-hardlink-geometry", hardlink("d.h5.part", "geometry.h5"), (), REFUSED, ("a second name",), ()),
            ("lock-symlink-case", symlink("d.h5.lock", "case.nml"), (), REFUSED, ("d.h5.lock", "symbolic"), ()),
            ("existing", lambda w: shutil.copy(w / "other.h5", w / "d.h5"), (), REFUSED, ("exists", "--overwrite"),
             ("d.h5",)),
            ("symlink-to-other", symlink("d.h5", "other.h5"), (), REFUSED, ("exists", "--overwrite"),
             ("other.h5", "d.h5")),
            ("existing-overwrite", lambda w: shutil.copy(w / "other.h5", w / "d.h5"), ("--overwrite",), RUNS, (),
             ()),
            ("hardlink-geometry", hardlink("d.h5", "geometry.h5"), ("--overwrite",), REFUSED,
             ("is the geometry file",), ())):
        out.append(Attack("link", f"dump/{name}", staged(BASE, "--check", "--dump", "d.h5", *args, prep=prep),
                          allowed, words, protect=("other.h5", *protect), example=name == "part-symlink-geometry"))
    # outputs that are other names of inputs
    for name, output, prep in (("hardlink-geometry", "hard.h5", hardlink("hard.h5", "geometry.h5")),
                               ("hardlink-case", "hard.h5", hardlink("hard.h5", "case.nml"))):
        out.append(Attack("link", f"output/{name}", staged(BASE.replace("output = 'out.h5'", f"output = '{output}'"),
                          "--quiet", "--overwrite", prep=prep), REFUSED, ("is the",)))
    return out


# --- special files ----------------------------------------------------------------------------


def special_attacks() -> list[Attack]:
    out = []
    kinds = ["fifo"] + (["device"] if ROOT else [])
    for kind in kinds:
        words = ("FIFO",) if kind == "fifo" else ("character device",)
        for overwrite in ((), ("--overwrite",)):
            tag = "-overwrite" if overwrite else ""
            out.append(Attack("special", f"output/{kind}{tag}", staged(
                BASE.replace("output = 'out.h5'", "output = 'special'"), "--quiet", *overwrite,
                prep=lambda w, k=kind: make(k, w / "special")), REFUSED, (*words, "not a regular file"),
                protect=("special",), example=kind == "device"))
            out.append(Attack("special", f"output/link-to-{kind}{tag}", staged(BASE, "--quiet", *overwrite,
                              prep=lambda w, k=kind: (make(k, w / "special"), (w / "out.h5").symlink_to("special"))),
                              REFUSED, words, protect=("special", "out.h5")))
        for companion in ("out.h5.lock", "out.h5.part"):
            out.append(Attack("special", f"{companion.split('.')[-1]}/{kind}", staged(
                BASE, "--quiet", prep=lambda w, k=kind, c=companion: make(k, w / c)), REFUSED, words,
                protect=(companion,)))
        out.append(Attack("special", f"dump/{kind}", staged(BASE, "--check", "--dump", "special", "--overwrite",
                          prep=lambda w, k=kind: make(k, w / "special")), REFUSED, words, protect=("special",)))
        # inputs: never waited on
        def case_special(work: Path, kind: str = kind) -> list[str]:
            stage(work)
            make(kind, work / "special")
            return ["special", "--check"]
        out.append(Attack("special", f"case/{kind}", case_special, REFUSED, words, protect=("special",)))
        out.append(Attack("special", f"geometry/{kind}", staged(BASE.replace("geometry = 'geometry.h5'",
                          "geometry = 'special'"), "--check", prep=lambda w, k=kind: make(k, w / "special")),
                          REFUSED, words, protect=("special",)))
        def restart_special(work: Path, kind: str = kind) -> list[str]:
            stage(work)
            make(kind, work / "special")
            return ["--restart", "special"]
        out.append(Attack("special", f"restart/{kind}", restart_special, REFUSED, words, protect=("special",),
                          absent=("special.lock",)))
    # a dataset whose raw values are kept in an external file that is a FIFO
    def external(work: Path) -> list[str]:
        case = stage(work)
        os.mkfifo(work / "raw")
        with h5py.File(work / "geometry.h5", "r+") as f:
            g = f["bodies/slab"]
            shape = g["knots_xi"].shape
            del g["knots_xi"]
            g.create_dataset("knots_xi", shape=shape, dtype="f8", external=[("raw", 0, h5py.h5f.UNLIMITED)])
        return [case.name, "--check"]
    out.append(Attack("special", "external-storage/fifo", external, REFUSED, ("knots_xi", "external files"),
                      example=True))
    return out


# --- files changed under a running writer ------------------------------------------------------


def second_run(work: Path) -> None:
    """The lock removed, a second run of the same case with --overwrite: it must run."""
    (work / "out.h5.lock").unlink()
    res = subprocess.run([os.environ["ATTACK_VOIGA"], "case.nml", "--quiet", "--overwrite"], cwd=work,
                         capture_output=True, text=True, timeout=300)
    if res.returncode != 0:
        raise AssertionError(f"the second run ended with exit {res.returncode}: {res.stderr[-300:]}")
    shutil.copy(work / "out.h5", work / "second.h5")


def swap_attacks() -> list[Attack]:
    def copy_other(work: Path) -> None:
        shutil.copy(work / "other.h5", work / "keep.h5")

    def prep_long(work: Path) -> None:
        copy_other(work)
        (work / "sub").mkdir()

    actions: dict[str, tuple[Callable[[Path], None], tuple[str, ...], tuple[tuple[str, str], ...]]] = {
        "result-replaced": (lambda w: os.replace(w / "other.h5", w / "out.h5"), ("moved, replaced or removed",),
                            (("out.h5", "keep.h5"),)),
        "result-removed": (lambda w: (w / "out.h5").unlink(), ("moved, replaced or removed",), ()),
        "result-moved": (lambda w: os.replace(w / "out.h5", w / "moved.h5"), ("moved, replaced or removed",), ()),
        "result-linked": (lambda w: (os.replace(w / "out.h5", w / "moved.h5"),
                                     (w / "out.h5").symlink_to("moved.h5")), ("moved, replaced or removed",), ()),
        "lock-removed-second-run": (second_run, ("lock file", "removed or replaced"), (("out.h5", "second.h5"),)),
        "lock-replaced": (lambda w: ((w / "out.h5.lock").unlink(), (w / "out.h5.lock").write_text("1\n")),
                          ("lock file", "removed or replaced"), ()),
        "folder-removed": (lambda w: shutil.rmtree(w / "sub"), ("lock file",), ()),
    }
    out = []
    for name, (action, words, same) in actions.items():
        text = LONG.replace("output = 'out.h5'", "output = 'sub/out.h5'") if name == "folder-removed" else LONG
        out.append(Attack("swap", name, staged(text, prep=prep_long), FAILS, words, same_as=same, during=action,
                          example=name in ("result-replaced", "lock-removed-second-run")))
    # the same under a restart, which writes the file in place from its start
    def restart_setup(work: Path) -> list[str]:
        stage(work, LONG)
        shutil.copy(GEOMETRY, work / "other.h5")
        copy_other(work)
        interrupted(work, keep=1)
        return ["--restart", "out.h5"]
    out.append(Attack("swap", "restart-result-replaced", restart_setup, FAILS, ("moved, replaced or removed",),
                      same_as=(("out.h5", "keep.h5"),), during=lambda w: os.replace(w / "other.h5", w / "out.h5")))
    return out


# --- huge sizes --------------------------------------------------------------------------------


def huge_dataset(key: str, shape: tuple[int, ...], dtype: str = "f8") -> Setup:
    def setup(work: Path) -> list[str]:
        case = stage(work)
        with h5py.File(work / "geometry.h5", "r+") as f:
            g = f["bodies/slab"]
            del g[key]
            g.create_dataset(key, shape=shape, dtype=dtype,
                             chunks=(1,) * (len(shape) - 1) + (min(shape[-1], 1024),))
        return [case.name, "--check"]
    return setup


def huge_attacks() -> list[Attack]:
    out = []
    for key, shape, dtype in (("control_points", (31623, 31623, 2), "f8"), ("weights", (1, 2**31), "f8"),
                              ("knots_xi", (10**9,), "f8"), ("knots_eta", (2**40,), "f8"),
                              ("degree", (10**7,), "i4"), ("control_points", (2, 100001, 2), "f8"),
                              ("weights", (2**20, 2**20), "f8"), ("control_points", (2**62, 1, 2), "f8")):
        out.append(Attack("huge", f"geometry/{key}-{'x'.join(map(str, shape))}", huge_dataset(key, shape, dtype),
                          REFUSED, (key,), example=key == "control_points" and shape[0] == 31623))
    # a virtual dataset: its values are read from another file
    def virtual(work: Path) -> list[str]:
        case = stage(work)
        with h5py.File(work / "geometry.h5", "r+") as f:
            g = f["bodies/slab"]
            knots = g["knots_xi"][()]
            del g["knots_xi"]
            with h5py.File(work / "knots.h5", "w") as k:
                k["k"] = knots
            layout = h5py.VirtualLayout(shape=knots.shape, dtype="f8")
            layout[:] = h5py.VirtualSource("knots.h5", "k", shape=knots.shape)
            g.create_virtual_dataset("knots_xi", layout)
        return [case.name, "--check"]
    out.append(Attack("huge", "geometry/virtual-dataset", virtual, REFUSED, ("knots_xi", "virtual")))
    # a restart file whose last displacement claims 2^31 values
    def restart_huge(work: Path) -> list[str]:
        stage(work)
        interrupted(work)
        with h5py.File(work / "out.h5", "r+") as f:
            g = f["steps/000002"]
            del g["displacement"]
            g.create_dataset("displacement", shape=(2**31,), dtype="f8", chunks=(1024,))
        return ["--restart", "out.h5"]
    out.append(Attack("huge", "restart/displacement-2^31", restart_huge, REFUSED, ("displacement",),
                      protect=("out.h5",)))
    for group, count in (("pressure", 40000), ("dirichlet", 100000), ("contact", 2000)):
        line = {"pressure": "&pressure body = 'slab', edge = 'top', p = 0.0, 0.0 /\n",
                "dirichlet": "&dirichlet body = 'slab', edge = 'top', fix_x = .true. /\n",
                "contact": "&contact slave = 'slab', master = 'rigid' /\n"}[group]
        given = count + BASE.count(f"&{group}")
        out.append(Attack("huge", f"namelist/{given}-{group}", staged(BASE + line * count, "--check"), REFUSED,
                          (f"&{group}", "at most 1000", f"({given} given)"), example=group == "pressure"))
    return out


def file_attacks() -> list[Attack]:
    """Every attack of issue 36."""
    return link_attacks() + special_attacks() + swap_attacks() + huge_attacks()
