"""Figures of force transmission (paper Sec. V and VI): polar <f_n>(theta), <f_t>(theta)
(Fig. 10), force anisotropies a_n, a_t (Fig. 11), normal-force pdfs with the exponential fit of
the strong forces (Fig. 14), the xi-network's q(xi)/p and a'(xi) (Figs. 15, 16), the proportions
k_s, k_d, f_s, f_d (Fig. 19), the s->d and d->s transitions (Fig. 20), pdfs per contact kind
(Fig. 23) and the strong/weak proportions k_s^S, k_s^W, k_d^S, k_d^W (Fig. 25).

Distributions are averaged over the snapshots chosen by ``time`` (default ``"residual"``, see
:func:`grainview.analysis.snapshots.select_snapshots`); evolutions are drawn against eps_q.
"""

from __future__ import annotations

import numpy as np

from ..contract.errors import ParameterError
from ..analysis.force_pdf import counting_error, pooled_force_pdf, strong_force_exponent, strong_force_prefactor
from ..analysis.forces import angular_profile, force_anisotropies
from ..analysis.xi_network import xi_profile
from ._docs import fill_doc
from ._style import (EPS_Q_LABEL, PALETTE, PI_TICK_LABELS, axis_label, datasets, draw_evolutions, finish, get_axes,
                     legend_in_first, new_figure, sample_colour, series_label, set_labels, tidy_polar, units_of,
                     values)
from .texture import full_turn

FORCE_RATIO_LABEL = r"$f_n/\langle f_n\rangle$"
XI_LABEL = r"$\xi$"


# -- Fig. 10: angular averages -----------------------------------------------------------------

@fill_doc
def plot_normal_force_polar(data, ax=None, label=None, time="residual", bins: int = 36, kind="all",
                            walls: bool = False, normalise: bool = True, **line_kw):
    """Polar plot of the angle-averaged normal force <f_n>(theta) (paper Fig. 10a).

    Divided by <f_n> unless ``normalise=False`` (then N) (:func:`grainview.analysis.forces.angular_profile`). Drawn over
    the full turn (pi-periodic).

    Parameters
    ----------
    {data}
    {ax_polar}
    {label}
    {time_averaged}
    {bins}
    {kind}
    {walls}
    {normalise}
    {line_kw}

    Returns
    -------
    {returns_axes}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eq. fnft (Sec. V.A) and Fig. 10a; docs/conventions.md §3.
    """
    return _polar(data, ax, label, "fn", r"\langle f_n\rangle(\theta)", time, bins, kind, walls, normalise,
                  line_kw)


@fill_doc
def plot_tangential_force_polar(data, ax=None, label=None, time="residual", bins: int = 36, kind="all",
                                walls: bool = False, normalise: bool = True, **line_kw):
    """Polar plot of the magnitude |<f_t>(theta)| of the angle-averaged tangential force (paper Fig. 10b).

    Divided by <f_n> unless ``normalise=False`` (then N) (:func:`grainview.analysis.forces.angular_profile`). A polar
    radius cannot be negative: the sign of <f_t>(theta), that of -sin 2(theta - theta_t), is
    dropped.

    Parameters
    ----------
    {data}
    {ax_polar}
    {label}
    {time_averaged}
    {bins}
    {kind}
    {walls}
    {normalise}
    {line_kw}

    Returns
    -------
    {returns_axes}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eq. fnft (Sec. V.A) and Fig. 10b; docs/conventions.md §3.
    """
    return _polar(data, ax, label, "ft", r"|\langle f_t\rangle(\theta)|", time, bins, kind, walls, normalise,
                  line_kw)


def _polar(data, ax, label, component, symbol, time, bins, kind, walls, normalise, line_kw):
    ax = get_axes(ax, polar=True)
    for lab, ds in datasets(data, label):
        profile = angular_profile(ds, component, time, bins, kind, walls, normalise).compute()
        r = values(profile)
        r = np.abs(r) if component == "ft" else r
        theta, r = full_turn(profile["theta"].values, r)
        ax.plot(theta, r, color=sample_colour(ax, lab, ds), label=lab, **line_kw)
    tidy_polar(ax)
    ax.set_xlabel(axis_label(r"$\theta$", "rad"))
    title = "$" + symbol + (r"/\langle f_n\rangle" if normalise else "") + "$"
    return finish(ax, None, title=axis_label(title, units_of(profile)))


