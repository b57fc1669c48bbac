"""Writing files safely: one atomic writer for every file Bladesmith produces.

ARCHITECTURE.md, house style 8: a temporary file in the same folder, then ``os.replace``,
so a failed write never leaves a partial file or clobbers a good one.
"""
from __future__ import annotations

import os
import tempfile


def _mode_for(path: str) -> int:
    """The mode of the file being replaced, or what ``open()`` would give a new one."""
    try:
        return os.stat(path).st_mode & 0o7777
    except OSError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask


def atomic_write(path, data: bytes | str, encoding: str = "utf-8") -> None:
    """Write ``data`` to ``path`` through a temporary file in the same folder.

    The temporary file gets the final mode before ``os.replace`` (``mkstemp`` makes it
    private), is flushed and fsynced, and is removed again if anything fails. Raises
    ``OSError`` on failure; the file at ``path``, if any, is then untouched.
    """
    path = os.fspath(path)
    if isinstance(data, str):
        data = data.encode(encoding)
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(path) + ".", suffix=".tmp", dir=folder)
    try:
        os.chmod(tmp, _mode_for(path))
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise
