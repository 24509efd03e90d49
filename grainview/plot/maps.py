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

from ..contacts import selection
from ..errors import ParameterError
from ..schema import polygon_vertices
from ._style import axis_label, get_axes, single_dataset, snapshot_index

PARTICLE_FACE = "0.92"
PARTICLE_EDGE = "0.55"
CLASS_COLOURS = {1: "#56B4E9", 2: "#009E73", 3: "#D55E00"}
"""Colours of the tricolor map, the paper's blue / green / red (Fig. 17) taken from the
Okabe–Ito palette, which stays distinguishable with every common colour-vision deficiency: very
weak (sky blue), weak (bluish green), strong (vermillion)."""
KIND_COLOURS = {1: "#0072B2", 2: "#D55E00"}
"""Colours of the kind map (paper Fig. 24), Okabe–Ito: simple (blue), double (vermillion)."""


def plot_particles(data, ax=None, time: int = -1, facecolor=PARTICLE_FACE, edgecolor=PARTICLE_EDGE,
                   linewidth: float = 0.5, values=None, cmap=None, norm=None):
    """Draw the particles of snapshot ``time``: disks as one EllipseCollection, the polygons of
    each vertex count as one PolyCollection. With ``values`` (one number per particle) the
    faces are coloured by them through ``cmap`` and ``norm`` (a matplotlib Normalize) instead of
    ``facecolor``. Sets equal aspect, the box as limits, x and y labels in m. Returns the axes."""
    _, ds = single_dataset(data)
    ax = get_axes(ax)
    k = snapshot_index(ds, time)
    position = np.asarray(ds["position"].isel(time=k).values, float)
    angle = np.asarray(ds["angle"].isel(time=k).values, float)
    radius = np.asarray(ds["radius"].values, float)
    n_vertices = np.asarray(ds["n_vertices"].values, int)
    style = dict(edgecolors=edgecolor, linewidths=linewidth, zorder=1)

    def faces(collection, sel):
        if values is None:
            collection.set_facecolor(facecolor)
        else:
            collection.set_array(np.asarray(values, float)[sel])
            collection.set_cmap(cmap)
            collection.set_norm(norm)
        ax.add_collection(collection)

    disks = n_vertices == 0
    if disks.any():
        faces(EllipseCollection(2 * radius[disks], 2 * radius[disks], np.zeros(disks.sum()), units="xy",
                                offsets=position[disks], offset_transform=ax.transData, **style), disks)
    for n in np.unique(n_vertices[~disks]):
        sel = n_vertices == n
        faces(PolyCollection(polygon_vertices(position[sel], radius[sel], angle[sel], int(n)), **style), sel)
    _frame(ax, ds, k)
    return ax


PARTICLE_FIELDS = {"c": "contacts c", "m_s": "simple contacts m_s", "m_d": "double contacts m_d",
                   "strong": "strong contacts", "rattler": "rattler (1) or not (0)",
                   "rotation": "rotation (rad)", "displacement": "displacement (m)"}
"""Fields a particle map can show (:func:`grainview.particle_fields.particle_fields`)."""


def plot_particle_map(data, field: str = "c", ax=None, time: int = -1, reference: int = 0, walls: bool = True,
                      cmap: str = "cividis"):
    """Particles of snapshot ``time`` coloured by a per-particle ``field`` (one of
    :data:`PARTICLE_FIELDS`: contacts, simple/double contacts, strong contacts, rattlers,
    rotation or displacement since ``reference``), with a colour bar; ``cividis`` is
    colour-blind safe (integer fields get one colour per value). Returns the axes."""
    import matplotlib as mpl

    from ..particle_fields import particle_fields

    if field not in PARTICLE_FIELDS:
        raise ParameterError(f"field={field!r}: expected one of {sorted(PARTICLE_FIELDS)}")
    _, ds = single_dataset(data)
    ax = get_axes(ax)
    k = snapshot_index(ds, time)
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


def plot_connectivity_map(data, ax=None, time: int = -1, **options):
    """:func:`plot_particle_map` of the contacts c of each particle."""
    return plot_particle_map(data, "c", ax=ax, time=time, **options)


def plot_rattler_map(data, ax=None, time: int = -1, **options):
    """:func:`plot_particle_map` of the rattlers (particles without force-bearing contacts)."""
    return plot_particle_map(data, "rattler", ax=ax, time=time, **options)


def plot_rotation_map(data, ax=None, time: int = -1, **options):
    """:func:`plot_particle_map` of each particle's rotation since the ``reference`` snapshot."""
    return plot_particle_map(data, "rotation", ax=ax, time=time, **options)


def _frame(ax, ds, k):
    lo = np.asarray(ds["box_min"].isel(time=k).values, float)
    hi = np.asarray(ds["box_max"].isel(time=k).values, float)
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal")
    ax.set_xlabel(axis_label("$x$", ds["position"].attrs.get("units", "m")))
    ax.set_ylabel(axis_label("$y$", ds["position"].attrs.get("units", "m")))


def contact_segments(ds: xr.Dataset, k: int, mask) -> tuple[np.ndarray, np.ndarray]:
    """(C, 2, 2) segments from the centre of i along the branch vector, and the slot indices
    of the C contacts of snapshot ``k`` selected by the boolean ``mask`` (contact,), m."""
    slots = np.flatnonzero(np.asarray(mask, bool))
    snap = ds.isel(time=k, contact=slots)
    i = np.asarray(snap["i"].values, int)
    start = np.asarray(ds["position"].isel(time=k).values, float)[i]
    end = start + np.asarray(snap["branch"].values, float)
    return np.stack([start, end], axis=1), slots


