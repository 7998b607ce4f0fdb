"""Finish a flush that a killed voiga left half done (docs/hdf5.md, "Crash safety").

voiga writes its result files through a journaled HDF5 driver (src/platform/journal_vfd.c):
a flush first appends its writes to the end of the file as a journal with a footer,
then writes them in place, then truncates the journal away. A file whose writer was
killed between the footer and the truncation ends in a complete journal; applying it
again gives the file as that flush left it. :func:`recover` does that, holding the
file's exclusive ``flock`` (a live writer holds it while it flushes, so a file being
written is never touched). The same format and steps as ``voiga_journal_recover``.
"""
from __future__ import annotations

import errno
import fcntl
import os
import stat
import struct
import zlib
from pathlib import Path

MAGIC = b"VOIGAJ01"
FOOTER = struct.Struct("<8sQQQQ")
"""magic, journal start, records' length, file size after the flush, CRC-32 of the records."""


def _records(data: bytes) -> list[tuple[int, bytes]] | None:
    """(address, bytes) of each record, or None if they do not parse."""
    out, at = [], 0
    while at + 16 <= len(data):
        addr, size = struct.unpack_from("<QQ", data, at)
        if size > len(data) - at - 16:
            return None
        out.append((addr, data[at + 16:at + 16 + size]))
        at += 16 + size
    return out if at == len(data) else None


def recover(path: str | Path) -> bool:
    """Apply the complete journal a killed writer left at the end of ``path``; True if
    there was one. Nothing when there is none, when the file cannot be opened for
    writing or is not a regular file, while another process holds its ``flock`` (a
    writer at work), or when the writes fail (a full disk: the journal stays, for a
    later call)."""
    try:
        # (O_NONBLOCK: a FIFO at the name must not make the open wait)
        fd = os.open(path, os.O_RDWR | os.O_NONBLOCK | os.O_NOCTTY)
    except OSError:
        return False
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            return False    # a FIFO, a device: nothing of ours, never written
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as err:
            if err.errno in (errno.EWOULDBLOCK, errno.EAGAIN):
                return False
            raise
        size = os.fstat(fd).st_size
        if size < FOOTER.size:
            return False
        magic, start, length, final, check = FOOTER.unpack(os.pread(fd, FOOTER.size, size - FOOTER.size))
        if magic != MAGIC or start + length + FOOTER.size != size or final > start:
            return False
        data = os.pread(fd, length, start)
        records = _records(data) if zlib.crc32(data) == check else None
        if records is None:
            return False
        try:
            for addr, chunk in records:
                os.pwrite(fd, chunk, addr)
            os.ftruncate(fd, final)
        except OSError:  # a full disk: the journal stays for a later try
            return False
        return True
    finally:
        os.close(fd)
