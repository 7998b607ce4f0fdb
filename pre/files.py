"""Writing output files safely (pre and post): every file the tools write (geometry,
case files, figures, ParaView files, tables, a study's cases and results) is first
written as a new file beside its target, created exclusively (``O_EXCL``, never
through a link), and then renamed onto the target's name. So a write that fails
leaves the earlier file as it was, a reader never sees half a file, and nothing is
written *through* whatever is at the name: a symbolic link, a FIFO, a device node,
a socket or a folder there is refused (:class:`OutputError`) before anything is
written. A regular file there is replaced by the rename (its name, not its bytes:
another name of the same file keeps them).

The same rules as voiga's own outputs (docs/files.md).
"""
from __future__ import annotations

import os
import shutil
import stat
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

__all__ = ["OutputError", "check_output", "new_file", "write_text", "write_bytes", "copy_file", "save_figure"]


class OutputError(ValueError):
    """An output path that must not be written: what is there is not a regular file."""


KINDS = ((stat.S_ISLNK, "a symbolic link"), (stat.S_ISDIR, "a folder"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
         (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))
"""What a file that is not a regular one is called in messages."""


def _kind(mode: int) -> str:
    return next((name for test, name in KINDS if test(mode)), "not a regular file")


def check_output(path: str | Path) -> Path:
    """``path`` as a Path when nothing or a regular file is at it (the link itself is
    looked at, not its target); OutputError naming what is there otherwise."""
    path = Path(path)
    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        return path
    except OSError as err:
        raise OutputError(f"{path}: cannot be written ({err.strerror})") from None
    if not stat.S_ISREG(mode):
        raise OutputError(f"{path} is {_kind(mode)}, not a regular file: not written (the tools write "
                          f"their outputs only as regular files)")
    return path


@contextmanager
def new_file(path: str | Path) -> Iterator[Path]:
    """A new, empty file beside ``path`` (same folder and suffix, created
    exclusively, permissions as ``open`` would give) for the caller to write; renamed
    onto ``path`` when the block ends without an exception, removed otherwise.
    OutputError (before anything is written) when ``path`` holds something that is
    not a regular file. The folder must exist."""
    path = check_output(path)
    fd, name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=f".part{path.suffix}",
                                dir=path.parent if str(path.parent) else ".")
    os.close(fd)
    tmp = Path(name)
    try:
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        yield tmp
        check_output(path)   # something else put there meanwhile is not replaced either
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def write_text(path: str | Path, text: str) -> Path:
    """Write ``text`` to ``path`` (:func:`new_file`)."""
    with new_file(path) as tmp:
        tmp.write_text(text)
    return Path(path)


def write_bytes(path: str | Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` (:func:`new_file`)."""
    with new_file(path) as tmp:
        tmp.write_bytes(data)
    return Path(path)


def copy_file(source: str | Path, path: str | Path) -> Path:
    """Copy ``source`` (its bytes and times) to ``path`` (:func:`new_file`)."""
    with new_file(path) as tmp:
        shutil.copy2(source, tmp)
    return Path(path)


def save_figure(fig: object, path: str | Path, **kwargs: object) -> Path:
    """``fig.savefig`` to ``path`` (:func:`new_file`), in the format its suffix names
    (PNG without one)."""
    path = Path(path)
    with new_file(path) as tmp:
        fig.savefig(tmp, format=path.suffix.lstrip(".").lower() or "png", **kwargs)  # type: ignore[attr-defined]
    return path
