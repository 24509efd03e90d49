"""One writer per file: an advisory lock held while a file of the contract is written.

The lock is ``flock`` on a small file beside the data file, ``.<name>.writer``, which also
names the process holding it for the error message. It is taken before the data file is read
or created and held while it is written, compressed or made netCDF-3 again, so it survives
the data file being replaced by a rename. The kernel releases it when the process ends, so a
crashed writer never leaves a stale lock: its note stays behind, unlocked, and the next
process that takes the lock takes it over and removes it when done. A second writer — a
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


def being_written(path) -> bool:
    """Whether a process is writing ``path`` now, as far as a reader can tell without taking
    the lock (which would make a writer starting at that moment fail): the note names a
    process of this machine that is alive, or one of another machine (which cannot be
    asked). A killed writer's note names a process that is gone: False."""
    text = _holder(os.fspath(path)) if os.path.exists(_note_path(os.fspath(path))) else None
    if text is None:
        return False
    words = text.split()
    if len(words) != 4 or words[0] != "process" or not words[1].isdigit():
        return True  # a note being written: its process has just taken the lock
    return words[3] != socket.gethostname() or process_alive(int(words[1]))


def process_alive(pid: int) -> bool:
    """Whether process ``pid`` exists on this machine (POSIX; True where it cannot be asked)."""
    if fcntl is None:  # Windows: os.kill(pid, 0) would send CTRL_C_EVENT
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process
        return True
    return True


class WriterLock:
    """Hold the writer's lock on ``path`` (existing or not yet created) until :meth:`release`.

    Raises :class:`FileLockedError` naming the holder when another process holds it, and
    OSError when the note cannot be created (a missing or read-only folder)."""

    def __init__(self, path):
        self.path = os.fspath(path)
        self._fd = None
        if fcntl is None:
            return
        note = _note_path(self.path)
        while True:
            fd = os.open(note, os.O_RDWR | os.O_CREAT, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                os.close(fd)
                raise FileLockedError(f"{self.path} is being written by {_holder(self.path)}; wait for that run to "
                                      "end or stop it first (a crashed writer releases the lock by itself)") from None
            try:  # the note locked is still the one at its path: not one a releasing holder removed
                current = os.path.samestat(os.fstat(fd), os.stat(note))
            except FileNotFoundError:
                current = False
            if current:
                break
            os.close(fd)
        self._fd = fd
        try:
            os.ftruncate(fd, 0)
            os.write(fd, f"process {os.getpid()} on {socket.gethostname()}".encode())
        except OSError:
            pass  # the note's text is a courtesy; the lock holds without it

    @property
    def held(self) -> bool:
        """True until :meth:`release` (always False without ``fcntl``)."""
        return self._fd is not None

    @staticmethod
    def check_free(path) -> None:
        """Raise :class:`FileLockedError` if another process holds ``path``'s lock (e.g. before
        replacing the file with ``overwrite``); take nothing."""
        if fcntl is None:
            return
        WriterLock(path).release()

    def release(self) -> None:
        """Remove the note and release the lock (nothing when already released)."""
        if self._fd is None:
            return
        try:
            os.remove(_note_path(self.path))  # while still held: a waiting process retries on the new note
        except OSError:
            pass
        fcntl.flock(self._fd, fcntl.LOCK_UN)
        os.close(self._fd)
        self._fd = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.release()
