"""One writer per file: a second writer or resumer is refused at once, naming the first; a
killed writer leaves no lock behind."""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from grainview.contract.locks import FileLockedError
from grainview.contract.writer import SnapshotWriter

pytest.importorskip("fcntl")
REPO = Path(__file__).resolve().parents[2]

HOLDER = """
import sys, time
import numpy as np
from grainview.contract.writer import SnapshotWriter
w = SnapshotWriter.create(sys.argv[1], radius=np.ones(3), n_vertices=0, mass=1.0, inertia=1.0)
print("ready", flush=True)
time.sleep(60)
"""


def _holder(path):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")]))
    child = subprocess.Popen([sys.executable, "-c", HOLDER, str(path)], env=env, stdout=subprocess.PIPE, text=True)
    assert child.stdout.readline().strip() == "ready"
    return child


def test_a_second_writer_is_refused_naming_the_first_and_the_file_is_untouched(tmp_path):
    path = tmp_path / "run.nc"
    child = _holder(path)
    try:
        before = path.read_bytes()
        with pytest.raises(FileLockedError, match=f"process {child.pid}"):
            SnapshotWriter.open_append(path)
        with pytest.raises(FileLockedError, match="being written"):
            SnapshotWriter.create(path, radius=np.ones(3), n_vertices=0, mass=1.0, inertia=1.0, overwrite=True)
        assert path.read_bytes() == before
    finally:
        child.kill()
        child.wait()
    # killed: the kernel released the lock; the stale note does not matter
    writer = SnapshotWriter.open_append(path)
    writer.close()
    assert not (tmp_path / ".run.nc.writer").exists()


def test_the_lock_is_released_on_close(tmp_path):
    path = tmp_path / "run.nc"
    first = SnapshotWriter.create(path, radius=np.ones(3), n_vertices=0, mass=1.0, inertia=1.0)
    with pytest.raises(FileLockedError):
        SnapshotWriter.open_append(path)
    first.close()
    SnapshotWriter.open_append(path).close()


def test_a_note_removed_by_a_releasing_holder_is_not_taken(tmp_path, monkeypatch):
    """The lock is flock on the note ``.NAME.writer``, which a holder removes as it releases: a
    process that opened the note just before that must not hold the removed one (two writers
    would then hold "the" lock), so it takes the note at the path again."""
    from grainview.contract import locks

    path = tmp_path / "run.nc"
    note = tmp_path / ".run.nc.writer"
    real = locks.fcntl.flock
    taken = []

    def released_meanwhile(fd, op):
        if not taken and op & locks.fcntl.LOCK_EX:
            os.remove(note)  # the previous holder released between our open and our flock
        taken.append(os.fstat(fd).st_ino)
        return real(fd, op)

    monkeypatch.setattr(locks.fcntl, "flock", released_meanwhile)
    lock = locks.WriterLock(path)
    monkeypatch.undo()
    assert len(taken) >= 2 and note.exists() and os.stat(note).st_ino == taken[-1]
    assert note.read_text() == f"process {os.getpid()} on {__import__('socket').gethostname()}"
    with pytest.raises(FileLockedError, match=f"process {os.getpid()}"):
        subprocess_lock(path)
    lock.release()
    assert not note.exists()


def subprocess_lock(path):
    """Take ``path``'s lock in another process; raise what it raised."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")]))
    done = subprocess.run([sys.executable, "-c", "import sys\nfrom grainview.contract.locks import WriterLock\n"
                           "try:\n    WriterLock(sys.argv[1])\nexcept Exception as e:\n    print(e)\n",
                           str(path)], env=env, capture_output=True, text=True, timeout=60)
    if done.stdout.strip():
        raise FileLockedError(done.stdout.strip())
