"""Contact lifetimes: every contact followed from birth to death, and its survival curve.

A contact is a pair of bodies {i, j} (particle–particle, and particle–wall with ``walls``)
present in the network (force-bearing, f_n > 0, unless ``near`` adds the pairs within that gap;
:func:`grainview.analysis.contacts.in_network`), identified as in :mod:`grainview.analysis.persistence`. A
*life* is a run of consecutive snapshots b, b+1, ..., d-1 in which the pair is present, with
the pair absent at d: it is born at t_b and dies at t_d, and its lifetime is

    tau = t_d - t_b                   (s; in strain units eps_q(t_d) - eps_q(t_b)).

Lifetimes are resolved only to the snapshot interval: the contact may have formed any time
after t_{b-1} and broken any time before t_d. A pair that breaks and forms again has two lives.
A life still running at the last snapshot is *right-censored* (its lifetime is at least
t_last - t_b); one already present at the first snapshot is *left-censored* (its birth is
unknown).

Survival S(tau), the probability that a contact lives longer than tau, is the Kaplan–Meier
estimate over the lives born within the series (left-censored lives are left out: their
lifetimes are not measured from birth):

    S(tau) = prod_{u <= tau} (1 - d_u / n_u),

u the distinct observed lifetimes, d_u the lives ending with lifetime u and n_u the lives
whose observed duration is at least u (deaths and censored alike: "at risk").

Coupling snapshots, these are computed (not lazy), one time-chunk at a time; the lives are
followed, and their survival estimated, on plain arrays by :mod:`grainview.analysis.arrays.lifetimes`.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ._lift import with_attrs
from .contacts import check_near, n_particles, near_attr
from ..contract.errors import ParameterError
from .persistence import _blocks, _check_flag, body_count
from .strain import strains
from .arrays.lifetimes import (advance_lives, all_lives, count_still_strong, kaplan_meier, median_lifetime, no_lives,
                               strong_pairs, survival_on)

__all__ = ["contact_events", "kaplan_meier", "lifetime_survival", "median_lifetime_by_force", "strong_persistence"]


def _events(ds, walls, near):
    """The lives of every pair as a dict of arrays (one entry per life), scanning snapshots in
    order: per snapshot one sort and one ``np.searchsorted`` against the open lives."""
    lives, ended = no_lives(), []
    for block, keys, present, kind, fn in _blocks(ds, walls, near, force=True):
        for r in range(keys.shape[0]):
            lives, gone = advance_lives(lives, block.start + r, keys[r][present[r]], kind[r][present[r]],
                                        fn[r][present[r]])
            if gone is not None:
                ended.append(gone)
    return all_lives(lives, ended)


def contact_events(ds: xr.Dataset, walls: bool = True, near=None) -> xr.Dataset:
    """Every life of every contact (module docstring), ordered by birth then pair.

    One entry per life along a ``contact_event`` dimension; a life runs from its birth t_b to its
    death t_d and lasts

        tau = t_d - t_b    (s; in strain units eps_q(t_d) - eps_q(t_b)).

    Variables: ``i``, ``j`` (the pair, i < j; j >= N for a wall), ``birth`` and ``death`` (s;
    death NaN when right-censored), ``lifetime`` (s: t_death - t_birth, or the observed
    duration t_last - t_birth when censored), ``censored`` (right), ``left_censored`` (present at
    the first snapshot), ``kind_at_birth`` (1 simple, 2 double), ``kind_switches`` (simple <->
    double changes during the life), ``mean_fn`` and ``max_fn`` (N, over the snapshots of the
    life), ``birth_fn`` (N, the normal force at the first snapshot of the life) and, when the
    file has its box, ``lifetime_eps_q`` (the shear strain eps_q over the life, 1); when it has
    a periodic cell, ``lifetime_gamma`` (the cell's simple-shear strain gamma over the life, 1,
    :func:`grainview.analysis.strain.strains`). A contact is the pair (i, j) whatever boundary
    of a periodic cell it crosses: it keeps its identity when its particles are stored a cell
    apart. Snapshot times must increase. Computed one time-chunk at a time.

    Parameters
    ----------
    ds : xarray.Dataset
        A grainview dataset (eager or chunked along ``time``).
    walls : bool, default True
        Follow particle–wall contacts too (``j >= N``).
    near : float, optional
        Gap threshold (m) adding the unloaded pairs within it to the network
        (:func:`grainview.analysis.contacts.in_network`); None counts force-bearing contacts only.

    Returns
    -------
    xarray.Dataset
        One entry per life along ``contact_event``, with the variables above (times and
        lifetimes in s, forces in N).

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. IV.A (contact persistence) and Sec. V (force classes); docs/analysis.md, "Contact
    lifetimes".
    """
    _check_flag("walls", walls)
    check_near(ds, near)
    times = np.asarray(ds["time"].values, dtype=float)
    if times.size > 1 and not np.all(np.diff(times) > 0):
        raise ParameterError("contact_events needs snapshot times that increase; sort the dataset by time first")
    e = _events(ds, walls, near)
    stride = body_count(ds)
    censored = e["death"] < 0
    last = times.size - 1
    end_index = np.where(censored, last, e["death"])
    order = np.lexsort((e["key"], e["birth"]))
    e = {name: values[order] for name, values in e.items()}
    censored, end_index = censored[order], end_index[order]
    birth_t, end_t = times[e["birth"]], times[end_index]
    dim = "contact_event"
    out = xr.Dataset({
        "i": (dim, e["key"] // stride), "j": (dim, e["key"] % stride),
        "birth": (dim, birth_t), "death": (dim, np.where(censored, np.nan, end_t)),
        "lifetime": (dim, end_t - birth_t), "censored": (dim, censored),
        "left_censored": (dim, e["birth"] == 0), "kind_at_birth": (dim, e["kind_at_birth"]),
        "kind_switches": (dim, e["switches"]),
        "mean_fn": (dim, e["sum_fn"] / np.maximum(e["count"], 1)), "max_fn": (dim, e["max_fn"]),
        "birth_fn": (dim, e["birth_fn"]),
    })
    if "box_min" in ds and "box_max" in ds:
        eps_q = np.asarray(strains(ds)["eps_q"].values, dtype=float)
        out["lifetime_eps_q"] = with_attrs(xr.DataArray(eps_q[end_index] - eps_q[e["birth"]], dims=dim),
                                           "lifetime_eps_q", "1", "shear strain eps_q over the life")
    if "cell" in ds.variables:
        gamma = np.asarray(strains(ds)["gamma"].values, dtype=float)
        out["lifetime_gamma"] = with_attrs(xr.DataArray(gamma[end_index] - gamma[e["birth"]], dims=dim),
                                           "lifetime_gamma", "1", "simple-shear strain gamma of the cell over the life")
    for name, units, long_name in (("birth", "s", "time of the first snapshot of the life"),
                                   ("death", "s", "time of the first snapshot without the contact"),
                                   ("lifetime", "s", "lifetime t_death - t_birth (observed duration if censored)"),
                                   ("mean_fn", "N", "mean normal force over the life"),
                                   ("max_fn", "N", "largest normal force over the life"),
                                   ("birth_fn", "N", "normal force at the first snapshot of the life")):
        out[name] = with_attrs(out[name], name, units, long_name)
    out.attrs.update(walls=int(walls), near=near_attr(near), n_particles=n_particles(ds),
                     comment="lifetimes resolved to the snapshot interval (grainview.analysis.lifetimes)")
    return out


def lifetime_survival(ds: xr.Dataset, walls: bool = True, near=None, by=None, unit: str = "time",
                      force_at: str = "life", very_weak: float = 0.1) -> xr.DataArray:
    """Survival S(tau) of the contacts' lives (Kaplan–Meier, module docstring).

        S(tau) = prod_{u <= tau} (1 - d_u / n_u)

    over the lives born within the series: left-censored lives left out, as a step function on
    the grid of every observed lifetime.

    ``by``: None (all lives), ``"kind"`` (simple / double at birth) or ``"force"``: strong
    (f > <f>), weak (``very_weak`` <f> <= f <= <f>) and very weak (f < ``very_weak`` <f>;
    paper Sec. V), f the mean normal force over the life (``force_at="life"``) or the force at
    birth (``"birth"``) and <f> its mean over all lives; ``unit``: ``"time"`` (tau in s) or
    ``"strain"`` (tau in eps_q) or ``"gamma"`` (tau in a periodic cell's gamma).

    Parameters
    ----------
    ds : xarray.Dataset
        A grainview dataset.
    walls, near
        Which contacts are followed, as in :func:`contact_events`.
    by : {None, "kind", "force"}
        Grouping of the lives.
    unit : {"time", "strain", "gamma"}
        Lifetimes in s, in shear strain eps_q (needs the file's box), or in the simple-shear
        strain gamma of a periodic cell (eps_q does not see a simple shear).
    force_at : {"life", "birth"}
        The force that classifies a life for ``by="force"``.
    very_weak : float, default 0.1
        The very weak threshold, a multiple of <f>.

    Returns
    -------
    xarray.DataArray
        ``survival`` (group, lifetime), dimensionless, a step function on the grid of every
        observed lifetime, with the number of lives per group as the coordinate ``lives``.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. V (strong, weak and very weak forces) and Sec. II.A (simple and double contacts);
    docs/analysis.md, "Contact lifetimes".
    """
    if by not in (None, "kind", "force"):
        raise ParameterError(f"by={by!r}: expected None, 'kind' or 'force'")
    if force_at not in ("life", "birth"):
        raise ParameterError(f"force_at={force_at!r}: expected 'life' or 'birth'")
    if unit not in ("time", "strain", "gamma"):
        raise ParameterError(f"unit={unit!r}: expected 'time', 'strain' or 'gamma'")
    events = contact_events(ds, walls=walls, near=near)
    events = events.isel(contact_event=~events["left_censored"].values)
    column = {"time": "lifetime", "strain": "lifetime_eps_q", "gamma": "lifetime_gamma"}[unit]
    if column not in events:
        raise ParameterError("unit='strain' needs the file's box (box_min, box_max)" if unit == "strain" else
                             "unit='gamma' needs a periodic cell (cell): gamma is the cell's simple-shear strain")
    tau = events[column].values
    observed = ~events["censored"].values
    if by is None:
        groups = {"all": np.ones(tau.size, bool)}
    elif by == "kind":
        groups = {"simple": events["kind_at_birth"].values == 1, "double": events["kind_at_birth"].values == 2}
    else:
        f = events["mean_fn" if force_at == "life" else "birth_fn"].values
        mean = float(f.mean()) if f.size else np.nan
        groups = {"strong": f > mean, "weak": (f >= very_weak * mean) & (f <= mean),
                  "very weak": f < very_weak * mean}
    grid = np.unique(tau[observed])
    survival = np.ones((len(groups), grid.size))
    for row, mask in enumerate(groups.values()):
        survival[row] = survival_on(grid, tau[mask], observed[mask])
    da = xr.DataArray(survival, dims=("group", "lifetime"),
                      coords={"group": list(groups), "lifetime": grid,
                              "lives": ("group", [int(m.sum()) for m in groups.values()])})
    da["lifetime"].attrs.update(units="s" if unit == "time" else "1",
                                long_name="lifetime tau" + {"time": "", "strain": " in shear strain eps_q",
                                                            "gamma": " in the cell's shear strain gamma"}[unit])
    return with_attrs(da, "survival", "1", "Kaplan-Meier survival S(tau) of the contacts' lives",
                      walls=int(walls), near=near_attr(near), by=str(by), unit=unit, force_at=force_at)


def median_lifetime_by_force(ds: xr.Dataset, bins=(0.0, 0.5, 1.0, 1.5, 2.0, np.inf), walls: bool = True,
                             near=None) -> xr.DataArray:
    """Median lifetime (s) of the lives in each bin of mean normal force relative to the mean.

    Do strong contacts live longer? The median lifetime (s) of the lives whose mean normal
    force over the life, over the mean of all lives, falls in each of ``bins``: the tau at which
    the bin's Kaplan–Meier survival first drops to 1/2 or below (censoring handled; NaN when it
    never does). Left-censored lives are left out.

    Parameters
    ----------
    ds : xarray.Dataset
        A grainview dataset.
    bins : sequence of float
        Increasing edges of the bins of mean force / <f>.
    walls, near
        Which contacts are followed, as in :func:`contact_events`.

    Returns
    -------
    xarray.DataArray
        ``median_lifetime`` (force_bin,) in s, with the number of lives per bin as the
        coordinate ``lives``.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. V (forces relative to the mean); docs/analysis.md, "Contact lifetimes".
    """
    bins = np.asarray(bins, dtype=float)
    if bins.ndim != 1 or bins.size < 2 or np.any(np.diff(bins) <= 0):
        raise ParameterError(f"bins={bins.tolist()}: expected increasing edges of at least one bin")
    events = contact_events(ds, walls=walls, near=near)
    events = events.isel(contact_event=~events["left_censored"].values)
    relative = events["mean_fn"].values / (float(events["mean_fn"].mean()) if events.sizes["contact_event"] else 1)
    which = np.digitize(relative, bins) - 1
    medians, counts = [], []
    for b in range(bins.size - 1):
        members = which == b
        medians.append(median_lifetime(events["lifetime"].values[members], ~events["censored"].values[members]))
        counts.append(int(members.sum()))
    labels = [f"{lo:g}-{hi:g}" for lo, hi in zip(bins[:-1], bins[1:])]
    da = xr.DataArray(np.array(medians, float), dims="force_bin",
                      coords={"force_bin": labels, "lives": ("force_bin", counts)})
    return with_attrs(da, "median_lifetime", "s", "median lifetime of the lives whose mean force / <f> is in the bin",
                      walls=int(walls), near=near_attr(near))


def strong_persistence(ds: xr.Dataset, max_lag: int = 20, strong: float = 1.0, walls: bool = False,
                       near=None) -> xr.DataArray:
    """Survival of the strong network: the fraction of strong contacts still strong after a lag.

        P(lag) = sum_t |S(t) & S(t + lag)| / sum_t |S(t)|

    S(t) the contacts strong at t (f_n > ``strong`` <f_n(t)>, paper Sec. V), the sums over every
    t that has a snapshot t + lag (pooled: sum of the kept over sum of the strong), for
    lag = 0 .. ``max_lag`` snapshots. Computed one time-chunk at a time, carrying the strong
    sets of the last ``max_lag`` snapshots.

    Parameters
    ----------
    ds : xarray.Dataset
        A grainview dataset.
    max_lag : int, default 20
        The largest lag, in snapshots (>= 1).
    strong : float, default 1.0
        The strong threshold, a multiple of the snapshot's mean normal force.
    walls, near
        Which contacts count, as in :func:`contact_events`.

    Returns
    -------
    xarray.DataArray
        ``strong_persistence`` (lag,), dimensionless, 1 at lag 0, with the mean time between
        snapshots ``lag`` apart (s) as the coordinate ``lag_time``.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. V (strong and weak networks); docs/analysis.md, "Contact lifetimes".
    """
    from collections import deque

    if isinstance(max_lag, bool) or not isinstance(max_lag, (int, np.integer)) or max_lag < 1:
        raise ParameterError(f"max_lag={max_lag!r}: expected an integer >= 1")
    if not (np.isfinite(strong) and strong > 0):
        raise ParameterError(f"strong={strong!r}: expected a positive multiple of the mean force")
    _check_flag("walls", walls)
    check_near(ds, near)
    kept = np.zeros(max_lag + 1)
    total = np.zeros(max_lag + 1)
    window = deque(maxlen=max_lag)
    for block, keys, present, _, fn in _blocks(ds, walls, near, force=True):
        for r in range(keys.shape[0]):
            sets = strong_pairs(keys[r][present[r]], fn[r][present[r]], strong)
            count_still_strong(sets, window, kept, total)
            window.append(sets)
    times = np.asarray(ds["time"].values, float)
    lag_time = [float(np.mean(times[lag:] - times[:times.size - lag])) if times.size > lag else np.nan
                for lag in range(max_lag + 1)]
    with np.errstate(invalid="ignore", divide="ignore"):
        da = xr.DataArray(kept / total, dims="lag", coords={"lag": np.arange(max_lag + 1), "lag_time": ("lag", lag_time)})
    da["lag_time"].attrs.update(units="s", long_name="mean time between snapshots lag apart")
    return with_attrs(da, "strong_persistence", "1", "fraction of strong contacts still strong after lag snapshots",
                      strong=strong, walls=int(walls), near=near_attr(near))
