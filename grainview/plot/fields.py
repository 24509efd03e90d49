"""Figures of the coarse-grained fields (:mod:`grainview.analysis.coarse_graining`): maps of a snapshot's
fields (sigma_yy, q/p, solid fraction...) over the sample, and their profiles across it, where
shear bands show. The fields are computed by :func:`grainview.analysis.coarse_graining.coarse_grained`;
these functions only draw them.
"""

from __future__ import annotations

import numpy as np

from ..contract.errors import ParameterError
from ._docs import fill_doc
from ._style import axis_label, new_figure, single_dataset, snapshot_index

__all__ = ["plot_field_maps", "plot_field_profiles", "plot_shear_band", "draw_band", "DEFAULT_FIELDS"]

DEFAULT_FIELDS = ("sigma_yy", "q_over_p", "solid_fraction")
"""The quantities drawn by default: vertical stress, stress ratio, solid fraction."""

SYMBOLS = {"sigma_xx": r"$\sigma_{xx}$", "sigma_yy": r"$\sigma_{yy}$", "sigma_xy": r"$\sigma_{xy}$", "p": "$p$",
           "q": "$q$", "q_over_p": "$q/p$", "solid_fraction": r"$\nu$", "density": r"$\rho$", "speed": "$|V|$",
           "fabric_anisotropy": "$a$", "shear_rate": r"$\dot\gamma$"}
CMAPS = {"q_over_p": "viridis", "solid_fraction": "cividis", "speed": "magma", "fabric_anisotropy": "viridis",
         "shear_rate": "magma"}


def _fields_of(ds, fields, k, width, spacing, cutoff):
    """Snapshot ``k`` of ``fields`` (coarse_grained of all of ``ds``), or the fields computed for
    that snapshot alone."""
    if fields is None:
        from ..analysis.coarse_graining import coarse_grained

        snap = coarse_grained(ds.isel(time=[k]), width=width, spacing=spacing, cutoff=cutoff).isel(time=0)
        if {"box_min", "box_max"} <= set(ds.variables):  # the strains of the whole run, not of this snapshot alone
            from ..analysis.strain import strains

            snap = snap.assign_coords(eps_q=strains(ds)["eps_q"].isel(time=k, drop=True))
        return snap.compute()
    if fields.sizes.get("time") != ds.sizes["time"]:
        raise ParameterError(f"fields has {fields.sizes.get('time')} snapshots, the dataset {ds.sizes['time']}: "
                             "pass coarse_grained(ds) of the same dataset")
    return fields.isel(time=k).compute()


def _names(names):
    from ..analysis.coarse_graining import QUANTITIES

    names = (names,) if isinstance(names, str) else tuple(names)
    if not names or any(name not in QUANTITIES for name in names):
        raise ParameterError(f"names={names!r}: expected quantities among {', '.join(QUANTITIES)}")
    return names


def _label(name, units):
    return axis_label(SYMBOLS.get(name, name), units)


