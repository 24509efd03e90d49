"""Which contact slots hold contacts, and which of them to use.

A snapshot's contacts occupy the first ``contact_count[time]`` slots of the ``contact``
dimension (docs/schema.md). Every analysis starts from :func:`selection`: the occupied slots
that are contacts of the packing — force-bearing ones by default, or also the near (open)
pairs within a gap threshold (``near=``) when the file holds them — optionally restricted to
particle–particle contacts (``walls=False``) or to one contact kind. All results are lazy when
the dataset is.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ..contract.errors import ParameterError
from ..contract.schema import KIND_DOUBLE, KIND_SIMPLE
from ..contract.validation import occupied
from ._docs import fill_doc

__all__ = ["n_particles", "snapshot_index", "occupied", "is_wall_contact", "kind_code",
           "check_near", "in_network", "near_attr", "selection"]

KINDS = {"all": None, "simple": KIND_SIMPLE, "double": KIND_DOUBLE, "s": KIND_SIMPLE, "d": KIND_DOUBLE}


@fill_doc
def n_particles(ds: xr.Dataset) -> int:
    """Number of particles N (walls are bodies N, N+1, ...).

    Parameters
    ----------
    {ds_short}

    Returns
    -------
    int
        N, the size of the ``particle`` dimension.
    """
    return ds.sizes["particle"]


@fill_doc
def snapshot_index(ds: xr.Dataset, value, name: str = "time") -> int:
    """``value`` as a snapshot index in [0, T) (negative counts from the end).

    One clear line naming the argument ``name`` when it is not an integer in [-T, T).

    Parameters
    ----------
    {ds_short}
    value : int
        A snapshot index in [-T, T), T the number of snapshots.
    name : str, default "time"
        The argument's name, for the error message.

    Returns
    -------
    int
        The index in [0, T).

    Raises
    ------
    grainview.contract.errors.ParameterError
        When ``value`` is not an integer in [-T, T).
    """
    n = ds.sizes["time"]
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not -n <= value < n:
        raise ParameterError(f"{name}={value!r}: expected a snapshot index in [{-n}, {n})")
    return int(value) % n


@fill_doc
def is_wall_contact(ds: xr.Dataset) -> xr.DataArray:
    """Boolean (time, contact): True where body j is a wall (j >= N).

    Parameters
    ----------
    {ds}

    Returns
    -------
    xarray.DataArray
        Boolean (time, contact); lazy on dask input.
    """
    return ds["j"] >= n_particles(ds)


def kind_code(kind) -> int | None:
    """Normalise a ``kind`` argument ("all", "simple", "double", 1, 2) to a code or None.

    Parameters
    ----------
    kind : {"all", "simple", "double", "s", "d", 1, 2} or None
        The contact kind: all (None or "all"), simple (vertex–edge and disk contacts; "simple",
        "s" or 1) or double (edge–edge; "double", "d" or 2).

    Returns
    -------
    int or None
        1 (simple), 2 (double) or None (all).

    Raises
    ------
    grainview.contract.errors.ParameterError
        For any other value.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. II.A and Fig. 1 (simple and double contacts); docs/conventions.md §0.
    """
    if kind in (None, "all"):
        return None
    if isinstance(kind, str):
        if kind not in KINDS:
            raise ParameterError(f"kind={kind!r}: expected 'all', 'simple' or 'double'")
        return KINDS[kind]
    if kind in (KIND_SIMPLE, KIND_DOUBLE):
        return int(kind)
    raise ParameterError(f"kind={kind!r}: expected 'all', 'simple' or 'double'")


@fill_doc
def check_near(ds: xr.Dataset, near) -> float | None:
    """Validate the ``near`` argument of the analyses (see :func:`in_network`).

    Parameters
    ----------
    {ds_short}
    near : float or None
        None, a gap threshold >= 0 in m, or ``np.inf``.

    Returns
    -------
    float or None
        ``near`` as a float, or None.

    Raises
    ------
    grainview.contract.errors.ParameterError
        When ``near`` is not None or a number >= 0; when a finite ``near`` is asked of a file
        without the variable ``gap`` or without near pairs (attribute ``near_contacts_m``); when
        ``near`` exceeds the gap up to which the file holds them (docs/analysis.md, "Near
        contacts").
    """
    if near is None:
        return None
    if isinstance(near, bool) or not isinstance(near, (int, float, np.integer, np.floating)) or np.isnan(near) \
            or near < 0:
        raise ParameterError(f"near={near!r}: expected None (force-bearing contacts only) or a gap "
                             "threshold >= 0 in m (np.inf: every pair the file holds)")
    near = float(near)
    if np.isinf(near):
        return near
    if "gap" not in ds:
        raise ParameterError(f"near={near!r}: the dataset has no 'gap' variable, so open pairs cannot be told "
                             "apart; write the run with near contacts (solver: near_contacts=True, "
                             "grainview run --near-contacts)")
    held = ds.attrs.get("near_contacts_m")
    if held is None or (isinstance(held, str) and held == "none"):
        raise ParameterError(f"near={near!r}: this file holds force-bearing contacts only (no open pairs); "
                             "write the run with near contacts (solver: near_contacts=True, "
                             "grainview run --near-contacts)")
    if near > float(held) * (1 + 1e-9):
        raise ParameterError(f"near={near!r} m exceeds the gap up to which this file holds open pairs "
                             f"(near_contacts_m = {float(held):g} m)")
    return near


@fill_doc
def in_network(ds: xr.Dataset, near=None) -> xr.DataArray:
    """Boolean (time, contact): the slots counted as contacts of the packing.

    ``near=None`` (default): the force-bearing contacts, f_n > 0 — the paper's contact network
    (Sec. IV: "the force-bearing network"). ``near=g`` (m): also the open or unloaded pairs
    whose gap (variable ``gap``, the smallest separation of the pair's points, negative when
    they overlap) is <= g, as a code that keeps every pair within its alert distance as a
    contact counts them (docs/analysis.md, "Near contacts"); ``near=np.inf``: every pair the
    file holds. Combine with :func:`occupied`.

    Parameters
    ----------
    {ds}
    near : float, optional
        None, a gap threshold g >= 0 in m (at most the file's ``near_contacts_m``), or
        ``np.inf`` (:func:`check_near`).

    Returns
    -------
    xarray.DataArray
        Boolean (time, contact); lazy on dask input.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. IV (the force-bearing network); docs/conventions.md §7.
    """
    near = check_near(ds, near)
    loaded = ds["fn"] > 0
    if near is None:
        return loaded
    if np.isinf(near):
        return xr.ones_like(loaded)
    return loaded | (ds["gap"] <= near)


def near_attr(near) -> str | float:
    """The ``near`` argument as a netCDF-friendly attribute value ("none" or the gap in m).

    Parameters
    ----------
    near : float or None
        The ``near`` argument of an analysis.

    Returns
    -------
    str or float
        "none" for None, else ``float(near)`` (m).
    """
    return "none" if near is None else float(near)


@fill_doc
def selection(ds: xr.Dataset, *, walls: bool = False, kind="all", near=None) -> xr.DataArray:
    """Boolean (time, contact) mask of the contacts an analysis uses.

    The occupied slots (:func:`occupied`) that are contacts of the network
    (:func:`in_network`), optionally restricted to particle–particle contacts and to one kind.

    Parameters
    ----------
    {ds}
    walls : bool, default False
        Include particle–wall contacts (default: particle–particle only).
    kind : {"all", "simple", "double"}, default "all"
        "all", "simple" (vertex–edge and disk contacts) or "double" (edge–edge)
        (:func:`kind_code`).
    near : float, optional
        None (default) for the force-bearing contacts (f_n > 0); a gap threshold in m to
        count also the pairs with gap <= near (:func:`in_network`).

    Returns
    -------
    xarray.DataArray
        Boolean (time, contact); lazy on dask input.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. II.A (simple and double contacts) and Sec. IV (the force-bearing network);
    docs/analysis.md, "Which contacts".
    """
    mask = occupied(ds) & in_network(ds, near)
    if not walls:
        mask = mask & ~is_wall_contact(ds)
    code = kind_code(kind)
    if code is not None:
        mask = mask & (ds["kind"] == code)
    return mask