@fill_doc
def plot_tangential_force(data, ax=None, label=None, time="residual", bins: int = 36, kind="all",
                          walls: bool = False, normalise: bool = True, **line_kw):
    """The angle-averaged tangential force <f_t>(theta), with its sign, against theta (paper Fig. 10b).

    theta in [0, pi). Harmonic form (docs/conventions.md §3):

        <f_t>(theta) = -<f> a_t sin 2(theta - theta_t)

    Divided by <f_n> unless ``normalise=False`` (then N) (:func:`grainview.analysis.forces.angular_profile`). Cartesian
    axes: a polar radius could not show the sign.

    Parameters
    ----------
    {data}
    {ax}
    {label}
    {time_averaged}
    {bins}
    {kind}
    {walls}
    {normalise}
    {line_kw}

    Returns
    -------
    {returns_axes}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eq. fnft (Sec. V.A) and Fig. 10b; docs/conventions.md §3.
    """
    return _cartesian_profile(data, ax, label, "ft", time, bins, kind, walls, normalise, line_kw)


@fill_doc
def plot_normal_force(data, ax=None, label=None, time="residual", bins: int = 36, kind="all",
                      walls: bool = False, normalise: bool = True, **line_kw):
    """The angle-averaged normal force <f_n>(theta) against theta on Cartesian axes (paper Fig. 10a).

    theta in [0, pi). Harmonic form (docs/conventions.md §3):

        <f_n>(theta) = <f> (1 + a_n cos 2(theta - theta_n))

    Divided by <f_n> unless ``normalise=False`` (then N) (:func:`grainview.analysis.forces.angular_profile`); a grey line
    marks the mean (1, or nothing when not normalised). The paper draws it in polar axes
    (:func:`plot_normal_force_polar`); these axes share theta and the scale with
    :func:`plot_tangential_force`, so that a_n and a_t compare by eye (Fig. 10 of the report).

    Parameters
    ----------
    {data}
    {ax}
    {label}
    {time_averaged}
    {bins}
    {kind}
    {walls}
    {normalise}
    {line_kw}

    Returns
    -------
    {returns_axes}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eq. fnft (Sec. V.A) and Fig. 10a; docs/conventions.md §3.
    """
    return _cartesian_profile(data, ax, label, "fn", time, bins, kind, walls, normalise, line_kw)


HALF_TURN_TICKS = np.arange(5) * np.pi / 4
"""Ticks of a theta axis over [0, pi], labelled as the polar figures' (multiples of pi/4)."""


def _cartesian_profile(data, ax, label, component, time, bins, kind, walls, normalise, line_kw):
    """<f_n>(theta) or <f_t>(theta) against theta in [0, pi] with pi/4 ticks; a grey line at
    the mean (<f_n>: 1 when normalised) or at zero (<f_t>)."""
    ax = get_axes(ax)
    for lab, ds in datasets(data, label):
        profile = angular_profile(ds, component, time, bins, kind, walls, normalise).compute()
        ax.plot(profile["theta"].values, values(profile), "o-", markersize=3, color=sample_colour(ax, lab, ds),
                label=lab, **line_kw)
    if component == "ft" or normalise:
        ax.axhline(0.0 if component == "ft" else 1.0, color="0.6", linewidth=0.8, zorder=0)
    ax.set_xlim(0.0, np.pi)
    ax.set_xticks(HALF_TURN_TICKS, PI_TICK_LABELS[:5])
    name = "f_t" if component == "ft" else "f_n"
    symbol = rf"$\langle {name}\rangle(\theta)" + (r"/\langle f_n\rangle$" if normalise else "$")
    set_labels(ax, axis_label(r"$\theta$", "rad"), axis_label(symbol, units_of(profile)))
    return finish(ax, None)


