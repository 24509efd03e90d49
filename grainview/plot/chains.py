"""Figures of the force chains (Peters et al. 2005; :mod:`grainview.analysis.force_chains`): a map of one
snapshot's chains coloured over the packing, their share of the particles and of the stress
along the shear, the pdf of their lengths, the distribution of their lifetimes, and a movie of
the maps. The chains are computed by :func:`grainview.analysis.force_chains.force_chains`; these
functions only draw them.
"""

from __future__ import annotations

import os

import numpy as np

from ..contract.errors import ParameterError
from ._docs import fill_doc
from ._style import (EPS_Q_LABEL, datasets, draw_evolutions, finish, get_axes, sample_colour, single_dataset,
                     snapshot_index)

__all__ = ["plot_chain_map", "plot_chain_fractions", "plot_chain_lengths", "plot_chain_lifetimes",
           "animate_chains", "CHAIN_COLOURS", "OUTSIDE_COLOUR"]

OUTSIDE_COLOUR = "0.88"
"""Face colour of the particles in no chain."""
CHAIN_COLOURS = ("#E69F00", "#56B4E9", "#009E73", "#F0E442", "#0072B2", "#D55E00", "#CC79A7", "#999999")
"""Face colours of the chains, in turn by chain id: the Okabe–Ito palette, distinguishable with
every common colour-vision deficiency (neighbouring chains differ in colour, not in meaning)."""
LINK_COLOUR = "k"


def _chains_of(ds, chains, k, angle, min_size):
    """Snapshot ``k`` of ``chains`` (a result of force_chains over all of ``ds``), or of the
    chains computed for that snapshot alone."""
    if chains is None:
        from ..analysis.force_chains import force_chains

        return force_chains(ds.isel(time=[k]), angle=angle, min_size=min_size).isel(time=0).compute()
    if chains.sizes.get("time") != ds.sizes["time"]:
        raise ParameterError(f"chains has {chains.sizes.get('time')} snapshots, the dataset {ds.sizes['time']}: "
                             "pass force_chains(ds) of the same dataset")
    return chains.isel(time=k).compute()


@fill_doc
def plot_chain_map(data, ax=None, time: int = -1, angle: float = 45.0, min_size: int = 3, chains=None,
                   linewidth: float = 1.5, title: bool = True):
    """Map of the force chains of snapshot ``time``: each chain's particles in one colour, the
    links along the branch vectors in black, the other particles light grey.

    The particles are drawn by :func:`grainview.plot.maps.plot_particles` and the links by
    :func:`grainview.plot.maps.contact_segments` (the segment from the centre of i to the centre
    of j). Title: the number of chains and the shares of particles and deviatoric stress they
    carry.

    Parameters
    ----------
    {data_one}
    {ax}
    {time_drawn}
    angle : float, default 45
        Alignment angle of :func:`grainview.analysis.force_chains.force_chains`, degrees.
    {min_size}
    chains : xarray.Dataset, optional
        ``force_chains(ds, ...)`` of the whole dataset, already computed or lazy (default:
        computed here for this snapshot with ``angle`` and ``min_size``).
    linewidth : float, default 1.5
        Width of the links, points.
    title : bool, default True
        Write the title.

    Returns
    -------
    {returns_axes}

    References
    ----------
    Peters, Muthuswamy, Wibowo & Tordesillas, Phys. Rev. E 72, 041307 (2005);
    docs/analysis.md, "Force chains".
    """
    import matplotlib as mpl
    from matplotlib.collections import LineCollection

    from .maps import _clip_to_cell, contact_segments, map_axes, plot_particles

    _, ds = single_dataset(data)
    k = snapshot_index(ds, time)
    snap = _chains_of(ds, chains, k, angle, min_size)
    ids = np.asarray(snap["chain"].values, int)
    colours = mpl.colors.ListedColormap([OUTSIDE_COLOUR, *CHAIN_COLOURS])
    norm = mpl.colors.BoundaryNorm(np.arange(-0.5, len(CHAIN_COLOURS) + 1.5), colours.N)
    values = np.where(ids >= 0, 1 + ids % len(CHAIN_COLOURS), 0)
    ax = map_axes(ax, ds, k)
    plot_particles(ds, ax=ax, time=k, values=values, cmap=colours, norm=norm)
    segments, _ = contact_segments(ds, k, np.asarray(snap["link"].values, bool))
    links = ax.add_collection(LineCollection(segments, colors=LINK_COLOUR, linewidths=linewidth, zorder=2,
                                             gid="chains"))
    _clip_to_cell(ax, ds, k, links)
    if title:
        ax.set_title(f"snapshot {k}: {int(snap['n_chains'])} chains, {float(snap['particle_fraction']):.0%} of the "
                     f"particles, contributing {float(snap['deviator_fraction']):.0%} of q", fontsize="small")
    return ax