def force_linewidths(fn, max_linewidth: float, force_scale=None) -> np.ndarray:
    """Line widths proportional to the normal force: max_linewidth * f_n / F (points), F the
    largest f_n drawn or, for maps that must compare (a movie's frames), ``force_scale`` (N)."""
    fn = np.asarray(fn, float)
    top = width_force(fn, force_scale)
    return max_linewidth * fn / top if top > 0 else np.zeros_like(fn)


def width_force(fn, force_scale=None) -> float:
    """The force F (N) drawn at the largest line width: ``force_scale`` when given, else the
    largest of ``fn`` (0 for none)."""
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
        key = WidthKey(width_force(fn, force_scale), max_linewidth, float(fn.mean()))
    colours = colours(slots) if callable(colours) else colours
    lines = LineCollection(segments, linewidths=widths, colors=colours, capstyle="round", zorder=zorder)
    lines.set_gid("contacts")
    ax.add_collection(lines)
    return lines, key


def newtons(force: float) -> str:
    """A force as a legend shows it, to at least 3 significant digits: whole newtons from 100 N
    to 100 kN, else 3 significant digits."""
    return f"{force:.0f} N" if 100.0 <= abs(force) < 1e5 else f"{force:.3g} N"


class WidthKey(NamedTuple):
    """What a map's line widths stand for: ``max_linewidth`` points for ``top_force`` N; the
    mean force drawn, ``mean_force`` N, is one of the legend's sample widths."""
    top_force: float
    max_linewidth: float
    mean_force: float


def contact_collection(ax) -> LineCollection:
    """The LineCollection of contacts drawn by a map on ``ax``."""
    for coll in ax.collections:
        if isinstance(coll, LineCollection) and coll.get_gid() == "contacts":
            return coll
    raise LookupError("no contact map on these axes")


def plot_force_chains(data, ax=None, time: int = -1, walls: bool = False, max_linewidth: float = 3.0,
                      colour="k", particles: bool = True, force_scale=None):
    """Map of the normal forces of snapshot ``time`` (paper Fig. 13): each force-bearing
    contact (f_n > 0) a segment along its branch vector, of width proportional to f_n
    (``max_linewidth`` points for the largest force, or for ``force_scale`` N when given),
    over the particles. Wall contacts only with ``walls=True``. Returns the axes."""
    _, ds = single_dataset(data)
    ax = get_axes(ax)
    k = snapshot_index(ds, time)
    mask = selection(ds.isel(time=k), walls=walls).values
    _, key = _network(ds, k, mask, colour, ax, max_linewidth, True, None, particles, force_scale=force_scale)
    _legend(ax, {}, key, colour)
    return ax


def plot_force_classes(data, ax=None, time: int = -1, walls: bool = False, very_weak: float = 0.1,
                       strong: float = 1.0, width_by_force: bool = False, linewidth: float = 1.0,
                       max_linewidth: float = 3.0, particles: bool = True):
    """Tricolor map of snapshot ``time`` (paper Fig. 17): very weak contacts
    (f_n < ``very_weak`` <f_n>) in blue, weak ones in green, strong ones (f_n > ``strong``
    <f_n>) in red, as classified by :func:`grainview.force_networks.force_class`. Uniform
    ``linewidth`` unless ``width_by_force``. Returns the axes, with a legend of the classes."""
    from ..force_networks import force_class
    _, ds = single_dataset(data)
    ax = get_axes(ax)
    k = snapshot_index(ds, time)
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


def plot_contact_kinds(data, ax=None, time: int = -1, walls: bool = False, max_linewidth: float = 3.0,
                       particles: bool = True):
    """Map of the normal-force network of snapshot ``time`` with simple contacts in blue and
    double contacts in red, width proportional to f_n (paper Fig. 24). Returns the axes."""
    _, ds = single_dataset(data)
    ax = get_axes(ax)
    k = snapshot_index(ds, time)
    mask = selection(ds.isel(time=k), walls=walls).values
    kind = np.asarray(ds["kind"].isel(time=k).values, int)
    _, key = _network(ds, k, mask, lambda slots: [KIND_COLOURS.get(c, "k") for c in kind[slots]], ax,
                      max_linewidth, True, None, particles)
    _legend(ax, {"simple (s)": KIND_COLOURS[1], "double (d)": KIND_COLOURS[2]}, key)
    return ax


def _legend(ax, entries, key=None, key_colour="0.3"):
    """A legend beside the map (never over the packing): one line per colour of ``entries``
    ({label: colour}) and, when the widths stand for forces (``key``, a :class:`WidthKey`), three
    sample widths labelled in N: the mean force, half the largest and the largest."""
    from matplotlib.lines import Line2D
    handles = [Line2D([], [], color=c, label=name) for name, c in entries.items()]
    if key is not None and key.top_force > 0:
        for force in sorted({key.mean_force, key.top_force / 2, key.top_force}):
            handles.append(Line2D([], [], color=key_colour, linewidth=key.max_linewidth * force / key.top_force,
                                  label=f"$f_n$ = {newtons(force)}"))
    if handles:
        ax.legend(handles=handles, fontsize="small", loc="upper left", bbox_to_anchor=(1.02, 1.0),
                  borderaxespad=0.0)


__all__ = ["plot_particles", "plot_force_chains", "plot_force_classes", "plot_contact_kinds",
           "contact_segments", "force_linewidths", "contact_collection"]