@fill_doc
def plot_angular_forces(data, label=None, **kw):
    """Figure of paper Fig. 10: (a) <f_n>(theta) and (b) <f_t>(theta) with its sign, against theta.

    Panels drawn by :func:`plot_normal_force` and :func:`plot_tangential_force`, on Cartesian
    axes with the same theta ticks (multiples of pi/4) and y ranges of one length, so that the
    two panels read on one scale (the paper draws polar plots: a polar radius cannot carry the
    sign of <f_t>, and its radial labels sit on the curves). One legend, in (a).

    Parameters
    ----------
    {data}
    {label}
    {panel_kw}

    Returns
    -------
    {returns_panels}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eq. fnft (Sec. V.A) and Fig. 10; docs/conventions.md §3.
    """
    fig, (ax_n, ax_t) = new_figure(2)
    plot_normal_force(data, ax_n, label, **kw)
    plot_tangential_force(data, ax_t, label, **kw)
    same_scale(ax_n, ax_t)
    if ax_t.get_legend() is not None:  # one legend, in (a)
        ax_t.get_legend().remove()
    return fig


def same_scale(*axes) -> None:
    """Give ``axes`` y ranges of one length, each centred on its own data, so that equal
    heights mean equal values from one panel to the next (a_n against a_t in Fig. 10)."""
    limits = [ax.get_ylim() for ax in axes]
    span = max(hi - lo for lo, hi in limits)
    for ax, (lo, hi) in zip(axes, limits):
        middle = 0.5 * (lo + hi)
        ax.set_ylim(middle - span / 2, middle + span / 2)


# -- Fig. 11: force anisotropies ---------------------------------------------------------------

@fill_doc
def plot_force_anisotropy(data, ax=None, label=None, component: str = "a_n", bins: int = 36,
                          walls: bool = False, **line_kw):
    """Signed force anisotropy a_n or a_t against eps_q (paper Fig. 11).

        a_n = 2 (H^n_1 - H^n_2) / tr H^n,    a_t = 2 (H^t_1 - H^t_2) / tr H^n,

    signed by cos 2(theta - theta_sigma) (docs/conventions.md §3 and "Signs";
    :func:`grainview.analysis.forces.force_anisotropies`). Dimensionless.

    Parameters
    ----------
    {data}
    {ax}
    {label}
    component : {"a_n", "a_t"}, default "a_n"
        The anisotropy drawn.
    {bins}
    {walls}
    {line_kw_colour}

    Returns
    -------
    {returns_axes}

    Raises
    ------
    grainview.contract.errors.ParameterError
        When ``component`` is neither "a_n" nor "a_t".

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eq. anat (Sec. V.A) and Fig. 11; docs/conventions.md §3.
    """
    if component not in ("a_n", "a_t"):
        raise ParameterError(f"component={component!r}: expected 'a_n' or 'a_t'")
    ax = get_axes(ax)
    draw_evolutions(ax, datasets(data, label), lambda ds: force_anisotropies(ds, bins, walls=walls),
                    [(None, component)], **line_kw)
    set_labels(ax, EPS_Q_LABEL, f"${component}$")
    return finish(ax, None)


@fill_doc
def plot_force_anisotropies(data, label=None, **kw):
    """Figure of paper Fig. 11: (a) a_n and (b) a_t against eps_q.

    Panels drawn by :func:`plot_force_anisotropy`.

    Parameters
    ----------
    {data}
    {label}
    {panel_kw}

    Returns
    -------
    {returns_panels}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eq. anat (Sec. V.A) and Fig. 11; docs/conventions.md §3.
    """
    fig, (ax_n, ax_t) = new_figure(2)
    plot_force_anisotropy(data, ax_n, label, "a_n", **kw)
    plot_force_anisotropy(data, ax_t, label, "a_t", **kw)
    return fig


# -- Figs. 14 and 23: force pdfs ---------------------------------------------------------------

SCALES = {"log-linear": "linear", "log-log": "log"}
"""The figures' scales and the bins of :func:`grainview.analysis.force_pdf.pooled_force_pdf` each draws."""


