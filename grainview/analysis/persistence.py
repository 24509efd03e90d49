"""Contact persistence gamma(t) and the transitions between simple and double contacts
(paper Sec. IV.A Fig. 6b, Sec. VI Fig. 20; docs/conventions.md §8).

A contact is identified by its pair of bodies {i, j}, encoded as the int64 key
``min(i, j) (N + W) + max(i, j)`` (N particles, W walls), so the result does not depend on
the order of the slots or of i and j. Pairs are matched with sorted keys and
``np.searchsorted``, with no loop over contacts.

These quantities couple snapshots, so they are computed rather than left lazy: on a dask-backed
dataset the snapshots are read one time-chunk at a time, carrying the state needed from one
chunk to the next (the reference contacts, the previous snapshot), so a file larger than
memory streams through. The matching of the pairs on plain arrays is
:mod:`grainview.analysis.arrays.persistence`'.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ._lift import with_attrs
from .contacts import check_near, n_particles, near_attr, selection, snapshot_index
from ..contract.errors import ParameterError
from ._docs import fill_doc
from .arrays.persistence import pair_keys, pair_transitions, pooled_counts, reference_found

__all__ = ["body_count", "pair_keys", "pooled_contacts", "time_blocks", "persistence", "type_transitions"]

@fill_doc
def body_count(ds: xr.Dataset) -> int:
    """N + W: particles plus walls, the stride of the pair keys.

    W is the larger of the size of the ``wall`` dimension and the attribute ``n_walls``.

    Parameters
    ----------
    {ds_short}

    Returns
    -------
    int
        N + W.
    """
    n_walls = max(ds.sizes.get("wall", 0), int(ds.attrs.get("n_walls", 0) or 0))
    return n_particles(ds) + n_walls


@fill_doc
def time_blocks(ds: xr.Dataset):
    """Slices of ``time`` following the dataset's dask chunks (one slice when eager).

    Parameters
    ----------
    {ds_short}

    Yields
    ------
    slice
        Consecutive slices of snapshot indices covering ``time``.
    """
    chunks = ds["fn"].chunksizes.get("time") if ds["fn"].chunks is not None else None
    sizes = chunks or (ds.sizes["time"],)
    start = 0
    for size in sizes:
        yield slice(start, start + size)
        start += size


def _blocks(ds, walls, near, start=0, force=False):
    """Yield ``(block slice, keys (T, C) int64, present (T, C) bool, kind (T, C))`` per time
    block from the block holding snapshot ``start`` on, and ``fn (T, C)`` as a fifth item when
    ``force``; each block is computed on its own."""
    stride = body_count(ds)
    present = selection(ds, walls=walls, near=near)
    small = xr.Dataset({"i": ds["i"], "j": ds["j"], "kind": ds["kind"], "present": present,
                        **({"fn": ds["fn"]} if force else {})})
    small = small.transpose("time", "contact")
    for block in time_blocks(ds):
        if block.stop <= start:
            continue
        values = small.isel(time=block).compute()
        present = values["present"].values
        keys = np.where(present, pair_keys(values["i"].values, values["j"].values, stride), -1)
        if force:
            yield block, keys, present, values["kind"].values, values["fn"].values
        else:
            yield block, keys, present, values["kind"].values


def _check_flag(name, value):
    if not isinstance(value, (bool, np.bool_)):
        raise ParameterError(f"{name}={value!r}: expected True or False")


@fill_doc
def persistence(ds: xr.Dataset, reference: int = 0, uninterrupted: bool = False, walls: bool = False,
                near=None) -> xr.DataArray:
    """gamma(t): fraction of the contacts of the reference snapshot still present at t.

        gamma(t) = |C(ref) & C(t)| / |C(ref)|

    C(t) the set of pairs {i, j} in contact at t (particle–particle unless ``walls``;
    force-bearing, f_n > 0, unless ``near`` adds the pairs within that gap,
    :func:`grainview.analysis.contacts.in_network`). With ``uninterrupted=True`` a contact counts only if
    present at every snapshot from the reference to t. gamma is 1 at the reference and NaN
    before it (and NaN if the reference holds no contact). Computed (not lazy), streaming one
    time-chunk at a time (paper Sec. IV.A, Fig. 6b; docs/conventions.md §8).

    Parameters
    ----------
    {ds}
    reference : int, default 0
        The reference snapshot index (negative counts from the end).
    uninterrupted : bool, default False
        Count a contact only if present at every snapshot from the reference to t.
    {walls}
    {near}

    Returns
    -------
    xarray.DataArray
        ``gamma`` (time,), dimensionless, computed; its attributes record ``reference``,
        ``uninterrupted``, ``walls`` and ``near``.

    Raises
    ------
    grainview.contract.errors.ParameterError
        When ``uninterrupted`` or ``walls`` is not a bool, or ``reference`` not a snapshot index.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. IV.A, Fig. 6b; docs/conventions.md §8.
    """
    _check_flag("uninterrupted", uninterrupted)
    _check_flag("walls", walls)
    check_near(ds, near)
    n_time = ds.sizes["time"]
    reference = snapshot_index(ds, reference, "reference")
    gamma = np.full(n_time, np.nan)
    ref_keys = alive = None
    for block, keys, present, _ in _blocks(ds, walls, near, start=reference):
        first = max(reference - block.start, 0)
        if ref_keys is None:
            ref_row = first
            ref_keys = np.unique(keys[ref_row][present[ref_row]])
            alive = np.ones(ref_keys.size, bool)
        if ref_keys.size == 0:
            break
        found = reference_found(ref_keys, keys[first:], present[first:])
        if uninterrupted:
            found = np.logical_and.accumulate(found & alive, axis=0)
            alive = found[-1].copy()
        gamma[block.start + first:block.stop] = found.sum(axis=1) / ref_keys.size
    da = xr.DataArray(gamma, dims="time", coords={"time": ds["time"].values})
    return with_attrs(da, "gamma", "1", "fraction of persistent contacts gamma",
                      reference=reference, uninterrupted=int(uninterrupted), walls=int(walls),
                      near=near_attr(near))


@fill_doc
def type_transitions(ds: xr.Dataset, walls: bool = False, near=None) -> xr.Dataset:
    """Cumulative fractions Delta gamma_{s->d}(t) and Delta gamma_{d->s}(t) of contacts that changed type.

    Definition used here (the paper gives none in formula): for each pair of consecutive
    snapshots (t-1, t),

        g_{s->d}(t) = #{pairs {i, j} in contact at t-1 and at t, simple at t-1, double at t}
                      / N_c(t-1),

    N_c(t-1) the number of contacts at t-1 (particle–particle unless ``walls``; force-bearing
    unless ``near`` adds near pairs, :func:`grainview.analysis.contacts.in_network`); likewise
    g_{d->s}. Then

        Delta gamma(t) = sum_{t' <= t} g(t'),

    with Delta gamma(0) = 0 (a step from a snapshot without contacts adds 0). Computed (not
    lazy), streaming one time-chunk at a time with the last snapshot of each chunk carried over
    to the next (paper Sec. VI, Fig. 20; docs/conventions.md §8).

    Parameters
    ----------
    {ds}
    {walls}
    {near}

    Returns
    -------
    xarray.Dataset
        ``delta_gamma_s_to_d`` and ``delta_gamma_d_to_s`` (time,), dimensionless, computed.

    Raises
    ------
    grainview.contract.errors.ParameterError
        When ``walls`` is not a bool.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. VI, Fig. 20; docs/conventions.md §8.
    """
    _check_flag("walls", walls)
    check_near(ds, near)
    stride = body_count(ds)
    n_time = ds.sizes["time"]
    s_to_d = np.zeros(n_time)
    d_to_s = np.zeros(n_time)
    carry = None
    for block, keys, present, kind in _blocks(ds, walls, near):
        if carry is None:  # the first snapshot has no predecessor
            carry = (keys[:1], kind[:1], present[:1])
            keys, kind, present, start = keys[1:], kind[1:], present[1:], block.start + 1
        else:
            start = block.start
        prev_keys = np.concatenate([carry[0], keys[:-1]])
        prev_kind = np.concatenate([carry[1], kind[:-1]])
        prev_present = np.concatenate([carry[2], present[:-1]])
        if keys.shape[0]:
            n_sd, n_ds, n_prev = pair_transitions(prev_keys, prev_kind, prev_present, keys, kind, present, stride)
            with np.errstate(invalid="ignore", divide="ignore"):
                s_to_d[start:block.stop] = np.where(n_prev > 0, n_sd / np.maximum(n_prev, 1), 0.0)
                d_to_s[start:block.stop] = np.where(n_prev > 0, n_ds / np.maximum(n_prev, 1), 0.0)
            carry = (keys[-1:], kind[-1:], present[-1:])
    coords = {"time": ds["time"].values}
    out = xr.Dataset({
        "delta_gamma_s_to_d": with_attrs(xr.DataArray(np.cumsum(s_to_d), dims="time", coords=coords),
                                         "delta_gamma_s_to_d", "1",
                                         "cumulative fraction of contacts turning simple to double"),
        "delta_gamma_d_to_s": with_attrs(xr.DataArray(np.cumsum(d_to_s), dims="time", coords=coords),
                                         "delta_gamma_d_to_s", "1",
                                         "cumulative fraction of contacts turning double to simple"),
    })
    out.attrs.update(walls=int(walls), near=near_attr(near),
                     comment="increment at t: contacts present at t-1 and t that changed kind, over N_c(t-1)")
    return out


def pooled_contacts(ds: xr.Dataset, walls: bool = False) -> tuple[int, float]:
    """How many different contacts the snapshots of ``ds`` hold, and how many one holds on average.

    A contact is a pair of bodies (:func:`pair_keys`), force-bearing
    (particle–particle unless ``walls``). The ratio of the two counts is how many snapshots'
    worth of independent contacts a distribution pooled over ``ds`` rests on: 1 when every
    snapshot holds the same contacts, the number of snapshots when none is seen twice.

    Parameters
    ----------
    ds : xarray.Dataset
        A dataset of the contract (e.g. its residual snapshots).
    walls : bool, default False
        Count the particle–wall contacts too.

    Returns
    -------
    distinct : int
        The number of different pairs in contact in any snapshot.
    per_snapshot : float
        The mean number of contacts of a snapshot.
    """
    order = ("time", "contact")
    present = np.asarray(selection(ds, walls=walls).transpose(*order).values, bool)
    keys = pair_keys(ds["i"].transpose(*order).values, ds["j"].transpose(*order).values, body_count(ds))
    return pooled_counts(keys, present)
