"""One snapshot's contacts in the forms other tools take: a tidy table and a sparse graph.

The contract stores contacts in padded slots (``contact`` dimension, empty slots with kind 0),
so a plain ``to_dataframe`` holds many empty rows and splits vectors across a ``xy``
dimension. :func:`contacts_table` gives one row per occupied slot with the vectors as columns;
:func:`contact_graph` the bodies' adjacency weighted by the normal force, as a
``scipy.sparse`` matrix (or a networkx graph, when networkx is installed).
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from .contacts import n_particles, occupied, snapshot_index
from ..contract.errors import ParameterError
from .persistence import body_count

__all__ = ["contacts_table", "contact_graph"]


def _snapshot(ds: xr.Dataset, time: int) -> xr.Dataset:
    snap = ds.isel(time=snapshot_index(ds, time))
    return snap.isel(contact=np.flatnonzero(occupied(snap).values))


def contacts_table(ds: xr.Dataset, time: int = -1):
    """A pandas DataFrame of the occupied contact slots of snapshot ``time``, one row per contact.

    Columns i, j, kind (1 simple, 2 double), wall (j >= N), fn, ft (N), normal_x, normal_y
    (unit, i -> j), point_x, point_y, branch_x, branch_y (m) and gap (m) where the file has it.
    ``time`` is an index (default the last). Units are in ``df.attrs["units"]``.

    Parameters
    ----------
    ds : xarray.Dataset
        A grainview dataset.
    time : int, default -1
        Index of the snapshot along ``time``.

    Returns
    -------
    pandas.DataFrame
        One row per occupied slot (no padding), with ``attrs["units"]`` and ``attrs["time"]``
        (s).

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eqs. 1-2 and Sec. II.A (the contact frame, simple and double contacts);
    docs/conventions.md §0.

    Examples
    --------
    >>> table = ds.grain.contacts_table(time=-1)                  # doctest: +SKIP
    >>> table[table.fn > table.fn.mean()].kind.value_counts()     # doctest: +SKIP
    """
    snap = _snapshot(ds, time)
    columns = {"i": snap["i"].values, "j": snap["j"].values, "kind": snap["kind"].values,
               "wall": snap["j"].values >= n_particles(ds), "fn": snap["fn"].values, "ft": snap["ft"].values}
    units = {"fn": "N", "ft": "N"}
    for name in ("normal", "point", "branch"):
        for axis, label in enumerate(("x", "y")):
            columns[f"{name}_{label}"] = snap[name].values[:, axis]
            units[f"{name}_{label}"] = "1" if name == "normal" else "m"
    if "gap" in snap:
        columns["gap"] = snap["gap"].values
        units["gap"] = "m"
    import pandas as pd

    table = pd.DataFrame(columns)
    table.attrs.update(units=units, time=float(snap["time"].values))
    return table


def contact_graph(ds: xr.Dataset, time: int = -1, as_networkx: bool = False):
    """The force-bearing contact network of snapshot ``time`` as a weighted graph.

    A symmetric (N + W) x (N + W) scipy.sparse CSR matrix of normal forces (N; bodies 0..N-1
    particles, then walls), or with ``as_networkx`` a networkx Graph whose edges carry fn, ft
    and kind. Only contacts with f_n > 0 are edges (the force-bearing network).

    Parameters
    ----------
    ds : xarray.Dataset
        A grainview dataset.
    time : int, default -1
        Index of the snapshot along ``time``.
    as_networkx : bool, default False
        Return a networkx Graph (networkx is an optional dependency).

    Returns
    -------
    scipy.sparse.csr_matrix or networkx.Graph
        The weighted adjacency of the force-bearing network (weights f_n in N).

    Raises
    ------
    grainview.contract.errors.ParameterError
        With ``as_networkx=True`` when networkx is not installed.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. IV (the force-bearing network); docs/conventions.md §7.
    """
    from scipy import sparse

    snap = _snapshot(ds, time)
    loaded = snap["fn"].values > 0
    i, j = snap["i"].values[loaded].astype(np.int64), snap["j"].values[loaded].astype(np.int64)
    fn = snap["fn"].values[loaded]
    size = body_count(ds)
    if as_networkx:
        try:
            import networkx as nx
        except ImportError:
            raise ParameterError("as_networkx=True needs networkx (pip install networkx)") from None
        graph = nx.Graph()
        graph.add_nodes_from(range(size))
        graph.add_edges_from((int(a), int(b), {"fn": float(f), "ft": float(t), "kind": int(k)})
                             for a, b, f, t, k in zip(i, j, fn, snap["ft"].values[loaded], snap["kind"].values[loaded]))
        return graph
    matrix = sparse.coo_matrix((np.concatenate([fn, fn]), (np.concatenate([i, j]), np.concatenate([j, i]))),
                               shape=(size, size))
    return matrix.tocsr()