@fill_doc
def plot_chain_fractions(data, ax=None, label=None, angle: float = 45.0, min_size: int = 3):
    """What the chains carry along the shear: their share of the particles and of the mean
    stress, and their contribution to the deviatoric stress, against eps_q.

    ``particle_fraction``, ``deviator_fraction`` ((D_chains : D)/(D : D), D the deviator of
    sum_p V_p sigma_p: signed, above 1 where the other particles' deviator opposes the
    sample's) and ``pressure_fraction`` of :func:`grainview.analysis.force_chains.force_chains`;
    several samples compare on the same axes.

    Parameters
    ----------
    data : xarray.Dataset, dict or list
        One dataset, or several as ``{label: ds}`` or ``[(label, ds), ...]``.
    {ax}
    label : str, optional
        Legend label of a single dataset.
    {angle}
    {min_size}

    Returns
    -------
    {returns_axes}

    References
    ----------
    Peters, Muthuswamy, Wibowo & Tordesillas, Phys. Rev. E 72, 041307 (2005);
    docs/analysis.md, "Force chains".
    """
    from ..analysis.force_chains import force_chains

    ax = get_axes(ax)
    pairs = datasets(data, label)
    draw_evolutions(ax, pairs, lambda ds: force_chains(ds, angle=angle, min_size=min_size),
                    [("contribution to q", "deviator_fraction"), ("share of p", "pressure_fraction"),
                     ("share of particles", "particle_fraction")])
    ax.axhline(0.0, color="0.6", linewidth=0.5)
    ax.axhline(1.0, color="0.6", linewidth=0.5)
    ax.set_xlabel(EPS_Q_LABEL)
    ax.set_ylabel("carried by the force chains (1: all)")
    return finish(ax, pairs)


@fill_doc
def plot_chain_lengths(data, ax=None, label=None, time="residual", angle: float = 45.0, min_size: int = 3,
                       max_length: int = 50):
    """Pdf of the chains' lengths (particles per chain) over the snapshots of ``time``.

        P(L) = (chains of L particles) / (chains), pooled over the snapshots,

    on a logarithmic axis (:func:`grainview.analysis.force_chains.chain_length_pdf`); the last bin counts the
    chains of ``max_length`` particles or more.

    Parameters
    ----------
    data : xarray.Dataset, dict or list
        One dataset, or several as ``{label: ds}`` or ``[(label, ds), ...]``.
    {ax}
    label : str, optional
        Legend label of a single dataset.
    time : "residual", "all", int, slice or sequence, default "residual"
        The snapshots pooled (:func:`grainview.analysis.snapshots.select_snapshots`).
    {angle}
    {min_size}
    max_length : int, default 50
        Last length bin.

    Returns
    -------
    {returns_axes}

    References
    ----------
    Peters, Muthuswamy, Wibowo & Tordesillas, Phys. Rev. E 72, 041307 (2005);
    docs/analysis.md, "Force chains".
    """
    from ..analysis.force_chains import chain_length_pdf

    ax = get_axes(ax)
    pairs = datasets(data, label)
    for name, ds in pairs:
        pdf = chain_length_pdf(ds, time, angle=angle, min_size=min_size, max_length=max_length).compute()
        shown = np.asarray(pdf["length_count"].values) > 0
        if not shown.any():
            continue
        ax.plot(np.asarray(pdf["length"].values)[shown], np.asarray(pdf["length_pdf"].values, float)[shown],
                marker="o", markersize=3, color=sample_colour(ax, name, ds), label=name)
    ax.set_yscale("log")
    ax.set_xlabel("chain length $L$ (particles)")
    ax.set_ylabel("$P(L)$")
    return finish(ax, pairs)


