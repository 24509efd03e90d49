"""Shared helpers of the figure modules: which datasets to draw, which snapshots, axis labels
with units taken from the ``units`` attributes, legends, and saving a figure as PNG and PDF.

Every figure function of :mod:`grainview.plot` takes either one dataset of the contract, or
several to compare on the same axes as a dict ``{label: ds}`` or a list of ``(label, ds)``
pairs; :func:`datasets` turns any of these into a list of ``(label, ds)``.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import xarray as xr

from ..contract.errors import ParameterError

EPS_Q_LABEL = r"$\varepsilon_q$"
"""Label of the x axis of every evolution (shear strain, dimensionless)."""

DIMENSIONLESS = ("", "1", None)


# -- which data --------------------------------------------------------------------------------

def datasets(data, label: str | None = None) -> list[tuple[str | None, xr.Dataset]]:
    """``[(label, ds), ...]`` from one dataset, a dict ``{label: ds}`` or a list of pairs.

    A single dataset gets ``label`` (None: no legend entry)."""
    if isinstance(data, xr.Dataset):
        return [(label, data)]
    if isinstance(data, dict):
        pairs = list(data.items())
    elif isinstance(data, (list, tuple)):
        pairs = list(data)
    else:
        raise ParameterError(f"data={type(data).__name__}: expected a dataset, a dict {{label: dataset}} "
                             "or a list of (label, dataset) pairs")
    if not pairs:
        raise ParameterError("data is empty: expected at least one dataset")
    for pair in pairs:
        if not (isinstance(pair, (list, tuple)) and len(pair) == 2 and isinstance(pair[1], xr.Dataset)):
            raise ParameterError(f"data item {pair!r}: expected a (label, dataset) pair")
    return [(str(lab), ds) for lab, ds in pairs]


def single_dataset(data, label: str | None = None) -> tuple[str | None, xr.Dataset]:
    """The one ``(label, ds)`` of ``data``; a map or a grey-level diagram draws one sample."""
    pairs = datasets(data, label)
    if len(pairs) != 1:
        raise ParameterError(f"data holds {len(pairs)} datasets: this figure draws one sample at a time "
                             "(call it once per sample, on separate axes)")
    return pairs[0]


def snapshot_index(ds: xr.Dataset, time=-1) -> int:
    """A single snapshot index (maps draw one snapshot); negative counts from the end."""
    from ..analysis.contacts import snapshot_index as index

    return index(ds, time)


def eps_q(ds: xr.Dataset) -> np.ndarray:
    """Shear strain eps_q of every snapshot (:func:`grainview.analysis.strain.strains`), as numbers."""
    from ..analysis.strain import strains
    return np.asarray(strains(ds)["eps_q"].values, dtype=float)


def values(da: xr.DataArray) -> np.ndarray:
    """The numbers of ``da`` (computing a lazy one) as a float array."""
    return np.asarray(da.values, dtype=float)


# -- axes and labels ---------------------------------------------------------------------------

def get_axes(ax=None, polar: bool = False):
    """``ax`` itself, or new axes on a new figure (polar ones when asked)."""
    if ax is not None:
        if polar and getattr(ax, "name", "") != "polar":
            raise ParameterError("ax: this figure needs polar axes (subplot_kw={'projection': 'polar'})")
        return ax
    import matplotlib.pyplot as plt
    _, ax = plt.subplots(subplot_kw={"projection": "polar"} if polar else None)
    return ax


def tidy_polar(ax):
    """Three radial ticks, in small type, along the 135 degree ray (between the lobes of a
    distribution elongated along 0 or 90 degrees), so that their labels stay readable."""
    from matplotlib.ticker import MaxNLocator

    ax.yaxis.set_major_locator(MaxNLocator(3))
    ax.set_rlabel_position(135)
    ax.tick_params(axis="y", labelsize="x-small")
    return ax


def new_figure(n_panels: int, polar=False, width: float = 4.5, height: float = 3.6):
    """A figure with ``n_panels`` axes side by side, marked (a), (b), ...; ``polar`` is one
    flag for all panels or one per panel. Returns (figure, list of axes)."""
    import matplotlib.pyplot as plt
    flags = list(polar) if isinstance(polar, (list, tuple)) else [bool(polar)] * n_panels
    fig = plt.figure(figsize=(width * n_panels, height), layout="constrained")
    axes = [fig.add_subplot(1, n_panels, k + 1, projection="polar" if flag else None)
            for k, flag in enumerate(flags)]
    for k, ax in enumerate(axes):
        ax.text(-0.14 if flags[k] else -0.18, 1.06, f"({chr(ord('a') + k)})", transform=ax.transAxes,
                fontweight="bold", va="bottom")
    return fig, axes


def format_units(units) -> str:
    """CF-style units ("rad-1", "kg m2", "m s-1") as mathtext ("rad$^{-1}$", "kg m$^{2}$")."""
    if units in DIMENSIONLESS:
        return ""
    return re.sub(r"([A-Za-z]+)(-?\d+)", r"\1$^{\2}$", str(units))


def axis_label(symbol: str, units=None) -> str:
    """``"symbol (units)"``, or ``symbol`` alone when the quantity is dimensionless."""
    text = format_units(units)
    return f"{symbol} ({text})" if text else symbol


def units_of(da: xr.DataArray) -> str | None:
    """The ``units`` attribute of ``da`` (None when absent)."""
    return da.attrs.get("units")


def set_labels(ax, xlabel: str | None = None, ylabel: str | None = None):
    """Set the axis labels that are given."""
    if xlabel is not None:
        ax.set_xlabel(xlabel)
    if ylabel is not None:
        ax.set_ylabel(ylabel)


LEGEND_INSIDE_MAX = 3
"""The most legend entries drawn inside the axes (:func:`finish`)."""


def finish(ax, pairs, title: str | None = None):
    """Legend when any curve is labelled, and the title. A legend of more than
    :data:`LEGEND_INSIDE_MAX` entries, or on polar axes, sits beside the axes, where it covers
    no curve; a shorter one goes where matplotlib finds the most room inside."""
    polar = getattr(ax, "name", "") == "polar"
    handles, labels = ax.get_legend_handles_labels()
    if labels:
        if polar:
            ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.0, 1.1))
        elif len(labels) > LEGEND_INSIDE_MAX:
            ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)
        else:
            ax.legend(fontsize="small")
    if polar:
        radian_ticks(ax)
    if title:
        ax.set_title(title, pad=14 if polar else None)
    return ax


PI_TICK_LABELS = ["0", r"$\pi/4$", r"$\pi/2$", r"$3\pi/4$", r"$\pi$", r"$5\pi/4$", r"$3\pi/2$", r"$7\pi/4$"]


def radian_ticks(ax):
    """Angular ticks of polar axes at multiples of pi/4, labelled in rad."""
    ax.set_xticks(np.arange(8) * np.pi / 4, PI_TICK_LABELS)


def series_label(dataset_label: str | None, curve: str | None) -> str | None:
    """Legend entry of one curve: "dataset, curve", either part alone, or None."""
    parts = [p for p in (dataset_label, curve) if p]
    return ", ".join(parts) if parts else None


# -- saving ------------------------------------------------------------------------------------

def save_figure(fig, path, dpi: int = 150) -> list[Path]:
    """Write ``fig`` as ``path.png`` and ``path.pdf``.

    ``fig`` is a Figure, or Axes whose figure is meant; ``path`` has no suffix (a ``.png`` or
    ``.pdf`` suffix is dropped). Parent folders are created.

    Parameters
    ----------
    fig : matplotlib.figure.Figure or matplotlib.axes.Axes
        The figure to save.
    path : str or path-like
        The file name without suffix.
    dpi : int, default 150
        Resolution of the PNG, dots per inch.

    Returns
    -------
    list of pathlib.Path
        The PNG and PDF paths.

    Raises
    ------
    grainview.contract.errors.ParameterError
        When ``fig`` is neither a Figure nor Axes.
    """
    figure = getattr(fig, "figure", fig) if not hasattr(fig, "savefig") else fig
    if not hasattr(figure, "savefig"):
        raise ParameterError(f"fig={type(fig).__name__}: expected a matplotlib Figure or Axes")
    base = Path(path)
    if base.suffix.lower() in (".png", ".pdf"):
        base = base.with_suffix("")
    base.parent.mkdir(parents=True, exist_ok=True)
    out = [base.with_name(base.name + ".png"), base.with_name(base.name + ".pdf")]
    figure.savefig(out[0], dpi=dpi, bbox_inches="tight")
    figure.savefig(out[1], bbox_inches="tight")
    return out


CAPTION_FONTSIZE = 8
"""Size of the caption text under a figure, points."""


def add_caption(fig, lines) -> None:
    """Write ``lines`` (what the figure plots, then its samples: N, strain window, preparation,
    seed) in :data:`CAPTION_FONTSIZE` type under the figure, each line wrapped to the figure's
    width; :func:`save_figure` keeps it in the saved file.

    The caption starts at the left edge of what the figure draws (axes, labels, legends) and
    just under its lowest part, not at the figure's edges: a figure narrower than its canvas
    (a tall map) is saved without a blank margin on its left, and a legend under the panels
    stays above the caption."""
    import textwrap

    figure = getattr(fig, "figure", fig) if not hasattr(fig, "savefig") else fig
    figure.canvas.draw()  # lays the figure out: its drawn extent is known from here
    box = figure.get_tightbbox(figure.canvas.get_renderer())  # inches: axes, labels, legends
    width, height = figure.get_figwidth(), figure.get_figheight()
    chars = max(60, int(box.width * 72 / (0.5 * CAPTION_FONTSIZE)))  # about half an em per character
    wrapped = [part for line in lines for part in textwrap.wrap(str(line), chars) or [""]]
    figure.text(box.x0 / width, box.y0 / height - 0.1 / height, "\n".join(wrapped), ha="left", va="top",
                fontsize=CAPTION_FONTSIZE, color="0.25", transform=figure.transFigure)


def legend_in_first(axes, loc: str = "upper right") -> None:
    """One legend for all ``axes`` of a figure, inside the first of them at ``loc`` (the
    entries of the first axes that has any), instead of a legend beside one panel, which would
    make that panel narrower than the others; the other panels' legends are removed."""
    handles, labels = [], []
    for ax in axes:
        handles, labels = ax.get_legend_handles_labels()
        if labels:
            break
    for ax in axes:
        if ax.get_legend() is not None:
            ax.get_legend().remove()
    if labels:
        axes[0].legend(handles, labels, loc=loc, fontsize="small")