def _pdf(ds, scale, time, bins, range, kind, walls):
    """The pooled pdf a figure draws (:func:`grainview.analysis.force_pdf.pooled_force_pdf` over
    the snapshots ``time``): linear bins on [0, 6] by default for ``"log-linear"``, log bins for
    ``"log-log"``."""
    if scale not in SCALES:
        raise ParameterError(f"scale={scale!r}: expected 'log-linear' or 'log-log'")
    if range is None and scale == "log-linear":
        range = (0.0, 6.0)
    return pooled_force_pdf(ds, bins=bins, scale=SCALES[scale], range=range, kind=kind, walls=walls,
                            time=time).compute()


@fill_doc
def plot_force_pdf(data, ax=None, label=None, scale: str = "log-linear", time="residual", bins: int = 40,
                   range=None, kind="all", walls: bool = False, fit: bool = True, **line_kw):
    """Pdf P of the normal forces f_n/<f_n> (paper Fig. 14), log-linear or log-log.

    ``scale="log-linear"``: linear bins on [0, 6] by default; ``"log-log"``: logarithmic bins.
    With ``fit`` (log-linear only) a dashed line

        P = A exp(-alpha f_n/<f_n>)

    over the strong forces (f_n > <f_n>) is drawn after each sample's pdf, alpha from
    :func:`grainview.analysis.force_pdf.strong_force_exponent` given in the legend, over the range of
    the data. Empty bins are not drawn; each bin carries its counting error bar, P / sqrt(n) for
    n contacts in it (:func:`grainview.analysis.force_pdf.counting_error`; upper bar only for n = 1). Lines per sample: the
    pdf, then the fit when drawn.

    Parameters
    ----------
    {data}
    {ax}
    {label}
    scale : {"log-linear", "log-log"}, default "log-linear"
        Linear bins (on [0, 6] by default) on a logarithmic P axis, or logarithmic bins on
        log-log axes.
    {time_averaged}
    bins : int, default 40
        Number of bins.
    range : (float, float), optional
        (low, high) of f_n/<f_n>; default (0, 6) for ``"log-linear"`` and the default of
        :func:`grainview.analysis.force_pdf.pooled_force_pdf` for ``"log-log"``.
    {kind}
    {walls}
    fit : bool, default True
        Draw the exponential fit of the strong forces (log-linear only).
    {line_kw}

    Returns
    -------
    {returns_axes}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eq. strong (Sec. V.B) and Fig. 14.
    """
    ax = get_axes(ax)
    outside = []
    for lab, ds in datasets(data, label):
        pdf = _pdf(ds, scale, time, bins, range, kind, walls)
        _draw_pdf(ax, pdf, lab, sample_colour(ax, lab, ds), line_kw)
        outside.append((lab, pdf))
        if fit and scale == "log-linear":
            alpha = float(strong_force_exponent(pdf))
            _draw_fit(ax, pdf, alpha, lab, ax.lines[-1].get_color())
    _pdf_axes(ax, scale)
    _outside_note(ax, outside)
    return finish(ax, None)


def _draw_pdf(ax, pdf, label, colour, line_kw, style="o-"):
    """The non-empty bins with their counting error bars (:func:`grainview.analysis.force_pdf.counting_error`); a bin of a
    single contact, whose lower bar would reach zero on the log axis, gets its upper bar only."""
    x = np.asarray(pdf["f_over_mean"].values, float)
    p = values(pdf["pdf"])
    keep = p > 0
    error = values(counting_error(pdf))[keep]
    lower = np.where(error < 0.999 * p[keep], error, 0.0)
    ax.errorbar(x[keep], p[keep], yerr=np.vstack([lower, error]), fmt="none", ecolor=colour, elinewidth=0.7,
                capsize=0)
    ax.plot(x[keep], p[keep], style, markersize=3, color=colour, label=label, **line_kw)