@fill_doc
def plot_field_maps(data, names=DEFAULT_FIELDS, time: int = -1, width=None, spacing=None, cutoff: float = 3.0,
                    fields=None, stress: str = "total", title: bool = True, band=None):
    """Maps of coarse-grained fields of snapshot ``time``, one panel per quantity, over the grid,
    with the sample's box drawn as a black frame; q/p only inside the box (outside it the ratio
    of the kernels' tails means nothing).

    Parameters
    ----------
    data : xarray.Dataset, dict or list
        One dataset of the contract (a dict or list must hold exactly one).
    names : sequence of str, default ("sigma_yy", "q_over_p", "solid_fraction")
        The quantities (:data:`grainview.analysis.coarse_graining.QUANTITIES`).
    {time_drawn}
    width, spacing, cutoff : float, optional
        The kernel width, grid spacing (m) and cutoff (widths) of
        :func:`grainview.analysis.coarse_graining.coarse_grained`, when ``fields`` is not given.
    fields : xarray.Dataset, optional
        ``coarse_grained(ds, ...)`` of the whole dataset, to draw instead of computing the fields
        of the one snapshot.
    stress : {"total", "contact", "kinetic"}, default "total"
        The stress of the stress quantities.
    title : bool, default True
        Title each panel with the kernel width and the snapshot's eps_q.
    band : bool or xarray.Dataset, optional
        Draw a shear band over the shear-rate panel (``"shear_rate"`` among ``names``): True
        finds it in the drawn snapshot's shear rate over the nodes two widths inside the box
        (:func:`grainview.analysis.shear_bands.find_shear_band`, its defaults), or give the finder's
        result (e.g. of the mean flow over a strain window). Drawn by :func:`draw_band`.

    Returns
    -------
    matplotlib.figure.Figure
        The figure, axes x and y in m, each panel with a colour bar in the quantity's units.

    Raises
    ------
    grainview.contract.errors.ParameterError
        For several datasets, an unknown quantity, or ``fields`` of another dataset; for
        ``band`` without "shear_rate" among ``names``.

    References
    ----------
    Weinhart, Thornton, Luding & Bokhove, Granular Matter 14, 289 (2012); docs/analysis.md,
    "Coarse-grained fields".
    """
    from ..analysis.coarse_graining import interior, scalar_field

    _, ds = single_dataset(data)
    names = _names(names)
    k = snapshot_index(ds, time)
    if band is not None and band is not False and "shear_rate" not in names:
        raise ParameterError(f"band= draws over the shear-rate map: expected 'shear_rate' among names={names!r}")
    snap = _fields_of(ds, fields, k, width, spacing, cutoff)
    fig, axes = new_figure(len(names), width=4.2, height=3.9)
    lo, hi = np.asarray(snap["box_min"].values, float), np.asarray(snap["box_max"].values, float)
    for ax, name in zip(axes, names):
        field = scalar_field(snap, name, stress)
        if name == "q_over_p":  # a ratio of the kernels' tails means nothing outside the packing
            field = field.where(interior(snap, margin=0.0))
        values = np.ma.masked_invalid(np.asarray(field.values, float))
        mesh = ax.pcolormesh(snap["x"].values, snap["y"].values, values, shading="nearest",
                             cmap=CMAPS.get(name, "RdBu_r" if name == "sigma_xy" else "inferno"))
        if name == "sigma_xy":
            bound = float(np.nanmax(np.abs(values))) if values.count() else 1.0
            mesh.set_clim(-bound, bound)
        frame = ax.add_patch(_frame(lo, hi))
        if name == "shear_rate" and band is not None and band is not False:
            if band is True:
                from ..analysis.shear_bands import find_shear_band

                found = find_shear_band(field, inside=interior(snap))
            else:
                found = band
            draw_band(ax, found, clip=frame)
        ax.set_aspect("equal")
        ax.set_xlabel(axis_label("$x$", "m"))
        ax.set_ylabel(axis_label("$y$", "m"))
        fig.colorbar(mesh, ax=ax, shrink=0.85, label=_label(name, field.attrs.get("units")))
        if title:
            strain = f", $\\varepsilon_q$ = {float(snap['eps_q']):.2f}" if "eps_q" in snap.coords else ""
            ax.set_title(f"{SYMBOLS.get(name, name)}, $w$ = {1e3 * snap.attrs['width_m']:.3g} mm{strain}",
                         fontsize="medium")
    return fig


def draw_band(ax, band, clip=None, color="c"):
    """Draw a shear band (:func:`grainview.analysis.shear_bands.find_shear_band`) over a map: its two
    half-maximum lines, s = edges (dashed), where s = -x sin(angle) + y cos(angle), and a legend
    entry with its angle to the x axis, width at half maximum and share of the shear rate in
    the searched strip; "no band" in the legend when the finder found none (nothing drawn).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Axes of a map in m.
    band : xarray.Dataset
        The finder's result.
    clip : matplotlib.patches.Patch, optional
        The lines are clipped to it (e.g. the sample's box); default the axes.
    color : str, default "c"
        The lines' colour.

    Returns
    -------
    list of matplotlib.lines.Line2D
        The lines drawn (none without a band).
    """
    if not bool(band["found"]):
        ax.plot([], [], " ", label=f"no band (contrast {float(band['contrast']):.2f})")
        ax.legend(fontsize="small", loc="upper right")
        return []
    t = np.radians(float(band["angle"]))
    tangent, normal = np.array([np.cos(t), np.sin(t)]), np.array([-np.sin(t), np.cos(t)])
    x0, x1 = ax.get_xlim()
    y0, y1 = ax.get_ylim()
    reach = np.hypot(x1 - x0, y1 - y0) + abs(float(band["edges"].max())) + abs(float(band["edges"].min()))
    u = np.array([-reach, reach])
    lines = []
    for k, s in enumerate(np.asarray(band["edges"].values, float)):
        points = s * normal[:, None] + tangent[:, None] * u
        label = (f"band: {float(band['angle']):.0f}°, {1e3 * float(band['fwhm']):.0f} mm, "
                 f"{100 * float(band['share']):.0f}% of the rate") if k == 0 else None
        (line,) = ax.plot(points[0], points[1], "--", color=color, linewidth=1.5, label=label)
        line.set_clip_path(clip if clip is not None else ax.patch)
        lines.append(line)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.legend(fontsize="small", loc="upper right")
    return lines


