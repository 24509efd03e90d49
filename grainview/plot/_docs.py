"""The docstring entries the figure functions share, and the step that puts them in place.

Most figure functions take the same ``data``, ``ax``, ``label``, ``time``, ``walls``... and
return the axes they drew on; the numpydoc entry of each is written once: the analysis's
(:data:`grainview.analysis._docs.FRAGMENTS`: ``ds``, ``walls``, ``kind``, ``near``...) and the
figures' own here. A docstring names one by a line holding only ``{name}``, indented as the
entry should be; :func:`fill_doc` puts the entry in place when the module is imported
(:func:`grainview.analysis._docs.build_docstring`).
"""

from __future__ import annotations

from ..analysis import _docs as _analysis_docs

FRAGMENTS = {
    **_analysis_docs.FRAGMENTS,
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
    "time_drawn": """\
time : int, default -1
    Index of the snapshot drawn (negative counts from the end).""",
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
    "map_options": """\
**options
    Keyword arguments of :func:`plot_particle_map` (``reference``, ``walls``, ``cmap``).""",
    "fn_forces": """\
fn : array_like of float
    Normal forces, N.""",
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
"""Numpydoc entries by name, unindented (the description four spaces in): the analysis's and
the figures' own."""


def build_docstring(doc: str | None) -> str | None:
    """``doc`` with its ``{name}`` lines replaced by :data:`FRAGMENTS`
    (:func:`grainview.analysis._docs.build_docstring`)."""
    return _analysis_docs.build_docstring(doc, FRAGMENTS)


def fill_doc(func):
    """Decorator: ``func`` with its docstring's fragments in place (:func:`build_docstring`)."""
    func.__doc__ = build_docstring(func.__doc__)
    return func
