"""Figures of the coarse-grained fields (:mod:`grainview.coarse_graining`): maps of a snapshot's
fields (sigma_yy, q/p, solid fraction...) over the sample, and their profiles across it, where
shear bands show. The fields are computed by :func:`grainview.coarse_graining.coarse_grained`;
these functions only draw them.
"""

from __future__ import annotations

import numpy as np

from ..contract.errors import ParameterError
from ._style import axis_label, new_figure, single_dataset, snapshot_index

__all__ = ["plot_field_maps", "plot_field_profiles", "DEFAULT_FIELDS"]

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
        from ..coarse_graining import coarse_grained

        snap = coarse_grained(ds.isel(time=[k]), width=width, spacing=spacing, cutoff=cutoff).isel(time=0)
        if {"box_min", "box_max"} <= set(ds.variables):  # the strains of the whole run, not of this snapshot alone
            from ..strain import strains

            snap = snap.assign_coords(eps_q=strains(ds)["eps_q"].isel(time=k, drop=True))
        return snap.compute()
    if fields.sizes.get("time") != ds.sizes["time"]:
        raise ParameterError(f"fields has {fields.sizes.get('time')} snapshots, the dataset {ds.sizes['time']}: "
                             "pass coarse_grained(ds) of the same dataset")
    return fields.isel(time=k).compute()


def _names(names):
    from ..coarse_graining import QUANTITIES

    names = (names,) if isinstance(names, str) else tuple(names)
    if not names or any(name not in QUANTITIES for name in names):
        raise ParameterError(f"names={names!r}: expected quantities among {', '.join(QUANTITIES)}")
    return names


def _label(name, units):
    return axis_label(SYMBOLS.get(name, name), units)


def plot_field_maps(data, names=DEFAULT_FIELDS, time: int = -1, width=None, spacing=None, cutoff: float = 3.0,
                    fields=None, stress: str = "total", title: bool = True):
    """Maps of coarse-grained fields of snapshot ``time``, one panel per quantity, over the grid,
    with the sample's box drawn as a black frame; q/p only inside the box (outside it the ratio
    of the kernels' tails means nothing).

    Parameters
    ----------
    data : xarray.Dataset, dict or list
        One dataset of the contract (a dict or list must hold exactly one).
    names : sequence of str, default ("sigma_yy", "q_over_p", "solid_fraction")
        The quantities (:data:`grainview.coarse_graining.QUANTITIES`).
    time : int, default -1
        Index of the snapshot drawn (negative counts from the end).
    width, spacing, cutoff : float, optional
        The kernel width, grid spacing (m) and cutoff (widths) of
        :func:`grainview.coarse_graining.coarse_grained`, when ``fields`` is not given.
    fields : xarray.Dataset, optional
        ``coarse_grained(ds, ...)`` of the whole dataset, to draw instead of computing the fields
        of the one snapshot.
    stress : {"total", "contact", "kinetic"}, default "total"
        The stress of the stress quantities.
    title : bool, default True
        Title each panel with the kernel width and the snapshot's eps_q.

    Returns
    -------
    matplotlib.figure.Figure
        The figure, axes x and y in m, each panel with a colour bar in the quantity's units.

    Raises
    ------
    grainview.contract.errors.ParameterError
        For several datasets, an unknown quantity, or ``fields`` of another dataset.

    References
    ----------
    Weinhart, Thornton, Luding & Bokhove, Granular Matter 14, 289 (2012); docs/analysis.md,
    "Coarse-grained fields".
    """
    from ..coarse_graining import interior, scalar_field

    _, ds = single_dataset(data)
    names = _names(names)
    k = snapshot_index(ds, time)
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
        ax.add_patch(_frame(lo, hi))
        ax.set_aspect("equal")
        ax.set_xlabel(axis_label("$x$", "m"))
        ax.set_ylabel(axis_label("$y$", "m"))
        fig.colorbar(mesh, ax=ax, shrink=0.85, label=_label(name, field.attrs.get("units")))
        if title:
            strain = f", $\\varepsilon_q$ = {float(snap['eps_q']):.2f}" if "eps_q" in snap.coords else ""
            ax.set_title(f"{SYMBOLS.get(name, name)}, $w$ = {1e3 * snap.attrs['width_m']:.3g} mm{strain}",
                         fontsize="medium")
    return fig


def _frame(lo, hi):
    from matplotlib.patches import Rectangle

    return Rectangle(lo, hi[0] - lo[0], hi[1] - lo[1], fill=False, edgecolor="k", linewidth=1.0)


def plot_field_profiles(data, names=DEFAULT_FIELDS, time=-1, across: str = "x", width=None, spacing=None,
                        cutoff: float = 3.0, fields=None, margin=None, stress: str = "total", label=None):
    """Profiles across the sample: each quantity averaged over the other grid axis, against
    ``across``, one panel per quantity (:func:`grainview.coarse_graining.profile`), over the
    nodes at least ``margin`` inside the box (:func:`grainview.coarse_graining.interior`).

    Parameters
    ----------
    data : xarray.Dataset, dict or list
        One dataset of the contract (a dict or list must hold exactly one).
    names : sequence of str, default ("sigma_yy", "q_over_p", "solid_fraction")
        The quantities (:data:`grainview.coarse_graining.QUANTITIES`).
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
    from ..coarse_graining import interior, profile, scalar_field

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
