"""No module of the application (grainview/app/) is longer than :data:`MAX_LINES`: a module
that grows past it is split by what it holds (the command line parses arguments and calls
the application; the workflows, settings and progress are modules of their own)."""

from __future__ import annotations

from pathlib import Path

APP = Path(__file__).resolve().parents[2] / "grainview" / "app"
MAX_LINES = 600
"""The longest a module of grainview/app may be, in lines."""


def test_no_application_module_is_over_the_limit():
    modules = sorted(APP.glob("*.py"))
    assert any(path.name == "cli.py" for path in modules)  # the folder the test means
    long = {path.name: n for path in modules if (n := len(path.read_text(encoding="utf-8").splitlines())) > MAX_LINES}
    assert not long, f"grainview/app modules over {MAX_LINES} lines: {long}"