# -- evolutions --------------------------------------------------------------------------------

PALETTE = {
    "pentagons": "#0072B2",
    "disks": "#E69F00",
    "simple": "#009E73",
    "double": "#CC79A7",
    "all": "0.15",
}
"""One meaning per colour in every figure (Okabe–Ito colours, told apart with the common
colour-vision deficiencies): a sample of pentagons is blue and one of disks orange wherever
samples are compared (the study's figures and the ensemble figures alike); simple contacts are
bluish green, double ones reddish purple and all contacts together near-black, in the curves of
Figs. 18, 19, 22, 23, 25 and the map of Fig. 24."""

OTHER_COLOURS = ("#56B4E9", "#D55E00", "0.45", "#F0E442", "0.15")
"""Colours of samples of other shapes, or a second sample of the same shape, in this order:
none of them is a colour of :data:`PALETTE`'s samples or contact kinds (near-black last)."""

NEUTRAL_COLOURS = ("0.15", "0.5", "#56B4E9", "#D55E00")
"""Colours of the curves of one sample that are neither samples nor contact kinds (Fig. 20's
s->d and d->s), in this order."""


def shape_key(label=None, ds: xr.Dataset | None = None) -> str | None:
    """The shape a sample is coloured by: "pentagons", "disks" or None (another shape).

    The dataset decides when given (no vertices: disks; regular pentagons: pentagons); otherwise the label
    does ("pent" or "5-gon": pentagons; "disk" or "disc": disks), as for an ensemble's groups.

    Parameters
    ----------
    label : str, optional
        The sample's label.
    ds : xarray.Dataset, optional
        The sample's dataset.

    Returns
    -------
    str or None
        A sample key of :data:`PALETTE`, or None.
    """
    if ds is not None and "n_vertices" in ds:
        from ..analysis.sample import shape_name

        return {"disk": "disks", "5-gon": "pentagons"}.get(shape_name(ds))
    low = str(label or "").lower()
    if "pent" in low or "5-gon" in low:
        return "pentagons"
    if "disk" in low or "disc" in low:
        return "disks"
    return None