def plot_shear_band(rate, band=None, inside=None, box=None, ax=None, title=None):
    """A shear-rate map (e.g. of the mean flow over a strain window) with its shear band drawn
    over it (:func:`draw_band`).

    Parameters
    ----------
    rate : xarray.DataArray
        The map over (y, x), coordinates in m, in s-1 (``scalar_field(..., "shear_rate")``).
    band : xarray.Dataset, optional
        :func:`grainview.analysis.shear_bands.find_shear_band` of it; default found over ``inside``.
    inside : xarray.DataArray of bool, optional
        The nodes drawn and searched (e.g. ``interior(fields).all("time")``); the others blank.
    box : (array_like, array_like), optional
        The sample's box (box_min, box_max) in m, drawn as a black frame that clips the band.
    ax : matplotlib.axes.Axes, optional
        Where to draw; default a new figure.
    title : str, optional
        The panel's title.

    Returns
    -------
    matplotlib.figure.Figure
        The figure: x and y in m, a colour bar in s-1.

    Raises
    ------
    grainview.contract.errors.ParameterError
        As :func:`grainview.analysis.shear_bands.find_shear_band`.
    """
    from ..analysis.shear_bands import find_shear_band

    band = find_shear_band(rate, inside=inside) if band is None else band
    shown = rate if inside is None else rate.where(inside)
    if ax is None:
        fig, axes = new_figure(1, width=4.4, height=4.2)
        ax = axes[0]
    fig = ax.figure
    mesh = ax.pcolormesh(shown["x"].values, shown["y"].values, np.ma.masked_invalid(shown.transpose("y", "x").values),
                         shading="nearest", cmap=CMAPS["shear_rate"])
    fig.colorbar(mesh, ax=ax, shrink=0.85, label=_label("shear_rate", rate.attrs.get("units", "s-1")))
    clip = ax.add_patch(_frame(np.asarray(box[0], float), np.asarray(box[1], float))) if box is not None else None
    ax.set_aspect("equal")
    ax.set_xlabel(axis_label("$x$", "m"))
    ax.set_ylabel(axis_label("$y$", "m"))
    draw_band(ax, band, clip=clip)
    if title:
        ax.set_title(title, fontsize="medium")
    return fig


def _frame(lo, hi):
    from matplotlib.patches import Rectangle

    return Rectangle(lo, hi[0] - lo[0], hi[1] - lo[1], fill=False, edgecolor="k", linewidth=1.0)


def plot_field_profiles(data, names=DEFAULT_FIELDS, time=-1, across: str = "x", width=None, spacing=None,
                        cutoff: float = 3.0, fields=None, margin=None, stress: str = "total", label=None):
    """Profiles across the sample: each quantity averaged over the other grid axis, against
    ``across``, one panel per quantity (:func:`grainview.analysis.coarse_graining.profile`), over the
    nodes at least ``margin`` inside the box (:func:`grainview.analysis.coarse_graining.interior`).

    Parameters
    ----------
    data : xarray.Dataset, dict or list
        One dataset of the contract (a dict or list must hold exactly one).
    names : sequence of str, default ("sigma_yy", "q_over_p", "solid_fraction")
        The quantities (:data:`grainview.analysis.coarse_graining.QUANTITIES`).
    time : int or sequence of int, default -1
        The snapshot(s) drawn, one curve each (negative counts from the end).
    across : {"x", "y"}, default "x"
        The axis the profiles run along.
    width, spacing, cutoff : float, optional
        As :func:`plot_field_maps`, when ``fields`` is not given.
    fields : xarray.Dataset, optional
        ``coarse_grained(ds, ...)`` of the whole dataset.
    margin : float, optional
        Distance from the box's edges left out, m (default: two kernel widths).
    stress : {"total", "contact", "kinetic"}, default "total"
        The stress of the stress quantities.
    label : str, optional
        Legend label prefix of the curves (each curve is also labelled with its eps_q).

    Returns
    -------
    matplotlib.figure.Figure
        The figure: ``across`` in m on the x axis, each quantity in its units on the y axis.

    Raises
    ------
    grainview.contract.errors.ParameterError
        For several datasets, an unknown quantity or axis, or ``fields`` of another dataset.

    References
    ----------
    Weinhart, Thornton, Luding & Bokhove, Granular Matter 14, 289 (2012); docs/analysis.md,
    "Coarse-grained fields".
    """
    from ..analysis.coarse_graining import interior, profile, scalar_field

    _, ds = single_dataset(data, label)
    names = _names(names)
    if across not in ("x", "y"):
        raise ParameterError(f"across={across!r}: expected 'x' or 'y'")
    times = [time] if isinstance(time, (int, np.integer)) else list(time)
    fig, axes = new_figure(len(names), width=4.0, height=3.4)
    for t in times:
        k = snapshot_index(ds, t)
        snap = _fields_of(ds, fields, k, width, spacing, cutoff)
        inside = interior(snap, margin)
        strain = f"$\\varepsilon_q$ = {float(snap['eps_q']):.2f}" if "eps_q" in snap.coords else f"snapshot {k}"
        for ax, name in zip(axes, names):
            field = scalar_field(snap, name, stress)
            curve = profile(field, across=across, inside=inside)
            ax.plot(curve[across].values, curve.values, label=f"{label}, {strain}" if label else strain)
            ax.set_xlabel(axis_label(f"${across}$", "m"))
            ax.set_ylabel(_label(name, field.attrs.get("units")))
    axes[0].legend(fontsize="small")
    return fig
