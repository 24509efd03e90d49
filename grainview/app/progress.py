"""The progress of a study whose samples run side by side in worker processes, and the signals
that stop them: a bar per sample in a terminal, else a line now and then; Ctrl-C or SIGTERM
sent to the command alone stops its workers too. The signal handling itself is the solver's
(:func:`solver.interrupt.handling`)."""

from __future__ import annotations

import contextlib
import signal
import sys

from solver.engine import PROGRESS_LINE_SECONDS, handling


@contextlib.contextmanager
def workers_stop_with_me():
    """While the study's samples run in worker processes: Ctrl-C or SIGTERM sent to this
    process alone (not to its process group, as a terminal or a batch scheduler sends them)
    stops the workers too, after their current step, as Ctrl-C does (a compaction writes its
    checkpoint, a test keeps its snapshots); this process then waits for them and stops.
    Yields ``{"signal": the signal received, or None}``. Only in the main thread."""
    import multiprocessing
    import os

    state = {"signal": None}

    def handler(signum, _frame):
        state["signal"] = signum
        for child in multiprocessing.active_children():
            os.kill(child.pid, signal.SIGINT)

    with handling(handler, (signal.SIGINT, signal.SIGTERM)):
        yield state


class SampleProgress:
    """The progress of one sample of a study run side by side with the others: a tqdm bar at
    its own line in a terminal, else a line every :attr:`every` seconds (steps done, elapsed,
    expected to go). Called as ``progress(total, desc)`` (:func:`solver.interrupt.progress_bar`);
    picklable, for the worker processes."""

    every = PROGRESS_LINE_SECONDS

    def __init__(self, terminal, position=0, label=""):
        self.terminal, self.position, self.label = terminal, position, label

    @classmethod
    def for_jobs(cls, flag):
        """The progress of side-by-side samples for the command line's ``--progress`` (None:
        auto, True: on, False: off): None when off."""
        if flag is False:
            return False
        return cls(terminal=sys.stderr.isatty() or flag is True)

    def at(self, position, label):
        """The progress of the sample ``label``, shown at line ``position``."""
        sample = SampleProgress(self.terminal, position, label)
        sample.every = self.every
        return sample

    def __call__(self, total, desc):
        if self.terminal:
            from tqdm.std import tqdm

            return tqdm(total=total, desc=f"{self.label}: {desc}", unit="step", position=self.position, leave=False)
        return ProgressLines(total, f"{self.label}: {desc}", self.every)


class ProgressLines:
    """A progress bar as lines on stdout, one every ``every`` seconds (a log file's progress)."""

    def __init__(self, total, desc, every):
        import time

        self.total, self.desc, self.every, self.done = total, desc, every, 0
        self.start = self.last = time.monotonic()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False

    def update(self, n):
        import time

        self.done += n
        now = time.monotonic()
        if now - self.last >= self.every:
            self.last = now
            elapsed = now - self.start
            print(f"{self.desc}: step {self.done} of at most {self.total}, {elapsed / 60:.0f} min", flush=True)
