"""One naming scheme for every file ``post`` writes.

``<folder>/<result stem>-<what>[-<step, 6 digits>].<ext>``: the folder is the
result file's unless ``out`` is given; the step number is zero-padded like the
result file's step groups (``/steps/000005``). Examples for ``m3-NN2.2.h5``:
``m3-NN2.2-deformed-000005.png``, ``m3-NN2.2-contact-000005.png``,
``m3-NN2.2-hertz-000005.png``, ``m3-NN2.2-history.csv``, ``m3-NN2.2.pvd``.
"""

from __future__ import annotations

from pathlib import Path


def output_path(result_path: str | Path, what: str | None, step: int | None = None,
                out: str | Path | None = None, ext: str = "png") -> Path:
    """The path of an output of ``result_path`` (see the module docstring);
    ``out`` is a folder (created when missing)."""
    result_path = Path(result_path)
    folder = Path(out) if out is not None else result_path.parent
    folder.mkdir(parents=True, exist_ok=True)
    name = result_path.stem
    if what:
        name += f"-{what}"
    if step is not None:
        name += f"-{step:06d}"
    return folder / f"{name}.{ext}"