def _draw_fit(ax, pdf, alpha, label, colour):
    """The exponential fit over the strong forces, drawn from f_n = <f_n> to the last bin that
    holds contacts (never beyond the data)."""
    prefactor = float(strong_force_prefactor(pdf, alpha))
    x = np.asarray(pdf["f_over_mean"].values, float)
    held = x[values(pdf["pdf"]) > 0]
    x = x[(x > 1.0) & (x <= (held.max() if held.size else -np.inf))]
    ax.plot(x, prefactor * np.exp(-alpha * x), "--", color=colour, linewidth=1,
            label=series_label(label, rf"$\exp(-{alpha:.2f}\, f_n/\langle f_n\rangle)$"))


def _pdf_axes(ax, scale):
    ax.set_yscale("log")
    if scale == "log-log":
        ax.set_xscale("log")
    set_labels(ax, FORCE_RATIO_LABEL, "$P$")


@fill_doc
def plot_force_pdfs(data, label=None, **kw):
    """Figure of paper Fig. 14: (a) log-linear and (b) log-log pdfs of f_n/<f_n>.

    Panels drawn by :func:`plot_force_pdf`.

    Parameters
    ----------
    {data}
    {label}
    {panel_kw}

    Returns
    -------
    {returns_panels}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eq. strong (Sec. V.B) and Fig. 14.
    """
    fig, (ax_lin, ax_log) = new_figure(2)
    plot_force_pdf(data, ax_lin, label, scale="log-linear", **kw)
    plot_force_pdf(data, ax_log, label, scale="log-log", **kw)
    legend_in_first([ax_lin, ax_log])  # inside (a), where the pdf falls away: both panels as wide
    return fig


@fill_doc
def plot_force_pdf_by_kind(data, ax=None, label=None, scale: str = "log-linear", time="residual",
                           bins: int = 40, range=None, walls: bool = False, **line_kw):
    """Pdfs of f_n/<f_n> for simple (s, solid) and double (d, dashed) contacts (paper Fig. 23).

    Each pdf is normalised over its own contacts (:func:`grainview.analysis.force_pdf.pooled_force_pdf`
    with ``kind``). Two lines per sample: s then d; with one sample in the contact kinds'
    colours (:data:`grainview.plot._style.PALETTE`), with several in the sample's colour.

    Parameters
    ----------
    {data}
    {ax}
    {label}
    scale : {"log-linear", "log-log"}, default "log-linear"
        Linear bins (on [0, 6] by default) on a logarithmic P axis, or logarithmic bins on
        log-log axes.
    {time_averaged}
    bins : int, default 40
        Number of bins.
    range : (float, float), optional
        (low, high) of f_n/<f_n>; default (0, 6) for ``"log-linear"`` and the default of
        :func:`grainview.analysis.force_pdf.pooled_force_pdf` for ``"log-log"``.
    {walls}
    {line_kw}

    Returns
    -------
    {returns_axes}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. V.B and Fig. 23.
    """
    ax = get_axes(ax)
    outside = []
    pairs = datasets(data, label)
    for lab, ds in pairs:
        colour = sample_colour(ax, lab, ds)
        for kind, name, style in (("simple", "s", "o-"), ("double", "d", "s--")):
            pdf = _pdf(ds, scale, time, bins, range, kind, walls)
            # one sample: the contact kinds' colours; several: the sample's, the kind by style
            _draw_pdf(ax, pdf, series_label(lab, name), PALETTE[kind] if len(pairs) == 1 else colour, line_kw,
                      style)
            outside.append((series_label(lab, name), pdf))
    _pdf_axes(ax, scale)
    ax.set_ylabel("$P$ (each kind normalised to 1)")
    _outside_note(ax, outside)
    return finish(ax, None)


def _outside_note(ax, pdfs):
    """Say in the panel which share of the contacts lies outside its force range (a pdf's
    ``outside_fraction``; e.g. the forces below the log axis's first bin), per curve."""
    notes = [f"{100 * float(pdf['outside_fraction']):.2g}%" + (f" ({lab})" if lab else "")
             for lab, pdf in pdfs if "outside_fraction" in pdf and float(pdf["outside_fraction"]) > 0]
    if notes:  # one line per curve, so that the note stays inside the frame
        edges = pdfs[0][1]["bin_edges"].values
        ax.text(0.03, 0.03, "\n".join([f"outside {edges[0]:g}-{edges[-1]:g} " + r"$\langle f_n\rangle$:", *notes]),
                transform=ax.transAxes, fontsize="x-small", va="bottom", ha="left", color="0.3")


