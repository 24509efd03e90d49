"""Movies of a series: force chains, force classes or connectivity, one frame per snapshot.

Each frame is the map of :mod:`grainview.plot.maps` for that snapshot, titled with its shear
strain eps_q and time, on scales fixed for the whole movie (the force of the widest line, the
connectivity colours), so that frames compare. GIF through Pillow (always available with
matplotlib); MP4 through ffmpeg when it is installed. The movie is written under a temporary
name and moved into place when complete.
"""

from __future__ import annotations

import os

import numpy as np

from ..analysis.contacts import selection
from ..contract.errors import ParameterError
from ._docs import fill_doc
from ._style import single_dataset

__all__ = ["animate"]

KINDS = ("force_chains", "force_classes", "connectivity")


def _writer(path, fps):
    from matplotlib import animation

    ext = os.path.splitext(str(path))[1].lower()
    if ext == ".gif":
        return animation.PillowWriter(fps=fps)
    if ext == ".mp4":
        if not animation.writers.is_available("ffmpeg"):
            raise ParameterError(f"{path}: MP4 needs ffmpeg, which is not installed; write a .gif instead")
        return animation.FFMpegWriter(fps=fps)
    raise ParameterError(f"{path}: expected a .gif or .mp4 file name")


def frame_title(ds):
    """A function of a snapshot index k giving a frame's title: "eps_q = ..., t = ... s
    (snapshot k)" (eps_q from the boxes, left out when the dataset has none)."""
    from ..analysis.strain import strains

    eps_q = np.asarray(strains(ds)["eps_q"].values, float) if {"box_min", "box_max"} <= set(ds.variables) else None
    times = np.asarray(ds["time"].values, float)

    def title(k: int) -> str:
        strain = f"$\\varepsilon_q$ = {eps_q[k]:.3f}, " if eps_q is not None else ""
        return f"{strain}t = {times[k]:.3g} s (snapshot {k})"

    return title


def save_frames(fig, path, writer, frames, draw, *, dpi, progress, overwrite, desc) -> str:
    """Draw ``draw(row, k)`` for each snapshot index k of ``frames`` (row its position) on
    ``fig``, grab each as a frame of ``writer``, and write the movie to ``path`` atomically
    (:func:`grainview.contract.writer.write_atomically`); ``fig`` is closed in any case. Returns
    ``str(path)``."""
    import matplotlib.pyplot as plt

    from ..contract.writer import write_atomically

    rows = list(enumerate(frames))
    if progress:
        from tqdm.auto import tqdm

        rows = tqdm(rows, desc=desc, unit="frame")

    def frames_to(temporary):
        with writer.saving(fig, temporary, dpi):
            for row, k in rows:
                draw(row, int(k))
                writer.grab_frame()

    try:
        write_atomically(str(path), overwrite, frames_to)
    finally:
        plt.close(fig)
    return str(path)


@fill_doc
def animate(data, path, kind: str = "force_chains", every: int = 1, fps: int = 8, walls: bool = False,
            max_linewidth: float = 3.0, dpi: int = 90, progress: bool = True, overwrite: bool = False) -> str:
    """Write a movie of every ``every``-th snapshot (and the last) to ``path`` (.gif or .mp4).

    ``kind``: ``"force_chains"`` (line width proportional to f_n, the largest force of the whole
    movie at ``max_linewidth`` points), ``"force_classes"`` (very weak / weak / strong, paper
    Fig. 17) or ``"connectivity"`` (particles coloured by their contacts, one colour bar for the
    movie). Each frame is titled with its shear strain eps_q and time. Written atomically
    (:func:`grainview.contract.writer.write_atomically`).

    Parameters
    ----------
    {data_one}
    path : str or path-like
        The movie's file name: ``.gif`` (Pillow) or ``.mp4`` (needs ffmpeg).
    kind : {"force_chains", "force_classes", "connectivity"}, default "force_chains"
        The map of each frame.
    every : int, default 1
        Draw every ``every``-th snapshot (the last always included).
    fps : int, default 8
        Frames per second.
    {walls}
    max_linewidth : float, default 3.0
        Width of the movie's largest force, points (``"force_chains"``).
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
        For an unknown ``kind``, an existing ``path`` without ``overwrite``, a name that is
        neither .gif nor .mp4, or an .mp4 without ffmpeg.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Figs. 13 and 17 (the maps of the frames).
    """
    import matplotlib.pyplot as plt

    from ..analysis.snapshots import snapshot_indices
    from .maps import plot_force_chains, plot_force_classes, plot_particles

    if kind not in KINDS:
        raise ParameterError(f"kind={kind!r}: expected one of {KINDS}")
    if os.path.exists(path) and not overwrite:  # before any drawing
        raise ParameterError(f"{path} exists; pass overwrite=True (--overwrite) to replace it")
    writer = _writer(path, fps)
    _, ds = single_dataset(data)
    frames = snapshot_indices(ds, every)
    title = frame_title(ds)
    force_scale = float(ds["fn"].where(selection(ds, walls=walls)).isel(time=frames).max())
    fig, ax = plt.subplots(figsize=(5, 7) if kind == "connectivity" else (7.5, 7))
    if kind != "connectivity":
        fig.subplots_adjust(left=0.1, right=0.62)  # room for the legend beside the map
    norm = cmap = None
    if kind == "connectivity":
        import matplotlib as mpl

        from ..analysis.particle_fields import particle_fields

        contacts = particle_fields(ds, walls=True)["c"].isel(time=frames).values
        top = max(int(contacts.max()), 1)
        cmap = "cividis"
        norm = mpl.colors.BoundaryNorm(np.arange(-0.5, top + 1.5), ncolors=mpl.colormaps[cmap].N)
        fig.colorbar(mpl.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax, ticks=np.arange(top + 1),
                     label="contacts c")

    def draw(row, k):
        ax.clear()
        if kind == "force_chains":
            plot_force_chains(ds, ax=ax, time=k, walls=walls, max_linewidth=max_linewidth, force_scale=force_scale)
        elif kind == "force_classes":
            plot_force_classes(ds, ax=ax, time=k, walls=walls)
        else:
            plot_particles(ds, ax=ax, time=k, values=contacts[row], cmap=cmap, norm=norm)
        ax.set_title(title(k), fontsize="small")

    return save_frames(fig, path, writer, frames, draw, dpi=dpi, progress=progress, overwrite=overwrite,
                       desc=f"movie ({kind})")
