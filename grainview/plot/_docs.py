"""The docstring fragments the figure functions share, and the step that puts them in place.

Most figure functions take the same ``data``, ``ax``, ``label``, ``time``, ``walls``... and
return the axes they drew on; the numpydoc entry of each is written once here, in
:data:`FRAGMENTS`. A docstring names one by a line holding only ``{name}``, indented as the
entry should be; :func:`fill_doc` (a decorator) replaces that line by the fragment, indented
alike, when the module is imported, so ``help()``, IDEs and the documentation read the whole
entry (as cf_xarray's ``_build_docstring`` does).
"""

from __future__ import annotations

import re

FRAGMENTS = {
    "data": """\
data : xarray.Dataset, dict or list
    One dataset of the contract, or several to compare on the same axes as ``{label: ds}``
    or ``[(label, ds), ...]``.""",
    "data_one": """\
data : xarray.Dataset, dict or list
    One dataset of the contract (a dict or list must hold exactly one): this figure draws
    one sample.""",
    "ax": """\
ax : matplotlib.axes.Axes, optional
    The axes to draw on (default: new axes on a new figure).""",
    "ax_polar": """\
ax : matplotlib.axes.Axes, optional
    Polar axes to draw on (default: new polar axes on a new figure).""",
    "label": """\
label : str, optional
    Legend label of a single dataset (None: no legend entry), so that successive calls on
    the same axes build a comparison.""",
    "time_averaged": """\
time : str, int, slice or sequence of int, default "residual"
    The snapshots averaged over (:func:`grainview.analysis.snapshots.select_snapshots`):
    ``"residual"`` the residual state, eps_q >= 0.3 (for a run that stops short of it, the
    last part of the run), ``"all"`` or None every snapshot, a snapshot index, a slice or a
    sequence of indices.""",
    "time_drawn": """\
time : int, default -1
    Index of the snapshot drawn (negative counts from the end).""",
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
    "normalise": """\
normalise : bool, default True
    Divide each snapshot's profile by its mean normal force <f_n> over the same contacts
    (dimensionless); otherwise in N.""",
    "angle": """\
angle : float, default 45
    Alignment angle, degrees.""",
    "min_size": """\
min_size : int, default 3
    Fewest particles of a chain.""",
    "particles": """\
particles : bool, default True
    Draw the particles under the network.""",
    "line_kw": """\
**line_kw
    Keyword arguments of ``matplotlib.axes.Axes.plot``.""",
    "line_kw_colour": """\
**line_kw
    Keyword arguments of ``matplotlib.axes.Axes.plot`` (``color`` applies when a single
    sample is drawn).""",
    "panel_kw": """\
**kw
    Keyword arguments of the panel function, passed to both panels.""",
    "returns_axes": """\
matplotlib.axes.Axes
    The axes drawn on.""",
    "returns_panels": """\
matplotlib.figure.Figure
    The figure with panels (a) and (b).""",
}
"""Numpydoc entries by name, unindented (the description four spaces in)."""

_PLACE = re.compile(r"^([ \t]*)\{(\w+)\}[ \t]*$", re.M)


def build_docstring(doc: str | None) -> str | None:
    """``doc`` with every line holding only ``{name}`` replaced by ``FRAGMENTS[name]``, each
    line of the fragment indented as the placeholder was.

    Raises
    ------
    KeyError
        When a placeholder names no fragment (a typo must not reach the rendered help).
    """
    if doc is None:  # python -OO
        return None

    def fragment(match):
        indent, name = match.groups()
        if name not in FRAGMENTS:
            raise KeyError(f"docstring fragment {{{name}}}: none of that name in grainview.plot._docs.FRAGMENTS")
        return "\n".join(indent + line if line else line for line in FRAGMENTS[name].split("\n"))

    return _PLACE.sub(fragment, doc)


def fill_doc(func):
    """Decorator: ``func`` with its docstring's fragments in place (:func:`build_docstring`)."""
    func.__doc__ = build_docstring(func.__doc__)
    return func