@fill_doc
def plot_force_pdfs_by_kind(data, label=None, **kw):
    """Figure of paper Fig. 23: pdfs per contact kind, (a) log-linear and (b) log-log.

    Panels drawn by :func:`plot_force_pdf_by_kind`.

    Parameters
    ----------
    {data}
    {label}
    {panel_kw}

    Returns
    -------
    {returns_panels}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. V.B and Fig. 23.
    """
    fig, (ax_lin, ax_log) = new_figure(2)
    plot_force_pdf_by_kind(data, ax_lin, label, scale="log-linear", **kw)
    plot_force_pdf_by_kind(data, ax_log, label, scale="log-log", **kw)
    legend_in_first([ax_lin, ax_log])
    return fig


# -- Figs. 15, 16: the xi-network --------------------------------------------------------------

@fill_doc
def plot_xi_stress(data, ax=None, label=None, xi=None, time="residual", min_contacts: float = 10, **line_kw):
    """Partial shear stress q(xi)/p of the contacts f_n < xi <f_n> against the cutoff xi (paper Fig. 15).

    q(xi) is divided by the p of the whole sample (docs/conventions.md §5; :func:`grainview.analysis.xi_network.xi_profile`).
    Cutoffs whose network holds fewer than ``min_contacts`` contacts per snapshot on average
    are not drawn. Dimensionless.

    Parameters
    ----------
    {data}
    {ax}
    {label}
    xi : array_like of float, optional
        The cutoffs xi >= 0, multiples of <f_n> (default: those of
        :func:`grainview.analysis.xi_network.xi_network`).
    {time_averaged}
    min_contacts : float, default 10
        Cutoffs whose network holds fewer contacts per snapshot on average are not drawn.
    {line_kw}

    Returns
    -------
    {returns_axes}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. V.C and Fig. 15; docs/conventions.md §5.
    """
    return _xi(data, ax, label, xi, time, "q_over_p", r"$q(\xi)/p$", min_contacts, line_kw)


@fill_doc
def plot_xi_anisotropy(data, ax=None, label=None, xi=None, time="residual", min_contacts: float = 10,
                       near=None, log: bool = False, **line_kw):
    """Partial fabric anisotropy a'(xi) of the contacts f_n < xi <f_n> against the cutoff xi (paper Fig. 16).

    a'(xi) is signed against the whole sample's major stress direction (docs/conventions.md §5;
    :func:`grainview.analysis.xi_network.xi_profile`). Cutoffs whose network holds fewer than ``min_contacts`` contacts per
    snapshot on average are not drawn: the anisotropy of a handful of contacts is noise (it
    spans [-2, 2]). Dimensionless.

    Parameters
    ----------
    {data}
    {ax}
    {label}
    xi : array_like of float, optional
        The cutoffs xi >= 0, multiples of <f_n> (default: those of
        :func:`grainview.analysis.xi_network.xi_network`).
    {time_averaged}
    min_contacts : float, default 10
        Cutoffs whose network holds fewer contacts per snapshot on average are not drawn.
    near : float, optional
        None: the force-bearing contacts (f_n > 0); a gap in m: also the pairs within it
        (:func:`grainview.analysis.xi_network.xi_profile`). The report counts the near pairs when the files hold them.
    log : bool, default False
        A logarithmic xi axis (the paper's inset: the very weak forces).
    {line_kw}

    Returns
    -------
    {returns_axes}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. V.C and Fig. 16; docs/conventions.md §5.
    """
    ax = _xi(data, ax, label, xi, time, "a_prime", r"$a'(\xi)$", min_contacts, line_kw, near)
    ax.axhline(0.0, color="0.6", linewidth=0.8, zorder=0)  # a' > 0 along the major stress, < 0 across it
    if log:
        ax.set_xscale("log")
    return ax


WEAK_XI = np.geomspace(1e-2, 1.0, 13)
"""The cutoffs of the paper's inset of Fig. 16, the very weak and weak forces, 0.01 to 1."""


