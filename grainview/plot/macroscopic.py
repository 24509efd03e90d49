"""Figures of the macroscopic behaviour (paper Sec. III and V): q/p (Fig. 3), eps_p (Fig. 4),
the stress–dilatancy diagram (Fig. 5), q/p against its harmonic prediction (Fig. 12) and the
partial q/p of simple and double contacts (Fig. 18), all against the shear strain eps_q.

Each function takes one dataset, a dict ``{label: ds}`` or a list of ``(label, ds)`` and draws
every sample on the same axes (one colour per sample), returning the axes.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ..analysis.strain import (EARLY_STRAIN, RESIDUAL_STRAIN, friction_and_dilatancy, friction_offset,
                               residual_window, strains)
from ..analysis.stress import stress_invariants
from ..analysis.forces import harmonic_prediction
from ._docs import fill_doc
from ._style import (EPS_Q_LABEL, PALETTE, axis_label, datasets, draw_evolutions, eps_q, finish, get_axes,
                     sample_colour, series_label, set_labels, values)


@fill_doc
def plot_q_over_p(data, ax=None, label=None, **line_kw):
    """Normalised shear stress q/p against eps_q (paper Fig. 3).

    q/p from :func:`grainview.analysis.stress.stress_invariants` (wall contacts included,
    docs/conventions.md §1), eps_q from :func:`grainview.analysis.strain.strains`
    (docs/conventions.md §6). Both dimensionless.

    Parameters
    ----------
    {data}
    {ax}
    {label}
    {line_kw_colour}

    Returns
    -------
    {returns_axes}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. III and Fig. 3; docs/conventions.md §1 and §6.
    """
    ax = get_axes(ax)
    draw_evolutions(ax, datasets(data, label), stress_invariants, [(None, "q_over_p")], **line_kw)
    set_labels(ax, EPS_Q_LABEL, "$q/p$")
    return finish(ax, None)


@fill_doc
def plot_volumetric_strain(data, ax=None, label=None, **line_kw):
    """Cumulative volumetric strain eps_p (dilation positive) against eps_q (paper Fig. 4).

        eps_p = ln(1 + (V - V0)/V0)

    (:func:`grainview.analysis.strain.strains`), both strains dimensionless.

    Parameters
    ----------
    {data}
    {ax}
    {label}
    {line_kw_colour}

    Returns
    -------
    {returns_axes}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. III and Fig. 4; docs/conventions.md §6.
    """
    ax = get_axes(ax)
    draw_evolutions(ax, datasets(data, label), strains, [(None, "eps_p")], **line_kw)
    set_labels(ax, EPS_Q_LABEL, r"$\varepsilon_p$")
    return finish(ax, None)


def _angles(ds, min_strain, incremental):
    """phi and psi of every snapshot (rad), NaN below ``min_strain``."""
    angles = friction_and_dilatancy(ds).compute()
    early = eps_q(ds) < min_strain
    phi = np.where(early, np.nan, values(angles["phi"]))
    psi = np.where(early, np.nan, values(angles["psi_incremental" if incremental else "psi"]))
    return phi, psi


@fill_doc
def plot_stress_dilatancy(data, ax=None, label=None, incremental: bool = False, min_strain: float = EARLY_STRAIN,
                          **line_kw):
    """Stress–dilatancy diagram: dilatancy angle psi against friction angle phi, in rad (paper Fig. 5).

        sin phi = q/p,    sin psi = eps_p/eps_q (cumulative) or d eps_p/d eps_q (incremental)

    (:func:`grainview.analysis.strain.friction_and_dilatancy`). Snapshots where psi is undefined
    (eps_q = 0) or ill-conditioned (eps_q < ``min_strain``) are not drawn (their line points are
    NaN), and the panel says so.

    The paper's point is that both shapes follow phi ~ phi_0 + psi (Taylor's stress–dilatancy
    relation, phi_0 the friction angle at zero dilatancy): each sample gets a dotted guide of
    slope 1 through phi_0, the median of phi - psi (:func:`grainview.analysis.strain.friction_offset`), labelled as a
    guide and not a fit, with phi_0 in the legend. Its slope is parallel to phi = psi, which
    passes through the origin, away from both paths, and is not drawn.

    Parameters
    ----------
    {data}
    {ax}
    {label}
    incremental : bool, default False
        Draw the incremental angle, sin psi = d eps_p/d eps_q, instead of the cumulative one.
    min_strain : float, default 0.02
        Snapshots with a smaller eps_q are not drawn (:data:`grainview.analysis.strain.EARLY_STRAIN`); 0 draws them all.
    {line_kw}

    Returns
    -------
    {returns_axes}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. III and Fig. 5; docs/conventions.md §6.
    """
    ax = get_axes(ax)
    for lab, ds in datasets(data, label):
        phi, psi = _angles(ds, min_strain, incremental)
        colour = sample_colour(ax, lab, ds)
        ax.plot(phi, psi, "o-", markersize=3, color=colour, label=lab, **line_kw)
        phi_0 = friction_offset(ds, min_strain, incremental)
        if np.isfinite(phi_0):
            ends = np.array([np.nanmin(phi), np.nanmax(phi)])
            ax.plot(ends, ends - phi_0, ":", color=colour, linewidth=1.2,
                    label=series_label(lab, rf"guide of slope 1, not a fit: $\varphi_0$ = {phi_0:.2f} rad"))
    if min_strain > 0:
        ax.text(0.98, 0.02, rf"$\varepsilon_q < {min_strain:g}$ not drawn ($\psi$ ill-conditioned)",
                transform=ax.transAxes, ha="right", va="bottom", fontsize="x-small", color="0.3")
    symbol = r"$\psi$" + (r" (incremental)" if incremental else "")
    set_labels(ax, axis_label(r"$\varphi$", "rad"), axis_label(symbol, "rad"))
    return finish(ax, None)


@fill_doc
def plot_harmonic_prediction(data, ax=None, label=None, bins: int = 36, **line_kw):
    """q/p and its harmonic predictions against eps_q (paper Eq. qa, Fig. 12).

    Three lines per sample, in this order: q/p, its harmonic prediction

        (a' + a_n + a_t)/2

    and the same with the cross term, (a' + a_n + a_t)/(2 + a' a_n)
    (:func:`grainview.analysis.forces.harmonic_prediction`, ``bins`` angular sectors). All
    dimensionless. Where the three agree (the disks) they overlap within the snapshots' noise,
    so they are drawn to stay apart even then: q/p as a wide pale band, the predictions as thin
    dashed and thin solid lines over it, all in the sample's colour; each legend entry gives
    the curve's mean over the residual state (eps_q >= 0.3), so that the agreement is read as
    numbers too.

    Parameters
    ----------
    {data}
    {ax}
    {label}
    {bins}
    {line_kw_colour}

    Returns
    -------
    {returns_axes}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eq. qa (Sec. V.A) and Fig. 12; docs/conventions.md §3.
    """
    ax = get_axes(ax)
    given = line_kw.pop("color", None)
    pairs = datasets(data, label)
    for lab, ds in pairs:
        result = harmonic_prediction(ds, bins).compute()
        x = eps_q(ds)
        window = np.asarray(residual_window(ds).values, bool)
        colour = given if given is not None and len(pairs) == 1 else sample_colour(ax, lab, ds)
        for (curve, name), style in zip(HARMONIC_CURVES, HARMONIC_STYLES):
            y = values(result[name])
            text = curve + (f": {np.nanmean(y[window]):.2f}" if window.any() else "")
            ax.plot(x, y, color=colour, label=series_label(lab, text), **{**style, **line_kw})
    set_labels(ax, EPS_Q_LABEL, "$q/p$ and its predictions")
    finish(ax, None)
    if ax.get_legend() is not None:
        ax.get_legend().set_title(rf"mean over $\varepsilon_q \geq {RESIDUAL_STRAIN:g}$", prop={"size": "small"})
    return ax


HARMONIC_CURVES = [("$q/p$", "q_over_p"), ("$(a' + a_n + a_t)/2$", "prediction"),
                   ("$(a' + a_n + a_t)/(2 + a' a_n)$", "prediction_cross_term")]
"""Fig. 12's curves: legend text and variable of :func:`grainview.analysis.forces.harmonic_prediction`."""
HARMONIC_STYLES = [dict(linewidth=4.0, alpha=0.35, solid_capstyle="butt"), dict(linewidth=1.0, linestyle="--"),
                   dict(linewidth=0.9, linestyle="-")]
"""Fig. 12's line styles: q/p a wide pale band, the two predictions thin lines over it."""


@fill_doc
def plot_partial_q_over_p(data, ax=None, label=None, **line_kw):
    """q/p of simple (s), double (d) and all (s+d) contacts against eps_q (paper Fig. 18).

    Each partial deviator is divided by the p of the whole sample
    (:func:`grainview.analysis.stress.stress_invariants` with ``kind``). Three lines per sample: s, d,
    s+d; with one sample in the contact kinds' colours (:data:`grainview.plot._style.PALETTE`).
    Dimensionless.

    Parameters
    ----------
    {data}
    {ax}
    {label}
    {line_kw_colour}

    Returns
    -------
    {returns_axes}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eq. sigmasd and Fig. 18; docs/conventions.md §1.
    """
    ax = get_axes(ax)
    curves = [("s", "simple"), ("d", "double"), ("s+d", "all")]
    draw_evolutions(ax, datasets(data, label), _partial_q_over_p, curves,
                    curve_colours=[PALETTE[kind] for kind in ("simple", "double", "all")], **line_kw)
    set_labels(ax, EPS_Q_LABEL, "$q_s/p$, $q_d/p$, $q/p$")
    return finish(ax, None)


def _partial_q_over_p(ds):
    return xr.Dataset({kind: stress_invariants(ds, kind)["q_over_p"] for kind in ("simple", "double", "all")})


__all__ = ["plot_q_over_p", "plot_volumetric_strain", "plot_stress_dilatancy",
           "plot_harmonic_prediction", "plot_partial_q_over_p"]
