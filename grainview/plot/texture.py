"""Figures of the texture (paper Sec. IV): coordination z and persistence gamma (Fig. 6),
connectivity P(c) (Fig. 7), polar P(theta) (Fig. 8), fabric anisotropy a' (Fig. 9), the grey
map of P(m_s, m_d) (Fig. 21) and the partial anisotropies a'_s, a'_d (Fig. 22).

Distributions (P(c), P(theta), P(m_s, m_d)) are averaged over the snapshots chosen by ``time``
(default ``"residual"``: the residual state; see :func:`grainview.plot._style.select_snapshots`).
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ..connectivity import connectivity_pdf, coordination, joint_connectivity_pdf
from ..fabric import fabric_anisotropy, orientation_pdf
from ._style import (EPS_Q_LABEL, axis_label, datasets, draw_evolutions, finish, get_axes,
                     next_colour, select_snapshots, set_labels, single_dataset, time_mean, units_of,
                     values)


def plot_coordination(data, ax=None, label=None, walls: bool = False, **line_kw):
    """Coordination number z of the force-bearing network (rattlers left out, a double contact
    counted once; docs/conventions.md §7) against eps_q (paper Fig. 6a;
    :func:`grainview.connectivity.coordination`)."""
    ax = get_axes(ax)
    draw_evolutions(ax, datasets(data, label), lambda ds: coordination(ds, walls=walls), [(None, "z")],
                    **line_kw)
    set_labels(ax, EPS_Q_LABEL, "$z$")
    return finish(ax, None)


def plot_persistence(data, ax=None, label=None, reference: int = 0, **line_kw):
    """Fraction gamma of the contacts of snapshot ``reference`` still present, against eps_q
    (paper Fig. 6b, docs/conventions.md §8; :func:`grainview.persistence.persistence`)."""
    from ..persistence import persistence
    ax = get_axes(ax)
    draw_evolutions(ax, datasets(data, label), lambda ds: persistence(ds, reference=reference), [(None, None)],
                    **line_kw)
    set_labels(ax, EPS_Q_LABEL, r"$\gamma$")
    return finish(ax, None)


def plot_connectivity_pdf(data, ax=None, label=None, time="residual", max_c: int = 10, walls: bool = False,
                          **line_kw):
    """P(c), the fraction of (non-rattler) particles with exactly c force-bearing contacts,
    against c, averaged over the snapshots ``time`` (paper Fig. 7;
    :func:`grainview.connectivity.connectivity_pdf`). Markers only, c >= 1 (P(c) is discrete,
    and P(0) = 0 by definition once rattlers are left out); one marker series per sample."""
    ax = get_axes(ax)
    for lab, ds in datasets(data, label):
        pdf = time_mean(connectivity_pdf(select_snapshots(ds, time), max_c=max_c, walls=walls)).sel(c=slice(1, None))
        ax.plot(pdf["c"].values, values(pdf), "o", linestyle="none", color=next_colour(ax), label=lab, **line_kw)
    set_labels(ax, "$c$", "$P(c)$")
    return finish(ax, None)


def plot_orientation_pdf(data, ax=None, label=None, time="residual", bins: int = 36, kind="all",
                         walls: bool = False, **line_kw):
    """Polar plot of the density P(theta) of contact-normal orientations (rad-1), averaged over
    the snapshots ``time`` (paper Fig. 8; :func:`grainview.fabric.orientation_pdf`).

    P is pi-periodic; the curve is drawn over the full turn (P(theta + pi) = P(theta)) and
    closed. Needs polar axes (created when ``ax`` is None)."""
    ax = get_axes(ax, polar=True)
    for lab, ds in datasets(data, label):
        pdf = time_mean(orientation_pdf(select_snapshots(ds, time), bins=bins, kind=kind, walls=walls))
        theta, r = full_turn(pdf["theta"].values, values(pdf))
        ax.plot(theta, r, color=next_colour(ax), label=lab, **line_kw)
    ax.set_xlabel(axis_label(r"$\theta$", "rad"))
    return finish(ax, None, title=axis_label(r"$P(\theta)$", units_of(pdf)))


def full_turn(theta, r):
    """A pi-periodic function sampled on [0, pi) extended to [0, 2 pi] and closed."""
    theta = np.concatenate([theta, theta + np.pi, theta[:1] + 2 * np.pi])
    r = np.concatenate([r, r, r[:1]])
    return theta, r


def plot_fabric_anisotropy(data, ax=None, label=None, walls: bool = False, **line_kw):
    """Signed fabric anisotropy a' = a cos 2(theta_F - theta_sigma) against eps_q (paper
    Fig. 9, docs/conventions.md §2; :func:`grainview.fabric.fabric_anisotropy`)."""
    ax = get_axes(ax)
    draw_evolutions(ax, datasets(data, label), lambda ds: fabric_anisotropy(ds, walls=walls),
                    [(None, "a_prime")], **line_kw)
    set_labels(ax, EPS_Q_LABEL, "$a'$")
    return finish(ax, None)


def plot_partial_fabric_anisotropy(data, ax=None, label=None, walls: bool = False, **line_kw):
    """Signed anisotropies a'_s and a'_d of the partial fabric tensors of simple and double
    contacts (F = F_s + F_d, each normalised by the count of all contacts) against eps_q (paper
    Fig. 22; :func:`grainview.fabric.fabric_anisotropy` with ``kind``). Two lines per sample:
    s then d."""
    ax = get_axes(ax)

    def partial(ds):
        return xr.Dataset({kind: fabric_anisotropy(ds, kind, walls)["a_prime"] for kind in ("simple", "double")})

    draw_evolutions(ax, datasets(data, label), partial, [("s", "simple"), ("d", "double")], **line_kw)
    set_labels(ax, EPS_Q_LABEL, "$a'$")
    return finish(ax, None)


def plot_joint_connectivity(data, ax=None, label=None, time="residual", max_m: int = 6, walls: bool = False,
                            cmap="Greys", colorbar: bool = True):
    """Grey-level map of P(m_s, m_d), the fraction of (non-rattler) particles with m_s simple
    and m_d double force-bearing contacts, averaged over the snapshots ``time`` (paper
    Fig. 21; :func:`grainview.connectivity.joint_connectivity_pdf`). One sample per axes; the
    image's array is P with rows m_d and columns m_s."""
    lab, ds = single_dataset(data, label)
    ax = get_axes(ax)
    pdf = time_mean(joint_connectivity_pdf(select_snapshots(ds, time), max_m=max_m, walls=walls))
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
