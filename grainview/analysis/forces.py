"""Force anisotropies (paper Sec. V.A, Eqs. fnft, HnHt, anat, qa; docs/conventions.md §3 and "Signs").

``a_n`` and ``a_t`` are signed like a': multiplied by cos 2(theta - theta_sigma), theta being
the major direction of H^(n) (resp. H^(t)) and theta_sigma the major principal stress
direction, so that (a' + a_n + a_t)/2 predicts q/p whatever the directions.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ._lift import apply, ratio, with_attrs
from .arrays import forces as _forces
from .arrays.tensors import principal
from .contacts import selection
from ..contract.errors import ParameterError
from .fabric import check_bins, reference_direction, fabric_anisotropy, theta_coord
from .snapshots import select_snapshots, time_mean
from .stress import stress_invariants
from ._docs import fill_doc

__all__ = ["angular_force_averages", "angular_profile", "force_tensors", "force_anisotropies", "harmonic_prediction"]


@fill_doc
def angular_force_averages(ds: xr.Dataset, bins: int = 36, kind="all", walls: bool = False, near=None) -> xr.Dataset:
    """<f_n>(theta), <f_t>(theta) (N) and N_c(theta) on ``bins`` sectors of [0, pi) (paper Eq. fnft).

        <f_n>(theta) = (1/N_c(theta)) sum_(c in S(theta)) f_n^c,
        <f_t>(theta) = (1/N_c(theta)) sum_(c in S(theta)) f_t^c,

    S(theta) = [theta - dtheta/2, theta + dtheta/2] with dtheta = pi/bins, N_c(theta) the
    number of selected contacts whose normal falls in it (paper Eq. fnft, Fig. 10); NaN in
    empty sectors. ``near``: which pairs are contacts (:func:`grainview.analysis.contacts.in_network`;
    default force-bearing only).

    Parameters
    ----------
    {ds}
    {bins}
    {kind}
    {walls}
    {near}

    Returns
    -------
    xarray.Dataset
        Over (time, theta): ``fn_mean`` and ``ft_mean`` in N and ``count`` (dimensionless), with
        the sector centres as the coordinate ``theta`` (rad); lazy on dask input.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eq. fnft (Sec. V.A) and Fig. 10; docs/conventions.md §3.
    """
    bins = check_bins(bins)
    mask = selection(ds, walls=walls, kind=kind, near=near)
    fn, ft, count = apply(_forces.angular_averages, ds["fn"], ds["ft"], ds["normal"], mask,
                          output_sizes={"theta": bins}, kwargs={"n_bins": bins})
    return xr.Dataset({
        "fn_mean": with_attrs(fn, "fn_mean", "N", "mean normal force <f_n>(theta)"),
        "ft_mean": with_attrs(ft, "ft_mean", "N", "mean tangential force <f_t>(theta)"),
        "count": with_attrs(count, "count", "1", "number of contacts N_c(theta)"),
    }).assign_coords(theta=theta_coord(bins))


@fill_doc
def force_tensors(ds: xr.Dataset, bins: int = 36, kind="all", walls: bool = False, near=None) -> xr.Dataset:
    """Force tensors H^(n) and H^(t) (time, xy_a, xy_b) in N (docs/conventions.md §3).

        H^(n)_ab = (1/pi) int_0^pi <f_n>(theta) n_a n_b dtheta,
        H^(t)_ab = sym[(1/pi) int_0^pi <f_t>(theta) n_a t_b dtheta],

    with <f_n>(theta), <f_t>(theta) the sector means of :func:`angular_force_averages`, taken
    as constant on each sector while n (x) n and n (x) t are integrated exactly over it; empty
    sectors contribute nothing, and tr H^(n) is the angular mean of <f_n>(theta). H^(t) uses
    n_a t_b, as docs/conventions.md §3 explains (the printed paper writes n_a n_b).

    Parameters
    ----------
    {ds}
    {bins}
    {kind}
    {walls}
    {near}

    Returns
    -------
    xarray.Dataset
        ``H_n`` and ``H_t`` (the symmetric part), (time, xy_a, xy_b) in N; lazy on dask input.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eq. HnHt (Sec. V.A), with the correction of docs/conventions.md §3.
    """
    bins = check_bins(bins)
    mask = selection(ds, walls=walls, kind=kind, near=near)
    h_n, h_t = apply(_forces.force_tensors, ds["fn"], ds["ft"], ds["normal"], mask,
                     kwargs={"n_bins": bins})
    return xr.Dataset({
        "H_n": with_attrs(h_n, "H_n", "N", "normal force tensor H^(n)"),
        "H_t": with_attrs(h_t, "H_t", "N", "tangential force tensor H^(t) (symmetric part)"),
    })


@fill_doc
def force_anisotropies(ds: xr.Dataset, bins: int = 36, kind="all", walls: bool = False,
                       reference="stress", near=None) -> xr.Dataset:
    """Signed normal and tangential force anisotropies a_n, a_t (docs/conventions.md §3).

        a_n = 2 (H^n_1 - H^n_2) / tr H^n,    a_t = 2 (H^t_1 - H^t_2) / tr H^n,

    H^n_1 >= H^n_2 and H^t_1 >= H^t_2 the principal values of the force tensors
    (:func:`force_tensors`), each signed by cos 2(theta - theta'), theta the major direction of
    its tensor (theta_n, theta_t) and theta' the ``reference`` direction (default: major
    principal stress direction), so that (a' + a_n + a_t)/2 predicts q/p whatever the
    directions (docs/conventions.md §3, "Signs"). The unsigned magnitudes are returned too.

    Parameters
    ----------
    {ds}
    {bins}
    {kind}
    {walls}
    reference : "stress", float or xarray.DataArray, default "stress"
        The reference direction theta' of the signs (rad): ``"stress"`` the major principal
        stress direction of the whole sample, a fixed angle in rad, or a DataArray over time
        (:func:`grainview.analysis.fabric.reference_direction`).
    {near}

    Returns
    -------
    xarray.Dataset
        Over ``time``: ``a_n``, ``a_t`` (signed), ``a_n_magnitude``, ``a_t_magnitude``
        (dimensionless) and ``theta_n``, ``theta_t`` (rad); lazy on dask input.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eq. anat (Sec. V.A) and Fig. 11, with the normalisation of docs/conventions.md §3.
    """
    h = force_tensors(ds, bins, kind, walls, near)
    n1, n2, theta_n = apply(principal, h["H_n"])
    t1, t2, theta_t = apply(principal, h["H_t"])
    trace = n1 + n2
    ref = reference_direction(ds, reference)
    a_n = ratio(2 * (n1 - n2), trace)
    a_t = ratio(2 * (t1 - t2), trace)
    return xr.Dataset({
        "a_n": with_attrs(a_n * np.cos(2 * (theta_n - ref)), "a_n", "1", "signed normal force anisotropy a_n"),
        "a_t": with_attrs(a_t * np.cos(2 * (theta_t - ref)), "a_t", "1", "signed tangential force anisotropy a_t"),
        "a_n_magnitude": with_attrs(a_n, "a_n_magnitude", "1", "normal force anisotropy |a_n|"),
        "a_t_magnitude": with_attrs(a_t, "a_t_magnitude", "1", "tangential force anisotropy |a_t|"),
        "theta_n": with_attrs(theta_n, "theta_n", "rad", "major direction of H^(n)"),
        "theta_t": with_attrs(theta_t, "theta_t", "rad", "major direction of H^(t)"),
    })


@fill_doc
def harmonic_prediction(ds: xr.Dataset, bins: int = 36, walls: bool = False, near=None) -> xr.Dataset:
    """q/p and its harmonic predictions (paper Eq. qa, Fig. 12; docs/conventions.md §3).

    ``prediction`` is the paper's first-order form

        q/p ~ (a' + a_n + a_t)/2.

    ``prediction_cross_term`` keeps the one cross product that survives the angular
    integration of the harmonic model: with P(theta) = [1 + a cos 2 theta]/pi and
    <f_n>(theta) = <f>[1 + a_n cos 2 theta], the mean stress is p ~ (1 + a a_n / 2), so

        q/p = (a' + a_n + a_t) / (2 + a' a_n),

    exact for the harmonic model with coaxial directions and equal branch lengths; the two
    forms differ by the factor 1 + a' a_n / 2 (a few percent for the paper's anisotropies,
    about 1.15 when a' and a_n are near 0.55).

    The anisotropies use the contacts selected by ``walls`` (default particle–particle);
    q/p is the stress of the whole sample (wall contacts included). ``near``: which pairs are
    contacts of the anisotropies (:func:`grainview.analysis.contacts.in_network`).

    Parameters
    ----------
    {ds}
    {bins}
    {walls}
    {near}

    Returns
    -------
    xarray.Dataset
        Over ``time``, all dimensionless: ``q_over_p``, ``prediction``,
        ``prediction_cross_term`` and the signed anisotropies ``a_prime``, ``a_n``, ``a_t``
        they are made of; lazy on dask input.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eq. qa (Sec. V.A) and Fig. 12; docs/conventions.md §3, "The cross term".
    """
    fab = fabric_anisotropy(ds, walls=walls, near=near)
    frc = force_anisotropies(ds, bins, walls=walls, near=near)
    total = fab["a_prime"] + frc["a_n"] + frc["a_t"]
    cross = ratio(total, 2 + fab["a_prime"] * frc["a_n"])
    return xr.Dataset({
        "q_over_p": stress_invariants(ds)["q_over_p"],
        "prediction": with_attrs(total / 2, "prediction", "1", "harmonic prediction (a' + a_n + a_t)/2"),
        "prediction_cross_term": with_attrs(cross, "prediction_cross_term", "1",
                                            "harmonic prediction with the cross term (a' + a_n + a_t)/(2 + a' a_n)"),
        "a_prime": fab["a_prime"], "a_n": frc["a_n"], "a_t": frc["a_t"],
    })


@fill_doc
def angular_profile(ds: xr.Dataset, component: str = "fn", time="residual", bins: int = 36, kind="all",
                    walls: bool = False, normalise: bool = True) -> xr.DataArray:
    """<f_n>(theta) or <f_t>(theta) on ``bins`` sectors of [0, pi), averaged over the snapshots ``time``.

    ``component="fn"`` gives <f_n>(theta), ``"ft"`` gives <f_t>(theta)
    (:func:`angular_force_averages`, paper Eq. fnft). With ``normalise`` each snapshot's profile
    is divided by that snapshot's mean normal force

        <f_n> = sum_k N_c(theta_k) <f_n>(theta_k) / sum_k N_c(theta_k)

    over the same contacts (dimensionless); otherwise in N. The snapshots' profiles are then
    averaged (NaN-aware: a sector empty in one snapshot does not void the others).

    Parameters
    ----------
    {ds_short}
    component : {"fn", "ft"}, default "fn"
        The normal or the tangential force.
    {time_averaged}
    {bins}
    {kind}
    {walls}
    normalise : bool, default True
        Divide each snapshot's profile by its mean normal force <f_n> over the same contacts
        (dimensionless); otherwise in N.

    Returns
    -------
    xarray.DataArray
        The profile over ``theta`` (rad); dimensionless with ``normalise``, else N. Lazy on
        dask input (``time="residual"`` reads the boxes to find the window).

    Raises
    ------
    grainview.contract.errors.ParameterError
        When ``component`` is neither "fn" nor "ft".

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eq. fnft (Sec. V.A) and Fig. 10; docs/conventions.md §3.
    """
    if component not in ("fn", "ft"):
        raise ParameterError(f"component={component!r}: expected 'fn' or 'ft'")
    avg = angular_force_averages(select_snapshots(ds, time), bins=bins, kind=kind, walls=walls)
    profile = avg[f"{component}_mean"]
    if normalise:
        count = avg["count"]
        mean_fn = ratio((avg["fn_mean"].fillna(0) * count).sum("theta"), count.sum("theta"))
        profile = ratio(profile, mean_fn).assign_attrs(units="1", long_name=profile.attrs["long_name"] + " / <f_n>")
    return time_mean(profile)

