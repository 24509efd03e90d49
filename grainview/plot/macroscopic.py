"""Figures of the macroscopic behaviour (paper Sec. III and V): q/p (Fig. 3), eps_p (Fig. 4),
the stress–dilatancy diagram (Fig. 5), q/p against its harmonic prediction (Fig. 12) and the
partial q/p of simple and double contacts (Fig. 18), all against the shear strain eps_q.

Each function takes one dataset, a dict ``{label: ds}`` or a list of ``(label, ds)`` and draws
every sample on the same axes (one colour per sample), returning the axes.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ..strain import friction_and_dilatancy, strains
from ..stress import stress_invariants
from ..forces import harmonic_prediction
from ._style import (EPS_Q_LABEL, axis_label, datasets, draw_evolutions, finish, get_axes, next_colour,
                     series_label, set_labels, values)


def plot_q_over_p(data, ax=None, label=None, **line_kw):
    """Normalised shear stress q/p against eps_q (paper Fig. 3).

    q/p from :func:`grainview.stress.stress_invariants` (wall contacts included,
    docs/conventions.md §1), eps_q from :func:`grainview.strain.strains`
    (docs/conventions.md §6). Both dimensionless.

    Parameters
    ----------
    data : xarray.Dataset, dict or list
        One dataset of the contract, or several to compare on the same axes as ``{label: ds}``
        or ``[(label, ds), ...]``.
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default: new axes on a new figure).
    label : str, optional
        Legend label of a single dataset (None: no legend entry), so that successive calls on
        the same axes build a comparison.
    **line_kw
        Keyword arguments of ``matplotlib.axes.Axes.plot`` (``color`` applies when a single
        sample is drawn).

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. III and Fig. 3; docs/conventions.md §1 and §6.
    """
    ax = get_axes(ax)
    draw_evolutions(ax, datasets(data, label), stress_invariants, [(None, "q_over_p")], **line_kw)
    set_labels(ax, EPS_Q_LABEL, "$q/p$")
    return finish(ax, None)


def plot_volumetric_strain(data, ax=None, label=None, **line_kw):
    """Cumulative volumetric strain eps_p (dilation positive) against eps_q (paper Fig. 4).

        eps_p = ln(1 + (V - V0)/V0)

    (:func:`grainview.strain.strains`), both strains dimensionless.

    Parameters
    ----------
    data : xarray.Dataset, dict or list
        One dataset of the contract, or several to compare on the same axes as ``{label: ds}``
        or ``[(label, ds), ...]``.
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default: new axes on a new figure).
    label : str, optional
        Legend label of a single dataset (None: no legend entry), so that successive calls on
        the same axes build a comparison.
    **line_kw
        Keyword arguments of ``matplotlib.axes.Axes.plot`` (``color`` applies when a single
        sample is drawn).

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. III and Fig. 4; docs/conventions.md §6.
    """
    ax = get_axes(ax)
    draw_evolutions(ax, datasets(data, label), strains, [(None, "eps_p")], **line_kw)
    set_labels(ax, EPS_Q_LABEL, r"$\varepsilon_p$")
    return finish(ax, None)


def plot_stress_dilatancy(data, ax=None, label=None, incremental: bool = False, **line_kw):
    """Stress–dilatancy diagram: dilatancy angle psi against friction angle phi, in rad (paper Fig. 5).

        sin phi = q/p,    sin psi = eps_p/eps_q (cumulative) or d eps_p/d eps_q (incremental)

    (:func:`grainview.strain.friction_and_dilatancy`). Snapshots where psi is undefined
    (eps_q = 0) leave a gap.

    The paper's point is that both shapes follow phi ~ phi_0 + psi (Taylor's stress–dilatancy
    relation, phi_0 the friction angle at zero dilatancy): each sample gets a dashed line of
    slope 1 with phi_0 the median of phi - psi over its snapshots, given in the legend.

    Parameters
    ----------
    data : xarray.Dataset, dict or list
        One dataset of the contract, or several to compare on the same axes as ``{label: ds}``
        or ``[(label, ds), ...]``.
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default: new axes on a new figure).
    label : str, optional
        Legend label of a single dataset (None: no legend entry), so that successive calls on
        the same axes build a comparison.
    incremental : bool, default False
        Draw the incremental angle, sin psi = d eps_p/d eps_q, instead of the cumulative one.
    **line_kw
        Keyword arguments of ``matplotlib.axes.Axes.plot``.

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. III and Fig. 5; docs/conventions.md §6.
    """
    ax = get_axes(ax)
    name = "psi_incremental" if incremental else "psi"
    for lab, ds in datasets(data, label):
        angles = friction_and_dilatancy(ds).compute()
        phi, psi = values(angles["phi"]), values(angles[name])
        colour = next_colour(ax)
        ax.plot(phi, psi, "o-", markersize=3, color=colour, label=lab, **line_kw)
        both = np.isfinite(phi) & np.isfinite(psi)
        if both.any():
            phi_0 = float(np.median(phi[both] - psi[both]))
            ends = np.array([np.nanmin(phi), np.nanmax(phi)])
            ax.plot(ends, ends - phi_0, "--", color=colour, linewidth=1,
                    label=series_label(lab, rf"$\varphi = \varphi_0 + \psi$, $\varphi_0$ = {phi_0:.2f} rad"))
    ax.axline((0.0, 0.0), slope=1.0, color="0.6", linewidth=0.8, zorder=0)  # phi = psi, the reference
    set_labels(ax, axis_label(r"$\varphi$", angles["phi"].attrs["units"]),
               axis_label(r"$\psi$", angles[name].attrs["units"]))
    return finish(ax, None)


def plot_harmonic_prediction(data, ax=None, label=None, bins: int = 36, **line_kw):
    """q/p and its harmonic predictions against eps_q (paper Eq. qa, Fig. 12).

    Three lines per sample, in this order: q/p (solid), its harmonic prediction

        (a' + a_n + a_t)/2

    and the same with the cross term, (a' + a_n + a_t)/(2 + a' a_n)
    (:func:`grainview.forces.harmonic_prediction`, ``bins`` angular sectors). All
    dimensionless.

    Parameters
    ----------
    data : xarray.Dataset, dict or list
        One dataset of the contract, or several to compare on the same axes as ``{label: ds}``
        or ``[(label, ds), ...]``.
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default: new axes on a new figure).
    label : str, optional
        Legend label of a single dataset (None: no legend entry), so that successive calls on
        the same axes build a comparison.
    bins : int, default 36
        Number of angular sectors of [0, pi), centred on theta_k = k pi/bins.
    **line_kw
        Keyword arguments of ``matplotlib.axes.Axes.plot`` (``color`` applies when a single
        sample is drawn).

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eq. qa (Sec. V.A) and Fig. 12; docs/conventions.md §3.
    """
    ax = get_axes(ax)
    curves = [("$q/p$", "q_over_p"), ("$(a' + a_n + a_t)/2$", "prediction"),
              ("$(a' + a_n + a_t)/(2 + a' a_n)$", "prediction_cross_term")]
    draw_evolutions(ax, datasets(data, label), lambda ds: harmonic_prediction(ds, bins), curves, **line_kw)
    set_labels(ax, EPS_Q_LABEL, "$q/p$")
    return finish(ax, None)


def plot_partial_q_over_p(data, ax=None, label=None, **line_kw):
    """q/p of simple (s), double (d) and all (s+d) contacts against eps_q (paper Fig. 18).

    Each partial deviator is divided by the p of the whole sample
    (:func:`grainview.stress.stress_invariants` with ``kind``). Three lines per sample: s, d,
    s+d. Dimensionless.

    Parameters
    ----------
    data : xarray.Dataset, dict or list
        One dataset of the contract, or several to compare on the same axes as ``{label: ds}``
        or ``[(label, ds), ...]``.
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default: new axes on a new figure).
    label : str, optional
        Legend label of a single dataset (None: no legend entry), so that successive calls on
        the same axes build a comparison.
    **line_kw
        Keyword arguments of ``matplotlib.axes.Axes.plot`` (``color`` applies when a single
        sample is drawn).

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eq. sigmasd and Fig. 18; docs/conventions.md §1.
    """
    ax = get_axes(ax)
    curves = [("s", "simple"), ("d", "double"), ("s+d", "all")]
    draw_evolutions(ax, datasets(data, label), _partial_q_over_p, curves, **line_kw)
    set_labels(ax, EPS_Q_LABEL, "$q/p$")
    return finish(ax, None)


def _partial_q_over_p(ds):
    return xr.Dataset({kind: stress_invariants(ds, kind)["q_over_p"] for kind in ("simple", "double", "all")})


__all__ = ["plot_q_over_p", "plot_volumetric_strain", "plot_stress_dilatancy",
           "plot_harmonic_prediction", "plot_partial_q_over_p"]
