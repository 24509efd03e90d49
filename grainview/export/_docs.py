"""The numpydoc entries the writers share (their input dataset, folder and stride), put in place
by :func:`fill_doc` as the analysis's are (:mod:`grainview.analysis._docs`)."""

from __future__ import annotations

from ..analysis._docs import FRAGMENTS as ANALYSIS_FRAGMENTS
from ..analysis._docs import build_docstring

FRAGMENTS = {
    **ANALYSIS_FRAGMENTS,
    "written": """\
ds : xarray.Dataset
    A grainview dataset.
out_dir : str or path-like
    Output folder, created if needed.
every : int, default 1
    Write every ``every``-th snapshot (the last always included).""",
}
"""The analysis's entries and the writers' own, unindented (the description four spaces in)."""


def fill_doc(func):
    """Decorator: ``func`` with its docstring's fragments in place (:data:`FRAGMENTS`)."""
    func.__doc__ = build_docstring(func.__doc__, FRAGMENTS)
    return func
