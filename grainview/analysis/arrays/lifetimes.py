"""Contact lives on plain arrays: the lives followed snapshot by snapshot, their Kaplan–Meier
survival, the strong contacts still strong after a lag (:mod:`grainview.analysis.lifetimes`
streams the snapshots through them; the definitions are there).

The open lives are a dict of arrays (:data:`LIFE_FIELDS`), one entry per life, sorted by key;
a snapshot's contacts are its present slots' pair keys
(:func:`grainview.analysis.arrays.persistence.pair_keys`), kinds and normal forces.
"""

from __future__ import annotations

import numpy as np

from ...contract.errors import ParameterError

__all__ = ["LIFE_FIELDS", "no_lives", "advance_lives", "all_lives", "kaplan_meier", "survival_on", "median_lifetime",
           "strong_pairs", "count_still_strong"]

LIFE_FIELDS = ("key", "birth", "kind_at_birth", "last_kind", "switches", "sum_fn", "max_fn", "count", "birth_fn")
"""What a life records, one array each, one entry per life: the pair's key, its birth (snapshot
index), its kind at birth and last, the kind switches, the sum and largest of its normal force,
its snapshots, its normal force at birth."""


def no_lives():
    """No life yet: every field of :data:`LIFE_FIELDS`, empty."""
    return {"key": np.empty(0, np.int64), "birth": np.empty(0, np.int64), "kind_at_birth": np.empty(0, np.int8),
            "last_kind": np.empty(0, np.int8), "switches": np.empty(0, np.int64), "sum_fn": np.empty(0),
            "max_fn": np.empty(0), "count": np.empty(0, np.int64), "birth_fn": np.empty(0)}


def _take(state, mask):
    """Every field of ``state`` at ``mask``."""
    return {name: values[mask] for name, values in state.items()}


def advance_lives(lives, t, keys, kind, fn):
    """The open lives after snapshot ``t`` whose contacts are ``keys``, ``kind``, ``fn`` (one per
    present slot): one sort and one ``np.searchsorted`` against the open lives.

    Returns the open lives (those continued, updated, and those born at t) and the lives that
    ended at t, with their ``death`` (t), or None when none did.
    """
    k, kd, f = keys, kind.astype(np.int8), fn
    k, first = np.unique(k, return_index=True)  # the contract stores a pair once per snapshot
    kd, f = kd[first], f[first]
    if lives["key"].size:
        position = np.minimum(np.searchsorted(lives["key"], k), lives["key"].size - 1)
        found = lives["key"][position] == k
    else:
        position, found = np.zeros(k.size, np.int64), np.zeros(k.size, bool)
    alive = np.zeros(lives["key"].size, bool)
    alive[position[found]] = True
    ended = {**_take(lives, ~alive), "death": np.full((~alive).sum(), t, np.int64)} if (~alive).any() else None
    index = position[found]
    lives["switches"][index] += lives["last_kind"][index] != kd[found]
    lives["last_kind"][index] = kd[found]
    lives["sum_fn"][index] += f[found]
    lives["max_fn"][index] = np.maximum(lives["max_fn"][index], f[found])
    lives["count"][index] += 1
    born = ~found
    new = {"key": k[born], "birth": np.full(born.sum(), t, np.int64), "kind_at_birth": kd[born],
           "last_kind": kd[born], "switches": np.zeros(born.sum(), np.int64), "sum_fn": f[born].astype(float),
           "max_fn": f[born].astype(float), "count": np.ones(born.sum(), np.int64),
           "birth_fn": f[born].astype(float)}
    kept = _take(lives, alive)
    merged = {name: np.concatenate([kept[name], new[name]]) for name in LIFE_FIELDS}
    order = np.argsort(merged["key"], kind="stable")
    return _take(merged, order), ended


def all_lives(lives, ended):
    """Every life, one array per field and ``death`` (-1: right-censored), the ended ones (a list
    of :func:`advance_lives`' second results) first, then the still open ``lives``."""
    ended = [*ended, {**lives, "death": np.full(lives["key"].size, -1, np.int64)}]  # right-censored
    return {name: np.concatenate([e[name] for e in ended]) for name in (*LIFE_FIELDS, "death")}


def kaplan_meier(durations, observed):
    """Kaplan–Meier survival S(u) at the distinct observed durations u.

        S(u) = prod_{v <= u} (1 - d_v/n_v)

    (u, S(u)) at the distinct durations u of ``durations`` whose ``observed`` flag is True
    (False = right-censored); d_v the deaths at v and n_v the durations of at least v (at risk).

    Parameters
    ----------
    durations : array_like of float
        Observed durations (a death's lifetime, or a censored life's duration so far).
    observed : array_like of bool
        True where the duration ends in a death, False where it is right-censored.

    Returns
    -------
    u : numpy.ndarray
        The distinct durations that end in a death, increasing.
    survival : numpy.ndarray
        S(u) at each of them; every life still counts as at risk up to its own duration,
        censored or not.

    Raises
    ------
    grainview.contract.errors.ParameterError
        When ``durations`` and ``observed`` differ in shape.
    """
    durations = np.asarray(durations, dtype=float)
    observed = np.asarray(observed, dtype=bool)
    if durations.shape != observed.shape:
        raise ParameterError("durations and observed must have the same length")
    u = np.unique(durations[observed])
    ordered = np.sort(durations)
    at_risk = ordered.size - np.searchsorted(ordered, u, side="left")
    deaths = np.searchsorted(np.sort(durations[observed]), u, side="right") - np.searchsorted(
        np.sort(durations[observed]), u, side="left")
    return u, np.cumprod(1.0 - deaths / at_risk)


def survival_on(grid, durations, observed):
    """The Kaplan–Meier survival of ``durations`` (:func:`kaplan_meier`) as a step function on
    ``grid``: S at the last death at or before each grid value, 1 before the first."""
    u, s = kaplan_meier(durations, observed)
    step = np.searchsorted(u, grid, side="right") - 1  # last event time <= tau
    return np.where(step >= 0, s[np.maximum(step, 0)] if s.size else 1.0, 1.0)


def median_lifetime(durations, observed):
    """The duration at which the Kaplan–Meier survival first drops to 1/2 or below; NaN when it
    never does."""
    u, s = kaplan_meier(durations, observed)
    below = np.flatnonzero(s <= 0.5)
    return u[below[0]] if below.size else np.nan


def strong_pairs(keys, fn, strong):
    """The sorted distinct keys of a snapshot's contacts carrying more than ``strong`` times its
    mean normal force (``keys``, ``fn`` one per present slot)."""
    return np.unique(keys[fn > strong * fn.mean()]) if fn.size else np.empty(0, np.int64)


def count_still_strong(sets, window, kept, total):
    """Add to ``kept[lag]`` how many of the strong pairs ``lag`` snapshots back (``window``, the
    last snapshots' :func:`strong_pairs`, oldest first) are strong in ``sets``, and to
    ``total[lag]`` how many there were (lag 0: ``sets`` itself), in place."""
    total[0] += sets.size
    kept[0] += sets.size
    for lag, earlier in enumerate(reversed(window), start=1):
        total[lag] += earlier.size
        kept[lag] += np.isin(earlier, sets, assume_unique=True).sum()