def _used_colours(ax) -> set:
    from matplotlib.colors import to_hex
    return {to_hex(line.get_color()) for line in ax.lines}


def sample_colour(ax, label=None, ds: xr.Dataset | None = None) -> str:
    """The colour of a sample drawn on ``ax``: its shape's colour in :data:`PALETTE` unless a
    line of ``ax`` already has it (a second sample of that shape), else the first of
    :data:`OTHER_COLOURS` not yet on ``ax``.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The axes the sample is drawn on.
    label : str, optional
        The sample's label (:func:`shape_key`).
    ds : xarray.Dataset, optional
        The sample's dataset (:func:`shape_key`).

    Returns
    -------
    str
        A matplotlib colour.
    """
    from matplotlib.colors import to_hex
    used = _used_colours(ax)
    shape = shape_key(label, ds)
    choices = ([PALETTE[shape]] if shape else []) + list(OTHER_COLOURS)
    for colour in choices:
        if to_hex(colour) not in used:
            return colour
    return choices[len(used) % len(choices)]


LINESTYLES = ("-", "--", ":", "-.")
CURVE_MARKERS = ("o", "s", "^", "D")
"""Markers that tell apart the curves of one sample when several samples share the axes (the
samples differ by colour): dashes alone are lost where noisy curves cross."""


