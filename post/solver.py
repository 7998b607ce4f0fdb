"""Finding and running the ``voiga`` program from Python (``python -m post run``).

The binary is, in this order: the one given, ``$VOIGA_BIN``, ``voiga`` on the
``PATH``, and ``build/install/bin/voiga`` of the source checkout this package
was imported from (``make build`` puts it there). An installed package has no
checkout, so the last choice only applies when running from the repository.
"""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import f90nml

from pre.files import new_file

CHECKOUT_BINARY = Path(__file__).resolve().parents[1] / "build" / "install" / "bin" / "voiga"
"""Where ``make build`` installs the program, when this package runs from a checkout."""

BUILD_HINT = ("build it with `make build` in the voiga repository (it installs "
              "build/install/bin/voiga), then put that folder on the PATH (export "
              "PATH=\"$PWD/build/install/bin:$PATH\") or set VOIGA_BIN")
"""How to get a voiga program, for the messages of a missing one."""


class InputError(Exception):
    """Bad input named by the message (the command line exits with 2)."""


def _runnable(path: Path) -> bool:
    return path.is_file() and os.access(path, os.X_OK)


def in_checkout() -> bool:
    """Whether this package runs from a source checkout (its fpm.toml beside it), not
    from an installed copy (site-packages has no build folder)."""
    return (CHECKOUT_BINARY.parents[3] / "fpm.toml").is_file()


def voiga_binary(explicit: str | Path | None = None) -> Path:
    """The voiga program to run (see the module docstring); InputError naming where
    it looked and how to build one when there is none."""
    if explicit:
        path = Path(explicit)
        if not _runnable(path):
            raise InputError(f"no voiga program at {path} (--binary): not an executable file")
        # absolute: the cases run in their own folders
        return path.absolute()
    if os.environ.get("VOIGA_BIN"):
        path = Path(os.environ["VOIGA_BIN"])
        if not _runnable(path):
            raise InputError(f"no voiga program at {path} (VOIGA_BIN): not an executable file "
                             "(unset VOIGA_BIN to use voiga on the PATH)")
        return path.absolute()
    found = shutil.which("voiga")
    if found:
        return Path(found)
    if in_checkout() and _runnable(CHECKOUT_BINARY):
        return CHECKOUT_BINARY
    where = f"no voiga on the PATH ({os.environ.get('PATH', '')})"
    if in_checkout():
        where += f" and no {CHECKOUT_BINARY}"
    raise InputError(f"no voiga program: {where}; {BUILD_HINT}")


def read_case_group(case: Path) -> dict:
    """The ``&case`` group of a case file (f90nml), InputError when unreadable."""
    if not case.is_file():
        raise InputError(f"no case file {case}")
    try:
        nml = f90nml.read(str(case))
    except Exception as err:  # f90nml raises several kinds on bad text
        raise InputError(f"{case}: not a readable namelist ({err})") from None
    if "case" not in nml:
        raise InputError(f"{case}: no &case group")
    return dict(nml["case"])


def stage_case(case: Path, folder: Path) -> Path:
    """A copy of ``case`` in ``folder`` whose geometry path points at the original
    geometry (a relative path), so that the run writes its result into ``folder`` and the
    input stays untouched. Returns the copy's path."""
    group = read_case_group(case)
    geometry = group.get("geometry")
    if not geometry:
        raise InputError(f"{case}: &case has no geometry")
    geometry_path = (case.parent / str(geometry)).resolve()
    if not geometry_path.is_file():
        raise InputError(f"{case}: geometry file {geometry_path} does not exist")
    folder.mkdir(parents=True, exist_ok=True)
    copy = folder / case.name
    if copy.resolve() == case.resolve():
        return case
    relative = os.path.relpath(geometry_path, folder.resolve())
    with new_file(copy) as tmp:
        tmp.unlink()      # f90nml writes the patched copy itself
        f90nml.patch(str(case), {"case": {"geometry": relative}}, str(tmp))
    return copy


def result_path(case: Path) -> Path:
    """The result file a case writes (``&case output``, relative to the case's folder)."""
    output = read_case_group(case).get("output")
    if not output:
        raise InputError(f"{case}: &case has no output")
    return case.parent / str(output)


def run_voiga(binary: Path, case: Path, quiet: bool = False, overwrite: bool = False) -> int:
    """Run ``voiga CASE`` (its per-step lines go to the terminal unless ``quiet``;
    ``overwrite``: replace an existing result file, which voiga otherwise refuses);
    returns its exit code."""
    args = [str(binary), str(case)] + (["--quiet"] if quiet else []) + (["--overwrite"] if overwrite else [])
    return subprocess.run(args, stdin=subprocess.DEVNULL).returncode
