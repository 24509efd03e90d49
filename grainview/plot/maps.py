"""Maps of one snapshot: the particles (disks and regular polygons) and the normal-force
network drawn along the branch vectors (paper Figs. 13, 17, 24).

Particles: a disk is a circle of its radius; polygon p with n vertices has vertex k at
``position[p] + radius[p] (cos(angle[p] + 2 pi k/n), sin(angle[p] + 2 pi k/n))`` (docs/schema.md).
Contacts: the segment from the centre of body i to ``position[i] + branch``, i.e. to the centre
of j for a particle pair, or to the contact point for a wall contact. All contacts of a map are
one :class:`~matplotlib.collections.LineCollection` and all particles one collection per shape
(no Python loop per contact or particle).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import xarray as xr
from matplotlib.collections import EllipseCollection, LineCollection, PolyCollection

from ..analysis.contacts import selection
from ..contract.errors import ParameterError
from ..contract.cell import fractional, image_shift, wrap
from ..contract.shapes import body_vertices_of, world_vertices
from ._docs import fill_doc
from ._style import PALETTE, axis_label, get_axes, single_dataset, snapshot_index

PARTICLE_FACE = "0.92"
PARTICLE_EDGE = "0.55"
CLASS_COLOURS = {1: "#0072B2", 2: "#009E73", 3: "#D55E00"}
"""Colours of the tricolor map, the paper's blue / green / red (Fig. 17) taken from the
Okabe–Ito palette, which stays distinguishable with every common colour-vision deficiency: very
weak (blue: the palette's sky blue has too little contrast on the light grey particles), weak
(bluish green), strong (vermillion)."""
KIND_COLOURS = {1: PALETTE["simple"], 2: PALETTE["double"]}
"""Colours of the kind map (paper Fig. 24): simple and double contacts in the colours they have
in every figure (:data:`grainview.plot._style.PALETTE`), not the paper's blue and red: blue marks
the pentagon sample wherever samples are compared."""


@fill_doc
def plot_particles(data, ax=None, time: int = -1, facecolor=PARTICLE_FACE, edgecolor=PARTICLE_EDGE,
                   linewidth: float = 0.5, values=None, cmap=None, norm=None):
    """Draw the particles of snapshot ``time``: disks and regular polygons.

    Disks as one EllipseCollection, the polygons of each vertex count as one PolyCollection
    (vertex k of polygon p at position[p] + radius[p] (cos(angle[p] + 2 pi k/n),
    sin(angle[p] + 2 pi k/n)), docs/schema.md). With ``values`` (one number per particle) the
    faces are coloured by them through ``cmap`` and ``norm`` (a matplotlib Normalize) instead of
    ``facecolor``. Sets equal aspect, the box as limits, x and y labels in m.

    In a periodic cell the particles are drawn wrapped into the cell, with the images of those
    that reach across a boundary, clipped by the cell's parallelogram, which is drawn as the
    frame (the limits hold it whole when it is tilted).

    Parameters
    ----------
    {data_one}
    {ax}
    {time_drawn}
    facecolor, edgecolor : matplotlib colour
        Face and edge colours of the particles.
    linewidth : float, default 0.5
        Edge width, points.
    values : array_like of float, optional
        One value per particle, to colour the faces by.
    cmap : str or matplotlib.colors.Colormap, optional
        Colour map of ``values``.
    norm : matplotlib.colors.Normalize, optional
        Normalisation of ``values``.

    Returns
    -------
    {returns_axes}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Figs. 13, 17 and 24 (the maps drawn over the particles).
    """
    _, ds = single_dataset(data)
    k = snapshot_index(ds, time)
    ax = map_axes(ax, ds, k)
    position = np.asarray(ds["position"].isel(time=k).values, float)
    angle = np.asarray(ds["angle"].isel(time=k).values, float)
    radius = np.asarray(ds["radius"].values, float)
    n_vertices = np.asarray(ds["n_vertices"].values, int)
    vertices = body_vertices_of(ds)
    style = dict(edgecolors=edgecolor, linewidths=linewidth, zorder=1)
    clip = None
    if "cell" in ds.variables:  # wrapped into the cell, with the images that reach into it, clipped by it
        index, position = _cell_images(ds, k, position, radius)
        angle, radius, n_vertices, vertices = angle[index], radius[index], n_vertices[index], vertices[index]
        values = None if values is None else np.asarray(values, float)[index]
        clip = _cell_outline(ds, k, fill=False)
        ax.add_patch(clip)
        clip.set_visible(False)

    def faces(collection, sel):
        if values is None:
            collection.set_facecolor(facecolor)
        else:
            collection.set_array(np.asarray(values, float)[sel])
            collection.set_cmap(cmap)
            collection.set_norm(norm)
        ax.add_collection(collection)
        if clip is not None:
            collection.set_clip_path(clip)

    disks = n_vertices == 0
    if disks.any():
        faces(EllipseCollection(2 * radius[disks], 2 * radius[disks], np.zeros(disks.sum()), units="xy",
                                offsets=position[disks], offset_transform=ax.transData, **style), disks)
    outlines = world_vertices(position, angle, vertices)
    for n in np.unique(n_vertices[~disks]):
        sel = n_vertices == n
        faces(PolyCollection(outlines[sel, :int(n)], **style), sel)
    _frame(ax, ds, k)
    return ax


def _cell_of(ds: xr.Dataset, k: int):
    """Snapshot ``k``'s cell (2, 2), origin (2,) and periodic flags (2,) of bool."""
    return (np.asarray(ds["cell"].isel(time=k).values, float), np.asarray(ds["box_min"].isel(time=k).values, float),
            np.asarray(ds["periodic"].values, bool))


def _cell_corners(ds: xr.Dataset, k: int) -> np.ndarray:
    """The corners (4, 2), m, of snapshot ``k``'s periodic cell, the parallelogram
    origin, origin + a, origin + a + b, origin + b (origin ``box_min``)."""
    cell, origin, _ = _cell_of(ds, k)
    return origin + np.array([[0.0, 0.0], cell[0], cell[0] + cell[1], cell[1]])


def _cell_outline(ds: xr.Dataset, k: int, fill: bool = False, **style):
    """The parallelogram of snapshot ``k``'s periodic cell as a matplotlib Polygon (not added)."""
    from matplotlib.patches import Polygon

    return Polygon(_cell_corners(ds, k), closed=True, fill=fill, **style)


def _cell_images(ds: xr.Dataset, k: int, position, reach) -> tuple[np.ndarray, np.ndarray]:
    """The particles of a periodic snapshot wrapped into the cell, and the images of those that
    reach into it across a boundary (within ``reach``, (P,) m, of it): the particle index and
    the centre (m) of each drawn copy, the wrapped centres first.

    Parameters
    ----------
    ds : xarray.Dataset
        A dataset with a cell.
    k : int
        Snapshot index.
    position : array_like, (P, 2)
        Centres, m.
    reach : array_like, (P,)
        How far each particle reaches from its centre (its circumscribed radius), m.

    Returns
    -------
    index : numpy.ndarray of int, (Q,)
    centres : numpy.ndarray, (Q, 2)
    """
    cell, origin, periodic = _cell_of(ds, k)
    position = np.asarray(position, float)
    finite = np.isfinite(position).all(-1)
    home = np.where(finite[:, None], wrap(np.nan_to_num(position), origin, cell, periodic), position)
    st = fractional(home - origin, cell)
    reach = np.asarray(reach, float)
    # how far a particle of radius r reaches in cell coordinates: r over the distance between opposite edges
    area = abs(cell[0, 0] * cell[1, 1] - cell[0, 1] * cell[1, 0])
    span = reach[:, None] * np.array([np.hypot(*cell[1]), np.hypot(*cell[0])]) / area
    index, centres = [np.arange(position.shape[0])], [home]
    for m in (-1, 0, 1):
        for n in (-1, 0, 1):
            if (m, n) == (0, 0) or (m and not periodic[0]) or (n and not periodic[1]):
                continue
            moved = st + [m, n]
            near = finite & np.all((moved > -span) & (moved < 1 + span), axis=-1)
            index.append(np.flatnonzero(near))
            centres.append(home[near] + m * cell[0] + n * cell[1])
    return np.concatenate(index), np.concatenate(centres)


PARTICLE_FIELDS = {"c": "contacts c", "m_s": "simple contacts m_s", "m_d": "double contacts m_d",
                   "strong": "strong contacts", "rattler": "rattler (1) or not (0)",
                   "rotation": "rotation (rad)", "displacement": "displacement (m)"}
"""Fields a particle map can show (:func:`grainview.analysis.particle_fields.particle_fields`)."""


@fill_doc
def plot_particle_map(data, field: str = "c", ax=None, time: int = -1, reference: int = 0, walls: bool = True,
                      cmap: str = "cividis"):
    """Particles of snapshot ``time`` coloured by a per-particle ``field``, with a colour bar.

    ``field`` is one of :data:`PARTICLE_FIELDS`: contacts, simple/double contacts, strong
    contacts, rattlers, rotation or displacement since ``reference``
    (:func:`grainview.analysis.particle_fields.particle_fields`); ``cividis`` is colour-blind safe
    (integer fields get one colour per value).

    Parameters
    ----------
    {data_one}
    field : str, default "c"
        "c", "m_s", "m_d", "strong", "rattler", "rotation" (rad) or "displacement" (m).
    {ax}
    {time_drawn}
    reference : int, default 0
        Snapshot the rotation and displacement are measured from.
    walls : bool, default True
        Include the particle–wall contacts; ``False`` leaves them out.
    cmap : str, default "cividis"
        The colour map.

    Returns
    -------
    {returns_axes}

    Raises
    ------
    grainview.contract.errors.ParameterError
        When ``field`` is not one of :data:`PARTICLE_FIELDS`.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. IV.A (connectivity, rattlers), Sec. V (strong contacts), Sec. VI and Fig. 21
    (m_s, m_d); docs/analysis.md, "Where in the sample".
    """
    import matplotlib as mpl

    from ..analysis.particle_fields import particle_fields

    if field not in PARTICLE_FIELDS:
        raise ParameterError(f"field={field!r}: expected one of {sorted(PARTICLE_FIELDS)}")
    _, ds = single_dataset(data)
    k = snapshot_index(ds, time)
    ax = map_axes(ax, ds, k)
    values = np.asarray(particle_fields(ds, reference=reference, walls=walls)[field].isel(time=k).values, float)
    if field in ("rotation", "displacement"):
        norm = mpl.colors.Normalize(vmin=np.nanmin(values), vmax=max(np.nanmax(values), np.nanmin(values) + 1e-12))
        ticks = None
    else:
        top = max(int(np.nanmax(values)), 1)
        norm = mpl.colors.BoundaryNorm(np.arange(-0.5, top + 1.5), ncolors=mpl.colormaps[cmap].N)
        ticks = np.arange(top + 1)
    plot_particles(ds, ax=ax, time=k, values=values, cmap=cmap, norm=norm)
    bar = ax.figure.colorbar(mpl.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax, ticks=ticks)
    bar.set_label(PARTICLE_FIELDS[field])
    ax.set_title(f"{PARTICLE_FIELDS[field]}, snapshot {k} (N = {ds.sizes['particle']})")
    return ax


@fill_doc
def plot_connectivity_map(data, ax=None, time: int = -1, **options):
    """:func:`plot_particle_map` of the contacts c of each particle.

    Parameters
    ----------
    {data_one}
    {ax}
    {time_drawn}
    {map_options}

    Returns
    -------
    {returns_axes}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. IV.A (connectivity); docs/conventions.md §7.
    """
    return plot_particle_map(data, "c", ax=ax, time=time, **options)


@fill_doc
def plot_rattler_map(data, ax=None, time: int = -1, **options):
    """:func:`plot_particle_map` of the rattlers (particles without force-bearing contacts).

    Parameters
    ----------
    {data_one}
    {ax}
    {time_drawn}
    {map_options}

    Returns
    -------
    {returns_axes}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. IV.A (rattlers); docs/conventions.md §7.
    """
    return plot_particle_map(data, "rattler", ax=ax, time=time, **options)


@fill_doc
def plot_rotation_map(data, ax=None, time: int = -1, **options):
    """:func:`plot_particle_map` of each particle's rotation (rad) since the ``reference`` snapshot.

    Parameters
    ----------
    {data_one}
    {ax}
    {time_drawn}
    {map_options}

    Returns
    -------
    {returns_axes}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    docs/analysis.md, "Where in the sample".
    """
    return plot_particle_map(data, "rotation", ax=ax, time=time, **options)


MAP_HEIGHT = 5.0
"""Height of a new map's figure, inches; its width follows the box's aspect."""


@fill_doc
def map_axes(ax, ds: xr.Dataset, k: int):
    """``ax`` itself, or new axes on a figure shaped like the box of snapshot ``k``.

    The figure is :data:`MAP_HEIGHT` inches high and as wide as the box drawn at that height
    plus room for the axis labels, so that a tall sample does not sit in the middle of a
    landscape figure with blank space on both sides.

    Parameters
    ----------
    ax : matplotlib.axes.Axes or None
        Axes to draw on.
    {ds_short}
    k : int
        The snapshot drawn.

    Returns
    -------
    matplotlib.axes.Axes
        ``ax``, or the new axes.
    """
    if ax is not None:
        return get_axes(ax)
    import matplotlib.pyplot as plt

    size = np.asarray(ds["box_max"].isel(time=k).values, float) - np.asarray(ds["box_min"].isel(time=k).values, float)
    aspect = size[0] / size[1] if size[1] > 0 and size[0] > 0 else 1.0
    width = float(np.clip(MAP_HEIGHT * aspect + 1.0, 2.5, 14.0))
    _, ax = plt.subplots(figsize=(width, MAP_HEIGHT))
    return ax


def _frame(ax, ds, k):
    lo = np.asarray(ds["box_min"].isel(time=k).values, float)
    hi = np.asarray(ds["box_max"].isel(time=k).values, float)
    if "cell" in ds.variables:  # the parallelogram, and limits that hold it
        corners = _cell_corners(ds, k)
        lo, hi = corners.min(axis=0), corners.max(axis=0)
        if not any(p.get_gid() == "cell" for p in ax.patches):
            outline = _cell_outline(ds, k, fill=False, edgecolor="0.3", linewidth=0.8, zorder=3)
            outline.set_gid("cell")
            ax.add_patch(outline)
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal")
    ax.set_xlabel(axis_label("$x$", ds["position"].attrs.get("units", "m")))
    ax.set_ylabel(axis_label("$y$", ds["position"].attrs.get("units", "m")))


@fill_doc
def contact_segments(ds: xr.Dataset, k: int, mask) -> tuple[np.ndarray, np.ndarray]:
    """Segments from the centre of i along the branch vector of the contacts selected by ``mask``.

    (C, 2, 2) segments, m, from the centre of body i to that centre plus the branch vector (the
    centre of j, or the contact point on a wall), and the slot indices of the C contacts of
    snapshot ``k`` selected by the boolean ``mask`` (contact,).

    In a periodic cell the centres are wrapped into the cell and the branch is the minimum
    image: a contact across the boundary is two segments, its branch from the centre of i and
    back from the centre of j (``-branch``), each with the contact's slot. Clipped by the cell
    (as the maps clip them), the two pieces inside it are the whole contact, drawn on both sides
    of the boundary, never a line across the box.

    Parameters
    ----------
    {ds_short}
    k : int
        Snapshot index.
    mask : array_like of bool
        (contact,): the slots drawn.

    Returns
    -------
    segments : numpy.ndarray
        (C, 2, 2) start and end points, m.
    slots : numpy.ndarray
        The C slot indices.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Fig. 13 (forces drawn along the branch vectors); docs/conventions.md §0.
    """
    slots = np.flatnonzero(np.asarray(mask, bool))
    snap = ds.isel(time=k, contact=slots)
    i = np.asarray(snap["i"].values, int)
    position = np.asarray(ds["position"].isel(time=k).values, float)
    branch = np.asarray(snap["branch"].values, float)
    if "cell" not in ds.variables:
        start = position[i]
        return np.stack([start, start + branch], axis=1), slots
    cell, origin, periodic = _cell_of(ds, k)
    home = wrap(np.nan_to_num(position), origin, cell, periodic)
    j = np.asarray(snap["j"].values, int)
    start = home[i]
    pair = (j >= 0) & (j < position.shape[0])
    far = home[np.where(pair, j, 0)]
    across = pair & np.any(image_shift(start + branch - far, cell, periodic) != 0, axis=-1)
    segments = np.concatenate([np.stack([start, start + branch], axis=1),
                               np.stack([far[across], far[across] - branch[across]], axis=1)])
    return segments, np.concatenate([slots, slots[across]])


@fill_doc
def force_linewidths(fn, max_linewidth: float, force_scale=None) -> np.ndarray:
    """Line widths proportional to the normal force, in points.

        width = max_linewidth * f_n / F

    F the largest f_n drawn or, for maps that must compare (a movie's frames), ``force_scale``
    (:func:`width_force`).

    Parameters
    ----------
    {fn_forces}
    max_linewidth : float
        Width of the force F, points.
    force_scale : float, optional
        F in N (default: the largest of ``fn``).

    Returns
    -------
    numpy.ndarray
        Widths, points (zeros when F is 0).

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Fig. 13 (line width proportional to the normal force).
    """
    fn = np.asarray(fn, float)
    top = width_force(fn, force_scale)
    return max_linewidth * fn / top if top > 0 else np.zeros_like(fn)


@fill_doc
def width_force(fn, force_scale=None) -> float:
    """The force F (N) drawn at the largest line width.

    ``force_scale`` when given, else the largest of ``fn`` (0 for none).

    Parameters
    ----------
    {fn_forces}
    force_scale : float, optional
        F in N.

    Returns
    -------
    float
        F, N.
    """
    fn = np.asarray(fn, float)
    return float(force_scale) if force_scale is not None else (float(fn.max()) if fn.size else 0.0)


def _network(ds, k, mask, colours, ax, max_linewidth, width_by_force, linewidth, particles, zorder=2,
             force_scale=None):
    if particles:
        plot_particles(ds, ax, time=k)
    else:
        _frame(ax, ds, k)
    segments, slots = contact_segments(ds, k, mask)
    fn = np.asarray(ds["fn"].isel(time=k).values, float)[slots]
    widths = (force_linewidths(fn, max_linewidth, force_scale) if width_by_force
              else np.full(slots.size, linewidth))
    key = None
    if width_by_force and fn.size:
        key = WidthKey(width_force(fn, force_scale), max_linewidth, float(fn.mean()),
                       float(ds.attrs.get("thickness_m", 1.0)))
    colours = colours(slots) if callable(colours) else colours
    lines = LineCollection(segments, linewidths=widths, colors=colours, capstyle="round", zorder=zorder)
    lines.set_gid("contacts")
    ax.add_collection(lines)
    _clip_to_cell(ax, ds, k, lines)
    return lines, key


def _clip_to_cell(ax, ds: xr.Dataset, k: int, artist) -> None:
    """Clip ``artist`` (added to ``ax``) by snapshot ``k``'s periodic cell, when the file has
    one (nothing otherwise): what lies beyond the parallelogram is drawn by the images on the
    other side."""
    if "cell" not in ds.variables:
        return
    clip = _cell_outline(ds, k, fill=False)
    ax.add_patch(clip)
    clip.set_visible(False)
    artist.set_clip_path(clip)


def _digits(value: float) -> str:
    """A number as a legend shows it: whole from 100 to 100,000, else 3 significant digits."""
    return f"{value:.0f}" if 100.0 <= abs(value) < 1e5 else f"{value:.3g}"


def newtons(force: float) -> str:
    """A force as a legend shows it, to at least 3 significant digits.

    Whole newtons from 100 N to 100 kN, else 3 significant digits.

    Parameters
    ----------
    force : float
        A force, N.

    Returns
    -------
    str
        The force with its unit, e.g. "1.4 N" or "250 N".
    """
    return f"{_digits(force)} N"


def per_metre(force: float, thickness: float = 1.0) -> str:
    """A force of a 2D sample as a map's legend shows it: per metre of the slab's thickness, in
    N/m, to at least 3 significant digits.

    A file's forces are in N on the slab of ``thickness`` m its 2D sample stands for
    (docs/schema.md); divided by that thickness they are forces per metre of thickness, the
    same numbers for the default 1 m, and comparable between files of any thickness.

    Parameters
    ----------
    force : float
        A force, N, on the slab.
    thickness : float, default 1.0
        The slab's thickness, m (a file's ``thickness_m``).

    Returns
    -------
    str
        The force per metre with its unit, e.g. "250 N/m" or "1.4 N/m".
    """
    return f"{_digits(force / thickness)} N/m"


class WidthKey(NamedTuple):
    """What a map's line widths stand for: ``max_linewidth`` points for ``top_force`` N.

    The mean force drawn, ``mean_force`` N, is one of the legend's sample widths. Forces are
    those on the slab of thickness ``thickness`` m that the 2D sample stands for
    (docs/schema.md); the legend gives them per metre of thickness (:func:`per_metre`).

    Attributes
    ----------
    top_force : float
        The force drawn at ``max_linewidth``, N.
    max_linewidth : float
        The largest line width, points.
    mean_force : float
        The mean force drawn, N.
    thickness : float
        The slab's thickness, m (the file's ``thickness_m``).
    """
    top_force: float
    max_linewidth: float
    mean_force: float
    thickness: float = 1.0


def contact_collection(ax) -> LineCollection:
    """The LineCollection of contacts drawn by a map on ``ax``.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Axes a map was drawn on.

    Returns
    -------
    matplotlib.collections.LineCollection
        The contacts' segments (gid ``"contacts"``).

    Raises
    ------
    LookupError
        When ``ax`` holds no contact map.
    """
    for coll in ax.collections:
        if isinstance(coll, LineCollection) and coll.get_gid() == "contacts":
            return coll
    raise LookupError("no contact map on these axes")


@fill_doc
def plot_force_chains(data, ax=None, time: int = -1, walls: bool = False, max_linewidth: float = 3.0,
                      colour="k", particles: bool = True, force_scale=None):
    """Map of the normal forces of snapshot ``time`` (paper Fig. 13).

    Each force-bearing contact (f_n > 0) a segment along its branch vector, of width
    proportional to f_n,

        width = max_linewidth * f_n / F,

    F the largest force (or ``force_scale`` N when given), over the particles. Wall contacts
    only with ``walls=True``. A legend beside the map gives sample widths in N.

    Parameters
    ----------
    {data_one}
    {ax}
    {time_drawn}
    {walls}
    max_linewidth : float, default 3.0
        Width of the largest force (or of ``force_scale``), points.
    colour : matplotlib colour, default "k"
        Colour of the segments.
    {particles}
    force_scale : float, optional
        The force F (N) drawn at ``max_linewidth``, to compare maps.

    Returns
    -------
    {returns_axes}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Fig. 13; docs/conventions.md §0.
    """
    _, ds = single_dataset(data)
    k = snapshot_index(ds, time)
    ax = map_axes(ax, ds, k)
    mask = selection(ds.isel(time=k), walls=walls).values
    _, key = _network(ds, k, mask, colour, ax, max_linewidth, True, None, particles, force_scale=force_scale)
    _legend(ax, {}, key, colour)
    return ax


@fill_doc
def plot_force_classes(data, ax=None, time: int = -1, walls: bool = False, very_weak: float = 0.1,
                       strong: float = 1.0, width_by_force: bool = False, linewidth: float = 1.0,
                       max_linewidth: float = 3.0, particles: bool = True):
    """Tricolor map of the force classes of snapshot ``time`` (paper Fig. 17).

    Very weak contacts (f_n < ``very_weak`` <f_n>) in blue, weak ones in green, strong ones
    (f_n > ``strong`` <f_n>) in red, as classified by
    :func:`grainview.analysis.force_networks.force_class`. Uniform ``linewidth`` unless
    ``width_by_force``. A legend of the classes.

    Parameters
    ----------
    {data_one}
    {ax}
    {time_drawn}
    {walls}
    very_weak : float, default 0.1
        Very weak threshold, a multiple of <f_n>.
    strong : float, default 1.0
        Strong threshold, a multiple of <f_n>.
    width_by_force : bool, default False
        Line width proportional to f_n (``max_linewidth`` for the largest) instead of uniform.
    linewidth : float, default 1.0
        Uniform line width, points.
    max_linewidth : float, default 3.0
        Width of the largest force with ``width_by_force``, points.
    {particles}

    Returns
    -------
    {returns_axes}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Secs. V.B and V.C, Fig. 17; docs/conventions.md §4.
    """
    from ..analysis.force_networks import force_class
    _, ds = single_dataset(data)
    k = snapshot_index(ds, time)
    ax = map_axes(ax, ds, k)
    snap = ds.isel(time=[k])
    classes = np.asarray(force_class(snap, very_weak=very_weak, strong=strong, walls=walls).isel(time=0).values, int)
    mask = selection(snap.isel(time=0), walls=walls).values & (classes > 0)
    palette = np.array([CLASS_COLOURS.get(c, "k") for c in range(4)], dtype=object)
    _, key = _network(ds, k, mask, lambda slots: list(palette[classes[slots]]), ax, max_linewidth,
                      width_by_force, linewidth, particles)
    _legend(ax, {rf"very weak, $f_n < {very_weak:g}\langle f_n\rangle$": CLASS_COLOURS[1],
                 rf"weak, ${very_weak:g}\langle f_n\rangle \leq f_n \leq {strong:g}\langle f_n\rangle$":
                     CLASS_COLOURS[2],
                 rf"strong, $f_n > {strong:g}\langle f_n\rangle$": CLASS_COLOURS[3]}, key)
    return ax


@fill_doc
def plot_contact_kinds(data, ax=None, time: int = -1, walls: bool = False, max_linewidth: float = 3.0,
                       particles: bool = True):
    """Map of the normal-force network of snapshot ``time`` by contact kind (paper Fig. 24).

    Simple contacts in blue and double contacts in red, width proportional to f_n
    (``max_linewidth`` points for the largest force).

    Parameters
    ----------
    {data_one}
    {ax}
    {time_drawn}
    {walls}
    max_linewidth : float, default 3.0
        Width of the largest force, points.
    {particles}

    Returns
    -------
    {returns_axes}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. II.A (simple and double contacts) and Fig. 24.
    """
    _, ds = single_dataset(data)
    k = snapshot_index(ds, time)
    ax = map_axes(ax, ds, k)
    mask = selection(ds.isel(time=k), walls=walls).values
    kind = np.asarray(ds["kind"].isel(time=k).values, int)
    _, key = _network(ds, k, mask, lambda slots: [KIND_COLOURS.get(c, "k") for c in kind[slots]], ax,
                      max_linewidth, True, None, particles)
    _legend(ax, {"simple (s)": KIND_COLOURS[1], "double (d)": KIND_COLOURS[2]}, key)
    return ax


def _legend(ax, entries, key=None, key_colour="0.3"):
    """A legend beside the map (never over the packing): one line per colour of ``entries``
    ({label: colour}) and, when the widths stand for forces (``key``, a :class:`WidthKey`), three
    sample widths labelled in N per metre of thickness (:func:`per_metre`), each saying which
    force it is (the mean force, half the widest line's, the widest line's), under a title that
    says so (:data:`FORCE_UNIT`)."""
    from matplotlib.lines import Line2D
    handles = [Line2D([], [], color=c, label=name) for name, c in entries.items()]
    title = None
    if key is not None and key.top_force > 0:
        names = {key.mean_force: r"mean $\langle f_n\rangle$", key.top_force / 2: "half the widest",
                 key.top_force: "widest line"}
        for force in sorted(names):
            handles.append(Line2D([], [], color=key_colour, linewidth=key.max_linewidth * force / key.top_force,
                                  label=f"{per_metre(force, key.thickness)}: {names[force]}"))
        title = f"line width $\\propto f_n$\n({FORCE_UNIT})"
    if handles:
        ax.legend(handles=handles, fontsize="small", loc="upper left", bbox_to_anchor=(1.02, 1.0),
                  borderaxespad=0.0, title=title, title_fontsize="small")


FORCE_UNIT = "forces per m of thickness, N/m"
"""What the forces of a map's legend are (:func:`per_metre`), as its title says."""


__all__ = ["plot_particles", "plot_force_chains", "plot_force_classes", "plot_contact_kinds",
           "plot_particle_map", "plot_connectivity_map", "plot_rattler_map", "plot_rotation_map",
           "contact_segments", "force_linewidths", "width_force", "newtons", "per_metre", "FORCE_UNIT", "WidthKey",
           "contact_collection"]
