"""Signals that stop a program cleanly: SIGTERM (what batch schedulers send at a wall-time
limit) raised as :class:`Terminated` where a file is being written, so that its ``except`` and
``finally`` clauses remove a temporary file and leave the user's file as it was; and the handlers
of Ctrl-C and SIGTERM set for a block and restored after it. The solver's runs
(:mod:`solver.interrupt`) and the readers' conversions both stand on it."""

from __future__ import annotations

import contextlib
import signal
import sys

__all__ = ["STOP_SIGNALS", "Terminated", "handling", "sigterm_raises"]


class Terminated(SystemExit):
    """A run stopped by SIGTERM after a whole step: a SystemExit with the shell's code for it,
    143, so that a script ends quietly with that code once every ``with`` block has closed its
    file (a Ctrl-C raises KeyboardInterrupt instead)."""

    def __init__(self, code=143):  # the code as an argument: unpickled from a worker process as Terminated(143)
        super().__init__(code)


STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)

@contextlib.contextmanager
def handling(handler, signals=STOP_SIGNALS):
    """Within the block, ``handler(signum, frame)`` handles each of ``signals``; the previous
    handlers are restored after it (the default action where the previous one was not set
    from Python). Yields True, or False outside the main thread, where no handler can be set
    and none is."""
    previous = {}
    try:
        for signum in signals:
            previous[signum] = signal.signal(signum, handler)
    except ValueError:  # not the main thread
        for signum, old in previous.items():
            signal.signal(signum, old if old is not None else signal.SIG_DFL)
        yield False
        return
    try:
        yield True
    finally:
        for signum, old in previous.items():
            signal.signal(signum, old if old is not None else signal.SIG_DFL)


@contextlib.contextmanager
def sigterm_raises():
    """Within the block, SIGTERM raises :class:`Terminated` at once (at the next Python
    instruction), for the phases that are not a loop of steps: creating, compressing or
    decompressing a run's file, whose ``except``/``finally`` clauses then remove their
    temporary file and leave the run's file as it was. Only in the main thread (a worker
    thread cannot set handlers: there it does nothing); the previous handler is restored."""
    if sys.platform == "win32":
        yield
        return

    def handler(_signum, _frame):
        raise Terminated()

    with handling(handler, (signal.SIGTERM,)):
        yield