@fill_doc
def plot_xi_anisotropies(data, label=None, near=None, **kw):
    """Figure of paper Fig. 16: a'(xi) over the whole range (a) and, on a logarithmic axis,
    for the weak forces, 0.01 <= xi <= 1 (b, the paper's inset).

    Panels drawn by :func:`plot_xi_anisotropy`; (b) is a panel of its own rather than an
    inset, so that it hides no part of (a) and carries its own axis labels.

    Parameters
    ----------
    {data}
    label : str, optional
        Legend label of a single dataset (None: no legend entry).
    near : float, optional
        None: the force-bearing contacts (f_n > 0); a gap in m: also the pairs within it
        (:func:`grainview.analysis.xi_network.xi_profile`).
    **kw
        Keyword arguments of :func:`plot_xi_anisotropy` (``time``, ``min_contacts``, line
        keywords), passed to both panels; ``xi`` applies to (a) only.

    Returns
    -------
    {returns_panels}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. V.C and Fig. 16 (with its inset); docs/conventions.md §5.
    """
    fig, (ax_all, ax_weak) = new_figure(2)
    plot_xi_anisotropy(data, ax_all, label, near=near, **kw)
    kw.pop("xi", None)
    plot_xi_anisotropy(data, ax_weak, label, xi=WEAK_XI, near=near, log=True, **kw)
    if ax_weak.get_legend() is not None:  # one legend, in (a)
        ax_weak.get_legend().remove()
    return fig


def _xi(data, ax, label, xi, time, name, ylabel, min_contacts, line_kw, near=None):
    ax = get_axes(ax)
    for lab, ds in datasets(data, label):
        prof = xi_profile(ds, xi, time, near).compute()
        keep = values(prof["count"]) >= min_contacts
        ax.plot(np.asarray(prof["xi"].values, float)[keep], values(prof[name])[keep], "o-", markersize=3,
                color=sample_colour(ax, lab, ds), label=lab, **line_kw)
    ax.axvline(1.0, color="0.6", linewidth=0.8, linestyle=":", zorder=0)  # xi = 1: the mean force
    set_labels(ax, XI_LABEL, ylabel)
    return finish(ax, None)


# -- Figs. 19, 20, 25: proportions and transitions ---------------------------------------------

@fill_doc
def plot_contact_proportions(data, ax=None, label=None, **line_kw):
    """Proportions k_s, k_d and relative force averages f_s, f_d against eps_q (paper Fig. 19).

        k_s = N_s/N_c,   k_d = N_d/N_c,   f_s = k_s <f_n>_s/<f_n>,   f_d = k_d <f_n>_d/<f_n>

    (docs/conventions.md §4; :func:`grainview.analysis.force_networks.contact_proportions`). Four lines
    per sample: k_s, k_d (solid), f_s, f_d (dashed); with one sample, simple and double in the
    contact kinds' colours (:data:`grainview.plot._style.PALETTE`). Dimensionless.

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
    Sec. VI and Fig. 19 (f_s, f_d with the correction of docs/conventions.md §4).
    """
    from ..analysis.force_networks import contact_proportions
    ax = get_axes(ax)
    curves = [("$k_s$", "k_s"), ("$k_d$", "k_d"), ("$f_s$", "f_s"), ("$f_d$", "f_d")]
    kinds = [PALETTE["simple"], PALETTE["double"]] * 2
    draw_evolutions(ax, datasets(data, label), contact_proportions, curves, curve_colours=kinds,
                    curve_styles=["-", "-", "--", "--"], **line_kw)
    set_labels(ax, EPS_Q_LABEL, "$k$: share of contacts, $f$: share of normal force")
    return finish(ax, None)


