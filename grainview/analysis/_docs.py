"""The numpydoc entries the analysis functions share, and the step that puts them in place.

Most functions of the analysis (and the figures, :mod:`grainview.plot._docs`) take the same
``ds``, ``walls``, ``near``, ``kind``...; the numpydoc entry of each is written once, in
:data:`FRAGMENTS`. A docstring names one by a line holding only ``{name}``, indented as the
entry should be; :func:`fill_doc` (a decorator) replaces that line by the fragment, indented
alike, when the module is imported, so ``help()``, IDEs, ``ds.grain`` and the documentation
read the whole entry (as cf_xarray's ``_build_docstring`` does).
"""

from __future__ import annotations

import re

FRAGMENTS = {
    "ds": """\
ds : xarray.Dataset
    A dataset of the contract (docs/schema.md), eager or chunked along ``time``.""",
    "ds_short": """\
ds : xarray.Dataset
    A dataset of the contract.""",
    "near": """\
near : float, optional
    Which pairs are contacts (:func:`grainview.analysis.contacts.in_network`): None (default) the
    force-bearing ones, f_n > 0; a gap threshold in m adds the pairs with gap <= ``near``
    (they carry f_n = 0); ``np.inf`` every pair the file holds.""",
    "time_averaged": """\
time : str, int, slice or sequence of int, default "residual"
    The snapshots averaged over (:func:`grainview.analysis.snapshots.select_snapshots`):
    ``"residual"`` the residual state, eps_q >= 0.3 (for a run that stops short of it, the
    last part of the run), ``"all"`` or None every snapshot, a snapshot index, a slice or a
    sequence of indices.""",
    "bins": """\
bins : int, default 36
    Number of angular sectors of [0, pi), centred on theta_k = k pi/bins.""",
    "kind": """\
kind : {"all", "simple", "double"}, default "all"
    The contacts used: all, simple (vertex–edge and disk contacts) or double (edge–edge)
    ones (also 1, 2, "s", "d"; :func:`grainview.analysis.contacts.kind_code`).""",
    "walls": """\
walls : bool, default False
    Include the particle–wall contacts (default: particle–particle only).""",
}
"""Numpydoc entries by name, unindented (the description four spaces in)."""

_PLACE = re.compile(r"^([ \t]*)\{(\w+)\}[ \t]*$", re.M)


def build_docstring(doc: str | None, fragments: dict | None = None) -> str | None:
    """``doc`` with every line holding only ``{name}`` replaced by ``fragments[name]`` (default
    :data:`FRAGMENTS`), each line of the fragment indented as the placeholder was.

    Raises
    ------
    KeyError
        When a placeholder names no fragment (a typo must not reach the rendered help).
    """
    if doc is None:  # python -OO
        return None
    fragments = FRAGMENTS if fragments is None else fragments

    def fragment(match):
        indent, name = match.groups()
        if name not in fragments:
            raise KeyError(f"docstring fragment {{{name}}}: none of that name among {sorted(fragments)}")
        return "\n".join(indent + line if line else line for line in fragments[name].split("\n"))

    return _PLACE.sub(fragment, doc)


def fill_doc(func):
    """Decorator: ``func`` with its docstring's fragments in place (:func:`build_docstring`)."""
    func.__doc__ = build_docstring(func.__doc__)
    return func