@fill_doc
def plot_chain_lifetimes(data, ax=None, label=None, angle: float = 45.0, min_size: int = 3):
    """Survival of the chains followed from snapshot to snapshot: the fraction of chains seen
    in at least n snapshots, against n, for the chains born and gone within the record
    (uncensored; :func:`grainview.analysis.force_chains.chain_survival`).

    Parameters
    ----------
    data : xarray.Dataset, dict or list
        One dataset, or several as ``{label: ds}`` or ``[(label, ds), ...]``.
    {ax}
    label : str, optional
        Legend label of a single dataset.
    {angle}
    {min_size}

    Returns
    -------
    {returns_axes}

    References
    ----------
    Peters, Muthuswamy, Wibowo & Tordesillas, Phys. Rev. E 72, 041307 (2005);
    docs/analysis.md, "Force chains".
    """
    from ..analysis.force_chains import chain_survival

    ax = get_axes(ax)
    pairs = datasets(data, label)
    for name, ds in pairs:
        survival = chain_survival(ds, angle=angle, min_size=min_size)
        if survival.size == 0:
            continue
        ax.step(survival["lifetime"].values, survival.values, where="post", color=sample_colour(ax, name, ds),
                label=name)
    ax.set_yscale("log")
    ax.set_xlabel("lifetime $n$ (snapshots)")
    ax.set_ylabel("fraction of chains seen in $\\geq n$ snapshots")
    return finish(ax, pairs)


@fill_doc
def animate_chains(data, path, every: int = 1, fps: int = 8, angle: float = 45.0, min_size: int = 3,
                   dpi: int = 90, progress: bool = True, overwrite: bool = False) -> str:
    """Write a movie of the chain maps (:func:`plot_chain_map`) of every ``every``-th snapshot
    (and the last) to ``path`` (.gif, or .mp4 with ffmpeg), each frame titled with its shear
    strain eps_q and time; written under a temporary name and moved into place when complete.

    Parameters
    ----------
    data : xarray.Dataset, dict or list
        One dataset of the contract (a dict or list must hold exactly one).
    path : str or path-like
        The movie's file name: ``.gif`` (Pillow) or ``.mp4`` (needs ffmpeg).
    every : int, default 1
        Draw every ``every``-th snapshot (the last always included).
    fps : int, default 8
        Frames per second.
    {angle}
    {min_size}
    dpi : int, default 90
        Resolution of the frames, dots per inch.
    progress : bool, default True
        Show a progress bar.
    overwrite : bool, default False
        Replace an existing ``path``.

    Returns
    -------
    str
        The path written.

    Raises
    ------
    grainview.contract.errors.ParameterError
        For an existing ``path`` without ``overwrite``, a name that is neither .gif nor .mp4,
        or an .mp4 without ffmpeg.

    References
    ----------
    Peters, Muthuswamy, Wibowo & Tordesillas, Phys. Rev. E 72, 041307 (2005);
    docs/analysis.md, "Force chains".
    """
    import matplotlib.pyplot as plt

    from ..analysis.force_chains import force_chains
    from ..analysis.snapshots import snapshot_indices
    from .movies import _writer, frame_title, save_frames

    if os.path.exists(path) and not overwrite:  # before any drawing
        raise ParameterError(f"{path} exists; pass overwrite=True to replace it")
    writer = _writer(path, fps)
    _, ds = single_dataset(data)
    frames = snapshot_indices(ds, every)
    shown = ds.isel(time=frames)
    chains = force_chains(shown, angle=angle, min_size=min_size).compute()
    title = frame_title(ds)
    fig, ax = plt.subplots(figsize=(5, 7))

    def draw(row, k):
        ax.clear()
        plot_chain_map(shown, ax=ax, time=row, chains=chains, title=False)
        ax.set_title(f"{title(k)}: {int(chains['n_chains'][row])} chains", fontsize="small")

    return save_frames(fig, path, writer, frames, draw, dpi=dpi, progress=progress, overwrite=overwrite,
                       desc="movie (force chains)")
