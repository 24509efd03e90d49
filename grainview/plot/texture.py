"""Figures of the texture (paper Sec. IV): coordination z and persistence gamma (Fig. 6),
connectivity P(c) (Fig. 7), polar P(theta) (Fig. 8), fabric anisotropy a' (Fig. 9), the grey
map of P(m_s, m_d) (Fig. 21) and the partial anisotropies a'_s, a'_d (Fig. 22).

Distributions (P(c), P(theta), P(m_s, m_d)) are averaged over the snapshots chosen by ``time``
(default ``"residual"``: the residual state; see :func:`grainview.analysis.snapshots.select_snapshots`).
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ..analysis.connectivity import connectivity_pdf, coordination, joint_connectivity_pdf
from ..analysis.fabric import fabric_anisotropy, orientation_pdf
from ..analysis.snapshots import select_snapshots, time_mean
from ._docs import fill_doc
from ._style import (EPS_Q_LABEL, PALETTE, axis_label, datasets, draw_evolutions, finish, get_axes,
                     sample_colour, tidy_polar, set_labels, single_dataset, units_of, values)


@fill_doc
def plot_coordination(data, ax=None, label=None, walls: bool = False, **line_kw):
    """Coordination number z of the force-bearing network against eps_q (paper Fig. 6a).

        z = sum_i c_i / N'

    over the N' non-rattler particles (rattlers left out, a double contact counted once;
    docs/conventions.md §7; :func:`grainview.analysis.connectivity.coordination`). Dimensionless.

    Parameters
    ----------
    {data}
    {ax}
    {label}
    {walls}
    {line_kw_colour}

    Returns
    -------
    {returns_axes}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. IV.A and Fig. 6a; docs/conventions.md §7.
    """
    ax = get_axes(ax)
    draw_evolutions(ax, datasets(data, label), lambda ds: coordination(ds, walls=walls), [(None, "z")],
                    **line_kw)
    set_labels(ax, EPS_Q_LABEL, "$z$")
    return finish(ax, None)


@fill_doc
def plot_persistence(data, ax=None, label=None, reference: int = 0, **line_kw):
    """Fraction gamma of the contacts of snapshot ``reference`` still present, against eps_q (paper Fig. 6b).

        gamma(t) = |C(ref) & C(t)| / |C(ref)|

    (docs/conventions.md §8; :func:`grainview.analysis.persistence.persistence`, particle–particle
    force-bearing contacts). Dimensionless; computed.

    Parameters
    ----------
    {data}
    {ax}
    {label}
    reference : int, default 0
        The reference snapshot index (negative counts from the end).
    {line_kw_colour}

    Returns
    -------
    {returns_axes}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. IV.A and Fig. 6b; docs/conventions.md §8.
    """
    from ..analysis.persistence import persistence
    ax = get_axes(ax)
    draw_evolutions(ax, datasets(data, label), lambda ds: persistence(ds, reference=reference), [(None, None)],
                    **line_kw)
    which = "the first snapshot's" if reference == 0 else f"snapshot {reference}'s"
    set_labels(ax, EPS_Q_LABEL, rf"$\gamma$: share of {which} contacts present")
    return finish(ax, None)


@fill_doc
def plot_connectivity_pdf(data, ax=None, label=None, time="residual", max_c: int = 10, walls: bool = False,
                          **line_kw):
    """P(c) against c, averaged over the snapshots ``time`` (paper Fig. 7).

    P(c) is the fraction of (non-rattler) particles with exactly c force-bearing contacts
    (:func:`grainview.analysis.connectivity.connectivity_pdf`). Markers only, c >= 1 (P(c) is discrete,
    and P(0) = 0 by definition once rattlers are left out); one marker series per sample.

    Parameters
    ----------
    {data}
    {ax}
    {label}
    {time_averaged}
    max_c : int, default 10
        The largest c drawn.
    {walls}
    {line_kw}

    Returns
    -------
    {returns_axes}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. IV.A and Fig. 7; docs/conventions.md §7.
    """
    ax = get_axes(ax)
    for lab, ds in datasets(data, label):
        pdf = time_mean(connectivity_pdf(select_snapshots(ds, time), max_c=max_c, walls=walls)).sel(c=slice(1, None)).compute()
        ax.plot(pdf["c"].values, values(pdf), "o", linestyle="none", color=sample_colour(ax, lab, ds), label=lab,
                **line_kw)
    ax.set_xticks(np.arange(1, max_c + 1))  # c is an integer: every value labelled
    set_labels(ax, "$c$", "$P(c)$")
    return finish(ax, None)


@fill_doc
def plot_orientation_pdf(data, ax=None, label=None, time="residual", bins: int = 36, kind="all",
                         walls: bool = False, **line_kw):
    """Polar plot of the density P(theta) of contact-normal orientations (rad-1) (paper Fig. 8).

    Averaged over the snapshots ``time`` (:func:`grainview.analysis.fabric.orientation_pdf`). P is
    pi-periodic; the curve is drawn over the full turn (P(theta + pi) = P(theta)) and closed.
    Needs polar axes (created when ``ax`` is None).

    Parameters
    ----------
    {data}
    {ax_polar}
    {label}
    {time_averaged}
    {bins}
    {kind}
    {walls}
    {line_kw}

    Returns
    -------
    {returns_axes}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. IV and Fig. 8; docs/conventions.md §2.
    """
    ax = get_axes(ax, polar=True)
    for lab, ds in datasets(data, label):
        pdf = time_mean(orientation_pdf(select_snapshots(ds, time), bins=bins, kind=kind, walls=walls)).compute()
        theta, r = full_turn(pdf["theta"].values, values(pdf))
        ax.plot(theta, r, color=sample_colour(ax, lab, ds), label=lab, **line_kw)
    tidy_polar(ax)
    ax.set_xlabel(axis_label(r"$\theta$", "rad"))
    return finish(ax, None, title=axis_label(r"$P(\theta)$", units_of(pdf)))


def full_turn(theta, r):
    """A pi-periodic function sampled on [0, pi) extended to [0, 2 pi] and closed.

    Parameters
    ----------
    theta : numpy.ndarray
        Angles in [0, pi), rad.
    r : numpy.ndarray
        The values at ``theta``.

    Returns
    -------
    theta, r : numpy.ndarray
        The angles theta, theta + pi and the first angle + 2 pi (rad), and the values repeated
        to match.
    """
    theta = np.concatenate([theta, theta + np.pi, theta[:1] + 2 * np.pi])
    r = np.concatenate([r, r, r[:1]])
    return theta, r


@fill_doc
def plot_fabric_anisotropy(data, ax=None, label=None, walls: bool = False, **line_kw):
    """Signed fabric anisotropy a' = a cos 2(theta_F - theta_sigma) against eps_q (paper Fig. 9).

        a' = 2 (F_1 - F_2) cos 2(theta_F - theta_sigma)

    (docs/conventions.md §2; :func:`grainview.analysis.fabric.fabric_anisotropy`). Dimensionless.

    Parameters
    ----------
    {data}
    {ax}
    {label}
    {walls}
    {line_kw_colour}

    Returns
    -------
    {returns_axes}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eq. a' (Sec. IV.B) and Fig. 9; docs/conventions.md §2.
    """
    ax = get_axes(ax)
    draw_evolutions(ax, datasets(data, label), lambda ds: fabric_anisotropy(ds, walls=walls),
                    [(None, "a_prime")], **line_kw)
    set_labels(ax, EPS_Q_LABEL, "$a'$")
    return finish(ax, None)


@fill_doc
def plot_partial_fabric_anisotropy(data, ax=None, label=None, walls: bool = False, **line_kw):
    """Signed anisotropies a'_s and a'_d of the partial fabric tensors against eps_q (paper Fig. 22).

    The partial tensors of simple and double contacts add up, F = F_s + F_d, each normalised by
    the count of all contacts (:func:`grainview.analysis.fabric.fabric_anisotropy` with ``kind``). Two
    lines per sample: s then d; with one sample in the contact kinds' colours
    (:data:`grainview.plot._style.PALETTE`). Dimensionless.

    Parameters
    ----------
    {data}
    {ax}
    {label}
    {walls}
    {line_kw_colour}

    Returns
    -------
    {returns_axes}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eq. fabricsd and Fig. 22; docs/conventions.md §2.
    """
    ax = get_axes(ax)

    def partial(ds):
        return xr.Dataset({kind: fabric_anisotropy(ds, kind, walls)["a_prime"] for kind in ("simple", "double")})

    draw_evolutions(ax, datasets(data, label), partial, [("s", "simple"), ("d", "double")],
                    curve_colours=[PALETTE["simple"], PALETTE["double"]], **line_kw)
    set_labels(ax, EPS_Q_LABEL, "$a'_s$, $a'_d$")
    return finish(ax, None)


@fill_doc
def plot_joint_connectivity(data, ax=None, label=None, time="residual", max_m: int = 6, walls: bool = False,
                            cmap="Greys", colorbar: bool = True):
    """Grey-level map of P(m_s, m_d), averaged over the snapshots ``time`` (paper Fig. 21).

    P(m_s, m_d) is the fraction of (non-rattler) particles with m_s simple and m_d double
    force-bearing contacts (:func:`grainview.analysis.connectivity.joint_connectivity_pdf`). One sample
    per axes; the image's array is P with rows m_d and columns m_s.

    Parameters
    ----------
    {data_one}
    {ax}
    label : str, optional
        Title of the axes for a single dataset (a dict's or list's label otherwise).
    {time_averaged}
    max_m : int, default 6
        The largest m_s and m_d drawn.
    {walls}
    cmap : str or matplotlib.colors.Colormap, default "Greys"
        The colour map.
    colorbar : bool, default True
        Draw a colour bar.

    Returns
    -------
    {returns_axes}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. VI and Fig. 21; docs/conventions.md §7.
    """
    lab, ds = single_dataset(data, label)
    ax = get_axes(ax)
    pdf = time_mean(joint_connectivity_pdf(select_snapshots(ds, time), max_m=max_m, walls=walls)).compute()
    image = values(pdf.transpose("m_d", "m_s"))
    mesh = ax.imshow(image, origin="lower", cmap=cmap, vmin=0,
                     extent=(-0.5, max_m + 0.5, -0.5, max_m + 0.5), interpolation="nearest")
    if colorbar:
        ax.figure.colorbar(mesh, ax=ax, label="$P(m_s, m_d)$")
    set_labels(ax, "$m_s$", "$m_d$")
    return finish(ax, None, title=lab)


__all__ = ["plot_coordination", "plot_persistence", "plot_connectivity_pdf", "plot_orientation_pdf",
           "plot_fabric_anisotropy", "plot_partial_fabric_anisotropy", "plot_joint_connectivity",
           "full_turn"]
