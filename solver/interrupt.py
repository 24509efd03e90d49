"""Long runs that stop cleanly: Ctrl-C as a flag checked between whole steps, the progress
bar, and the message that tells how to resume an interrupted biaxial test."""

from __future__ import annotations

import contextlib
import os
import shlex
import signal
import sys


@contextlib.contextmanager
def interruptible():
    """Turn Ctrl-C into a flag checked between steps, so a run stops after a whole step."""
    state = {"stop": False}
    if sys.platform == "win32" or signal.getsignal(signal.SIGINT) is None:
        yield state
        return
    try:
        previous = signal.signal(signal.SIGINT, lambda *_: state.__setitem__("stop", True))
    except ValueError:  # not the main thread
        yield state
        return
    try:
        yield state
    finally:
        signal.signal(signal.SIGINT, previous)


def progress_bar(total, desc, progress):
    """A tqdm bar of ``total`` steps; ``progress`` None: shown when stderr is a terminal."""
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
