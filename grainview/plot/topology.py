"""Figures of the force network's topology (:func:`grainview.analysis.network_topology.network_persistence`):
a snapshot's persistence diagram, the Betti curves beta_0(xi), beta_1(xi), and the 3- and
4-cycles by number of strong edges.

Each function takes datasets of the contract (the analysis is run on them with its defaults)
or the Datasets :func:`~grainview.analysis.network_topology.network_persistence` returned (drawn as
they are); several samples as ``{label: ds}`` or ``[(label, ds), ...]``. The functions only
draw: every number comes from the topic module.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ..contract.errors import ParameterError
from ._docs import fill_doc
from ._style import datasets, finish, get_axes, new_figure, sample_colour, single_dataset

__all__ = ["plot_persistence_diagram", "plot_betti_curves", "plot_cycle_counts", "plot_network_topology"]

XI_LABEL = r"$\xi = f_n/\langle f_n\rangle$"


def _result(ds: xr.Dataset) -> xr.Dataset:
    """``ds`` itself when it is a result of network_persistence, else the analysis of it."""
    if "birth" in ds and "beta_0" in ds:
        return ds
    from ..analysis.network_topology import network_persistence

    return network_persistence(ds)


@fill_doc
def plot_persistence_diagram(data, time=-1, ax=None, label=None):
    """One snapshot's persistence diagram: each feature at (birth, death), in units of <f_n>.

    The filtration lowers xi, so every point lies on or below the diagonal death = birth;
    the farther below, the longer the feature lives. Components (dimension 0) are dots, loops
    (dimension 1) crosses; the features that never die (death = -inf) are drawn on the
    bottom line marked "never", below xi = 0.

    Parameters
    ----------
    data : xarray.Dataset, dict or list
        One dataset of the contract or one result of
        :func:`~grainview.analysis.network_topology.network_persistence` (a single sample).
    time : int, default -1
        The snapshot (an index along ``time``).
    {ax}
    label : str, optional
        The sample's name, in the legend.

    Returns
    -------
    matplotlib.axes.Axes

    References
    ----------
    Kramár, Goullet, Kondic & Mischaikow, Phys. Rev. E 87, 042207 (2013), Fig. 3.
    """
    label, ds = single_dataset(data, label)
    result = _result(ds)
    n = result.sizes["time"]
    if isinstance(time, bool) or not isinstance(time, (int, np.integer)) or not -n <= time < n:
        raise ParameterError(f"time={time!r}: expected a snapshot index in [{-n}, {n})")
    snap = result.isel(time=int(time)).compute()
    birth, death, dim = snap["birth"].values, snap["death"].values, snap["dimension"].values
    ax = get_axes(ax)
    finite = death[np.isfinite(death)]
    top = max(float(np.nanmax(birth)) if np.isfinite(birth).any() else 1.0, 1.0) * 1.05
    never = -0.08 * top
    for k, marker, name in ((0, "o", "components"), (1, "x", "loops")):
        keep = dim == k
        if not keep.any():
            continue
        shown = np.where(np.isinf(death[keep]), never, death[keep])
        ax.scatter(birth[keep], shown, marker=marker, s=14, alpha=0.7, linewidths=1.0,
                   label=", ".join(p for p in (label, f"dimension {k}, {name}") if p))
    ax.plot([0, top], [0, top], color="0.5", lw=0.8)
    ax.axhline(never, color="0.5", lw=0.6, ls=":")
    ax.text(top, never, " never", va="center", ha="left", fontsize="small", color="0.3", clip_on=False)
    ax.set_xlim(0, top)
    ax.set_ylim(never * 1.6, top if finite.size == 0 else max(top * 0.5, float(finite.max()) * 1.1))
    ax.set_xlabel(r"birth $\xi_b$ ($f_n/\langle f_n\rangle$ at which the feature appears)")
    ax.set_ylabel(r"death $\xi_d$ ($f_n/\langle f_n\rangle$)")
    ax.legend(fontsize="small", loc="upper left")  # above the diagonal: no point there
    return ax


def plot_betti_curves(data, ax=None, label=None, per_particle: bool = True):
    """Betti curves beta_0(xi) (components, dashed) and beta_1(xi) (loops, solid) of the network
    of contacts with f_n >= xi <f_n>, averaged over the snapshots given.

    Parameters
    ----------
    data : xarray.Dataset, dict or list
        Datasets of the contract or results of
        :func:`~grainview.analysis.network_topology.network_persistence`, one or several samples
        (select the snapshots, e.g. the residual state, before).
    ax : matplotlib.axes.Axes, optional
        The axes to draw on.
    label : str, optional
        Legend label of a single sample.
    per_particle : bool, default True
        Divide by the number of particles N, so that samples of different sizes compare.

    Returns
    -------
    matplotlib.axes.Axes

    References
    ----------
    Kramár, Goullet, Kondic & Mischaikow, Phys. Rev. E 87, 042207 (2013), Sec. IV.
    """
    ax = get_axes(ax)
    for name, ds in datasets(data, label):
        result = _result(ds)
        scale = 1.0 / ds.sizes["particle"] if per_particle and "particle" in ds.dims else 1.0
        if per_particle and "particle" not in ds.dims:
            raise ParameterError("per_particle=True needs the dataset of the contract (its particle count), "
                                 "not the analysis's result; pass the dataset or per_particle=False")
        colour = sample_colour(ax, name, ds)
        for var, style, what in (("beta_1", "-", r"$\beta_1$ loops"), ("beta_0", "--", r"$\beta_0$ components")):
            if var in result:
                curve = result[var].mean("time").values * scale
                ax.plot(result["xi"].values, curve, ls=style, color=colour,
                        label=", ".join(p for p in (name, what) if p))
    ax.set_xlabel(XI_LABEL)
    ax.set_ylabel(r"$\beta_k(\xi)/N$, per particle" if per_particle else r"$\beta_k(\xi)$, count")
    return finish(ax, None)


def plot_cycle_counts(data, ax=None, label=None, per_particle: bool = True):
    """3-cycles and chordless 4-cycles by their number of strong edges (f_n >= <f_n> by
    default), averaged over the snapshots given: bars side by side per sample.

    Parameters
    ----------
    data : xarray.Dataset, dict or list
        Datasets of the contract or results of
        :func:`~grainview.analysis.network_topology.network_persistence`.
    ax : matplotlib.axes.Axes, optional
        The axes to draw on.
    label : str, optional
        Legend label of a single sample.
    per_particle : bool, default True
        Divide by the number of particles N (needs the datasets of the contract).

    Returns
    -------
    matplotlib.axes.Axes

    References
    ----------
    Tordesillas, Walker & Lin, Phys. Rev. E 81, 011302 (2010).
    """
    ax = get_axes(ax)
    pairs = datasets(data, label)
    width = 0.8 / (2 * len(pairs))
    positions = np.arange(5)
    for s, (name, ds) in enumerate(pairs):
        result = _result(ds)
        if per_particle and "particle" not in ds.dims:
            raise ParameterError("per_particle=True needs the dataset of the contract (its particle count), "
                                 "not the analysis's result; pass the dataset or per_particle=False")
        scale = 1.0 / ds.sizes["particle"] if per_particle else 1.0
        colour = sample_colour(ax, name, ds)
        for c, (var, hatch, what) in enumerate((("cycles_3", None, "3-cycles"), ("cycles_4", "//", "4-cycles"))):
            offset = (2 * s + c - len(pairs) + 0.5) * width
            ax.bar(positions + offset, result[var].mean("time").values * scale, width, color=colour, hatch=hatch,
                   alpha=0.85 if c == 0 else 0.45, edgecolor=colour,
                   label=", ".join(p for p in (name, what) if p))
    ax.set_xticks(positions)
    strong = float(_result(pairs[0][1]).attrs.get("strong", 1.0))
    ax.set_xlabel(r"strong edges of the cycle ($f_n \geq$" + f" {strong:g} " + r"$\langle f_n\rangle$)")
    ax.set_ylabel("cycles per particle" if per_particle else "cycles, count")
    return finish(ax, None)


def plot_network_topology(data, time=-1, label=None):
    """Three panels: (a) the persistence diagram of the first sample's snapshot ``time``,
    (b) the Betti curves and (c) the cycle counts of every sample, per particle.

    Parameters
    ----------
    data : xarray.Dataset, dict or list
        Datasets of the contract, one or several samples.
    time : int, default -1
        The snapshot of panel (a).
    label : str, optional
        Legend label of a single sample.

    Returns
    -------
    matplotlib.figure.Figure

    References
    ----------
    Kramár, Goullet, Kondic & Mischaikow, Phys. Rev. E 87, 042207 (2013); Tordesillas, Walker
    & Lin, Phys. Rev. E 81, 011302 (2010).
    """
    pairs = datasets(data, label)
    results = [(name, _with_particles(_result(ds), ds)) for name, ds in pairs]
    fig, axes = new_figure(3, width=4.6, height=3.8)
    plot_persistence_diagram(results[0][1], time=time, ax=axes[0], label=results[0][0])
    if len(results) == 1:  # a single sample keeps its label, None included
        plot_betti_curves(results[0][1], ax=axes[1], label=results[0][0])
        plot_cycle_counts(results[0][1], ax=axes[2], label=results[0][0])
    else:
        plot_betti_curves(results, ax=axes[1])
        plot_cycle_counts(results, ax=axes[2])
    return fig


def _with_particles(result: xr.Dataset, ds: xr.Dataset) -> xr.Dataset:
    """``result`` carrying ``ds``'s particle dimension and shapes (``radius``, ``n_vertices``
    and ``vertices`` where the file has them: they give the sample's colour,
    :func:`grainview.plot._style.shape_key`), so that the per-particle figures divide by N."""
    return result.assign({name: ds[name] for name in ("radius", "n_vertices", "vertices") if name in ds.variables})
