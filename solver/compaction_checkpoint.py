"""Checkpoints of an isotropic compaction, so that a compaction stopped or killed part-way
resumes where it was, bit for bit, instead of starting again from its deposit.

A compaction's state is the simulation's (particles, walls, the warm start of the next step,
time, step index: what a snapshot of the data contract holds, :mod:`solver.restart`; the
unconverged steps so far) and the loop's own
(:class:`solver.compaction_progress.CompactionProgress`: steps taken, the equilibrium test's
window of wall stresses and strain rates, the largest inertia number so far, the walls' target
stress and own speed cap). :class:`CompactionCheckpoint` writes both into
one file of the contract (one snapshot, ``scene = "compaction"``; the loop's state as global
attributes ``checkpoint_*``) every ``every_steps`` steps or ``every_seconds`` of wall time, and
when Ctrl-C or SIGTERM stops the compaction. Each checkpoint is written whole under a hidden
temporary name, synced, then renamed over the previous one, so a kill at any moment leaves the
previous checkpoint or the new one, never half of one.

The file records what it is the compaction of (``checkpoint_of``: the preparation and the
solver parameters asked for, as JSON); :meth:`CompactionCheckpoint.load` refuses, in one line,
a checkpoint of another sample. Writing a checkpoint changes nothing of the run: the steps
after it are those of a run that was never checkpointed.
"""

from __future__ import annotations

import json
import os
import time
from dataclasses import asdict

from grainview.contract.errors import FileFormatError

from .compaction_progress import CompactionProgress

CHECKPOINT_SECONDS = 600.0
"""Default wall time between two checkpoints, s: at most ten minutes of a compaction is redone
after a kill (a 14,400-pentagon step takes about 0.1-0.4 s, a checkpoint file a fraction of it)."""

SCENE = "compaction"
"""The ``scene`` attribute of a checkpoint file."""


def describe(preparation, parameters) -> str:
    """What a compaction is of, as the JSON a checkpoint records: the preparation's fields and
    every solver parameter, those asked for (``parameters``, a dict of
    :class:`solver.parameters.Parameters` fields) and the defaults of the others, so that a
    default given explicitly is the same compaction."""
    from .parameters import Parameters

    prep = asdict(preparation) if preparation is not None else {}
    return json.dumps({"preparation": prep, "parameters": asdict(Parameters(**(parameters or {})))},
                      sort_keys=True, default=str)


class CompactionCheckpoint:
    """Where and how often a compaction is checkpointed, and the checkpoint's reading back.

    Parameters
    ----------
    path : str or path-like
        The checkpoint file (a file of the contract, netCDF-3).
    of : str
        What the compaction is of (:func:`describe`); a checkpoint of anything else is refused.
    every_steps : int, optional
        Write a checkpoint every this many compaction steps.
    every_seconds : float, optional
        Write a checkpoint when this much wall time has passed since the last one (s); default
        :data:`CHECKPOINT_SECONDS` when ``every_steps`` is not given.
    """

    def __init__(self, path, of="", every_steps=None, every_seconds=None):
        self.path = os.fspath(path)
        self.of = str(of)
        self.every_steps = None if every_steps is None else int(every_steps)
        self.every_seconds = (CHECKPOINT_SECONDS if every_steps is None and every_seconds is None
                              else every_seconds)
        self._last = time.monotonic()
        self.written = 0  # checkpoints written by this object

    def due(self, steps) -> bool:
        """Whether a checkpoint is due after ``steps`` compaction steps."""
        if self.every_steps is not None and steps % self.every_steps == 0:
            return True
        return self.every_seconds is not None and time.monotonic() - self._last >= self.every_seconds

    def write(self, sim, progress: CompactionProgress):
        """Write the simulation and the loop's state as the checkpoint, replacing the previous
        one atomically (a temporary file synced, renamed, the folder synced). The simulation's
        unconverged-step count is left as it was."""
        from .interrupt import sigterm_raises
        from .output import Recorder

        folder, name = os.path.split(os.path.abspath(self.path))
        temporary = os.path.join(folder, f".{name}.{os.getpid()}.checkpoint")
        unconverged = sim.take_unconverged()
        attrs = {"scene": SCENE, "checkpoint_of": self.of, "sigma0_Pa": float(sim.history.sigma0),
                 "checkpoint_unconverged_steps": int(unconverged.steps),
                 "checkpoint_unconverged_residual": float(unconverged.residual),
                 "checkpoint_unconverged_local_law_residual": float(unconverged.local_law_residual),
                 **progress.attrs()}
        try:
            with sigterm_raises():  # a SIGTERM now stops here, the previous checkpoint kept
                with Recorder(temporary, sim, attrs=attrs, overwrite=True, compress=False) as recorder:
                    recorder.write()
                fd = os.open(temporary, os.O_RDONLY)
                try:
                    os.fsync(fd)
                finally:
                    os.close(fd)
                os.replace(temporary, self.path)
                _sync_folder(folder)
        except BaseException:
            if os.path.exists(temporary):
                os.remove(temporary)
            raise
        finally:
            sim.unconverged = unconverged
        self._last = time.monotonic()
        self.written += 1

    def exists(self) -> bool:
        return os.path.exists(self.path)

    def load(self):
        """The checkpointed compaction: ``(sim, progress)``, the :class:`Simulation` whose next
        step is the one after the checkpoint (its warm start, its unconverged steps so far, its
        history's confining stress) and the loop's :class:`CompactionProgress`. Raises
        :class:`FileFormatError` naming the file when it is not a compaction checkpoint, or one
        of another sample (``of``)."""
        from grainview.contract.reader import ContractFile

        from .restart import simulation_from_state, snapshot_state
        from .sample_history import SampleHistory
        from .stepper import Unconverged

        with ContractFile(self.path) as ds:
            attrs = self._checked(ds)
            state = snapshot_state(ds, 0, self.path)
        sim = simulation_from_state(state, self.path)
        sim.history = SampleHistory(sigma0=float(attrs["sigma0_Pa"]))
        sim.unconverged = Unconverged(int(attrs["checkpoint_unconverged_steps"]),
                                      float(attrs["checkpoint_unconverged_residual"]),
                                      float(attrs["checkpoint_unconverged_local_law_residual"]))
        return sim, CompactionProgress.from_attrs(attrs)

    def check(self):
        """Refuse, as :meth:`load` does and without loading it, a file that is not a compaction
        checkpoint of this sample (:class:`FileFormatError`, one line)."""
        from grainview.contract.reader import ContractFile

        with ContractFile(self.path) as ds:
            self._checked(ds)

    def _checked(self, ds) -> dict:
        attrs = dict(ds.attrs)
        if attrs.get("scene") != SCENE or "checkpoint_steps" not in attrs or ds.n_snapshots != 1:
            raise FileFormatError(f"{self.path}: not a compaction checkpoint (expected one snapshot and "
                                  "checkpoint_* attributes); remove it or pass --overwrite")
        if self.of and attrs.get("checkpoint_of") != self.of:
            raise FileFormatError(f"{self.path} holds the compaction of another sample or with other "
                                  "settings; pass --overwrite to start this one again, or give the settings "
                                  "it was made with")
        return attrs

    def remove(self):
        """Remove the checkpoint (its compaction's sample is written elsewhere now)."""
        if os.path.exists(self.path):
            os.remove(self.path)


def _sync_folder(folder):
    """Sync a folder's entries to disk (a rename in it made durable); nothing where folders
    cannot be opened (Windows)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)
