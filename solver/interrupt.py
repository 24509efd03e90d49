"""Long runs that stop cleanly: Ctrl-C (SIGINT) and SIGTERM (what batch schedulers send at a
wall-time limit) as a flag checked between whole steps, the progress bar, and the message that
tells how to resume an interrupted biaxial test."""

from __future__ import annotations

import contextlib
import os
import shlex
import signal
import sys

from grainview.contract.signals import STOP_SIGNALS, Terminated, handling, sigterm_raises  # noqa: F401 (their home)

PROGRESS_LINE_SECONDS = 60.0
"""Seconds between two progress lines of a run whose progress goes to a log, not a terminal
(the command line's side-by-side samples)."""


@contextlib.contextmanager
def interruptible():
    """Turn Ctrl-C and SIGTERM into a flag checked between steps, so a run stops after a whole
    step: ``state["stop"]`` becomes True and ``state["signal"]`` names the signal."""
    state = {"stop": False, "signal": None}
    if sys.platform == "win32" or signal.getsignal(signal.SIGINT) is None:
        yield state
        return

    def handler(signum, _frame):
        state["stop"] = True
        state["signal"] = signum

    with handling(handler):
        yield state


def stop_exception(state) -> BaseException:
    """The exception that ends a run stopped by ``state``'s signal: :class:`Terminated` for
    SIGTERM, KeyboardInterrupt for Ctrl-C."""
    return Terminated() if state.get("signal") == signal.SIGTERM else KeyboardInterrupt()


def stop_reason(state) -> str:
    return "terminated (SIGTERM)" if state.get("signal") == signal.SIGTERM else "interrupted"


def progress_bar(total, desc, progress):
    """A tqdm bar of ``total`` steps; ``progress`` None: shown when stderr is a terminal, a
    bool: shown or not, a callable: ``progress(total, desc)`` makes the bar (any context
    manager with ``update(n)``; the ensemble runner reports its workers' steps so)."""
    if callable(progress):
        return progress(total, desc)
    enabled = sys.stderr.isatty() if progress is None else bool(progress)
    from tqdm.std import tqdm

    if enabled:
        try:  # a widget in Jupyter when ipywidgets is there; tqdm.auto warns otherwise
            import ipywidgets  # noqa: F401
            from tqdm.auto import tqdm
        except ImportError:
            pass
    return tqdm(total=total, desc=desc, unit="step", disable=not enabled, leave=False)


def resume_instructions(path) -> str:
    """How to resume the run written to ``path``: the shell command and the Python call."""
    path = os.path.abspath(os.fspath(path))
    return (f"resume it with:  {shlex.quote(sys.executable)} -m solver.restart {shlex.quote(path)}\n"
            f"or in Python:    from solver.restart import resume; resume({path!r})")
