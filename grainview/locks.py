"""One writer per file: an advisory lock held while a file of the contract is written.

The lock is ``flock`` on the data file itself (POSIX; the kernel releases it when the process
ends, so a crashed writer never leaves a stale lock), and a small note beside it,
``.<name>.writer``, names the process holding it for the error message (the note is only
informative: a note whose file is not locked is stale and ignored). A second writer — a
re-queued batch job resuming a run that is still going, or a second run started with
``--overwrite`` on the same path — fails at once with one line naming the first.
On systems without ``fcntl`` (Windows) no lock is taken.
"""

from __future__ import annotations

import os
import socket

from .errors import GrainviewError

try:
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None


class FileLockedError(GrainviewError, OSError):
    """The file is being written by another process."""


def _note_path(path: str) -> str:
    directory, base = os.path.split(os.path.abspath(path))
    return os.path.join(directory, f".{base}.writer")


def _holder(path: str) -> str:
    try:
        with open(_note_path(path)) as fh:
            return fh.read().strip() or "another process"
    except OSError:
        return "another process"


class WriterLock:
    """Hold the writer's lock on ``path`` (an existing file) until :meth:`release`."""

    def __init__(self, path):
        self.path = os.fspath(path)
        self._fd = None
        if fcntl is None:
            return
        fd = os.open(self.path, os.O_RDONLY)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            raise FileLockedError(f"{self.path} is being written by {_holder(self.path)}; wait for that run to end "
                                  "or stop it first (a crashed writer releases the lock by itself)") from None
        self._fd = fd
        try:
            with open(_note_path(self.path), "w") as fh:
                fh.write(f"process {os.getpid()} on {socket.gethostname()}")
        except OSError:
            pass  # the note is a courtesy; the lock holds without it

    @staticmethod
    def check_free(path) -> None:
        """Raise :class:`FileLockedError` if another process holds ``path``'s lock (e.g. before
        replacing the file with ``overwrite``); take nothing. Only for files that are appended
        to (netCDF-3): HDF5 holds a shared lock of its own on a compressed file while a reader
        has it open, which is not a writer's (:func:`grainview.writer.is_compressed`)."""
        if fcntl is None or not os.path.exists(path):
            return
        WriterLock(path).release()

    def release(self) -> None:
        if self._fd is None:
            return
        try:
            os.remove(_note_path(self.path))
        except OSError:
            pass
        fcntl.flock(self._fd, fcntl.LOCK_UN)
        os.close(self._fd)
        self._fd = None