@fill_doc
def plot_type_transitions(data, ax=None, label=None, **line_kw):
    """Cumulative proportions Delta gamma of s->d and d->s transitions against eps_q (paper Fig. 20).

    Simple contacts turned double (s->d) and double turned simple (d->s)
    (docs/conventions.md §8; :func:`grainview.analysis.persistence.type_transitions`). Two lines per
    sample. Dimensionless; computed.

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
    Sec. VI and Fig. 20; docs/conventions.md §8.
    """
    from ..analysis.persistence import type_transitions
    ax = get_axes(ax)
    curves = [(r"$s\rightarrow d$", "delta_gamma_s_to_d"), (r"$d\rightarrow s$", "delta_gamma_d_to_s")]
    draw_evolutions(ax, datasets(data, label), type_transitions, curves, **line_kw)
    set_labels(ax, EPS_Q_LABEL, r"$\Delta\gamma$")
    return finish(ax, None)


@fill_doc
def plot_strong_weak_proportion(data, ax=None, label=None, network: str = "strong", **line_kw):
    """Fractions k_s and k_d of the strong or of the weak contacts against eps_q (a panel of paper Fig. 25).

    ``network="strong"``: k_s^S and k_d^S, the fractions of all contacts that are simple and
    strong, double and strong; ``"weak"``: k_s^W and k_d^W. Strong means f_n > <f_n>, weak
    f_n <= <f_n>
    (docs/conventions.md §4; :func:`grainview.analysis.force_networks.contact_proportions`). Two lines
    per sample, s then d; with one sample in the contact kinds' colours
    (:data:`grainview.plot._style.PALETTE`). Dimensionless.

    Parameters
    ----------
    {data}
    {ax}
    {label}
    network : {"strong", "weak"}, default "strong"
        Which network's fractions are drawn.
    {line_kw_colour}

    Returns
    -------
    {returns_axes}

    Raises
    ------
    grainview.contract.errors.ParameterError
        When ``network`` is neither "strong" nor "weak".

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. VI and Fig. 25; docs/conventions.md §4.
    """
    from ..analysis.force_networks import contact_proportions
    if network not in ("strong", "weak"):
        raise ParameterError(f"network={network!r}: expected 'strong' or 'weak'")
    ax = get_axes(ax)
    mark = "S" if network == "strong" else "W"
    curves = [(f"$k_s^{mark}$", f"k_s_{network}"), (f"$k_d^{mark}$", f"k_d_{network}")]
    draw_evolutions(ax, datasets(data, label), contact_proportions, curves,
                    curve_colours=[PALETTE["simple"], PALETTE["double"]], curve_styles=["-", "--"], **line_kw)
    relation = ">" if network == "strong" else r"\leq"
    set_labels(ax, EPS_Q_LABEL, f"share of contacts, {network} ($f_n {relation} " + r"\langle f_n\rangle$)")
    return finish(ax, None)


@fill_doc
def plot_strong_weak_proportions(data, label=None, **kw):
    """Figure of paper Fig. 25: (a) k_s^S and k_d^S, (b) k_s^W and k_d^W against eps_q.

    Panels drawn by :func:`plot_strong_weak_proportion`. The paper compares simple with double
    contacts within each network (k_s^S with k_d^S, k_s^W with k_d^W); one panel per network
    keeps each comparison apart from the curves of the other, which cross it.

    Parameters
    ----------
    {data}
    label : str, optional
        Legend label of a single dataset (None: no legend entry).
    {panel_kw}

    Returns
    -------
    {returns_panels}

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. VI and Fig. 25; docs/conventions.md §4.
    """
    fig, (ax_strong, ax_weak) = new_figure(2)
    for ax, network in ((ax_strong, "strong"), (ax_weak, "weak")):
        plot_strong_weak_proportion(data, ax, label, network, **kw)
        legend_in_first([ax], loc="best")  # inside each panel: both panels as wide
    return fig


__all__ = ["plot_normal_force_polar", "plot_tangential_force_polar", "plot_tangential_force", "plot_angular_forces",
           "plot_force_anisotropy", "plot_force_anisotropies", "plot_force_pdf", "plot_force_pdfs",
           "plot_force_pdf_by_kind", "plot_force_pdfs_by_kind", "plot_xi_stress", "plot_xi_anisotropy",
           "plot_xi_anisotropies", "plot_normal_force", "plot_strong_weak_proportion", "same_scale",
           "plot_contact_proportions", "plot_type_transitions", "plot_strong_weak_proportions"]