def draw_evolutions(ax, pairs, compute, curves, marker: str = "", curve_colours=None, curve_styles=None,
                    **line_kw):
    """One line per (dataset, curve) against eps_q.

    ``compute(ds)`` returns a Dataset (or a DataArray) over time; ``curves`` lists
    ``(curve_label, variable_name)`` of it (a name None takes the DataArray itself). One sample
    with several curves: a colour and a line style per curve, the colours ``curve_colours`` (one
    per curve, e.g. :data:`PALETTE`'s contact kinds) or else the sample's colour for the first
    curve and :data:`NEUTRAL_COLOURS` for the others, and the line styles ``curve_styles`` (one
    per curve) or else :data:`LINESTYLES` in turn. Several samples: a colour per sample
    (:func:`sample_colour`) and, with one curve each, a line style per sample (readable in grey
    print); with several curves, per curve a line style and a marker (:data:`CURVE_MARKERS`, on
    about a dozen points of each line). Returns the drawn DataArrays (computed), in drawing order.
    """
    drawn = []
    given = line_kw.pop("color", None)
    several = len(pairs) > 1 and len(curves) > 1
    for sample, (label, ds) in enumerate(pairs):
        x = eps_q(ds)
        result = compute(ds).compute()
        colour = given if given is not None and len(pairs) == 1 else sample_colour(ax, label, ds)
        neutral = iter(NEUTRAL_COLOURS)
        for k, (curve_label, name) in enumerate(curves):
            y = result if name is None else result[name]
            style = dict(marker=marker, color=colour)
            if len(pairs) > 1 and len(curves) == 1:  # samples by line style too: readable in grey print
                style["linestyle"] = LINESTYLES[sample % len(LINESTYLES)]
            if several:
                style.update(marker=CURVE_MARKERS[k % len(CURVE_MARKERS)], markersize=3.5,
                             markevery=max(1, len(x) // 12))
            elif len(curves) > 1 and given is None:
                if curve_colours is not None:
                    style["color"] = curve_colours[k]
                elif k > 0:
                    style["color"] = next(neutral, colour)
            style.setdefault("linestyle", curve_styles[k] if curve_styles is not None
                             else LINESTYLES[k % len(LINESTYLES)])
            if "linestyle" in line_kw or "ls" in line_kw:  # the caller's style wins
                style.pop("linestyle")
            ax.plot(x, values(y), label=series_label(label, curve_label), **style, **line_kw)
            drawn.append(y)
    return drawn
