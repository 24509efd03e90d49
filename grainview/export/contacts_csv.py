"""Snapshots as CSV, for pandas and spreadsheets.

``contacts.csv``: the tidy contact table of every exported snapshot
(:func:`grainview.analysis.tables.contacts_table`), one row per occupied contact slot, its columns
named with their units (:data:`CSV_COLUMNS`, docs/analysis.md "Exports"): ``snapshot``,
``time_s``, ``i``, ``j``, ``kind`` ("simple" or "double"), ``wall``, ``loaded`` (f_n > 0:
the force-bearing contacts; False for the pairs without force, such as the near pairs of a
file written with them), ``fn_N``, ``ft_N``, ``normal_x``, ``normal_y``, ``point_x_m``,
``point_y_m``, ``branch_x_m``, ``branch_y_m`` and ``gap_m`` (when the file has gaps).

The file is written to a temporary name and moved into place, so that an interrupted export
never leaves a half-written file under the final name; an existing file is not overwritten
unless ``overwrite``.
"""

from __future__ import annotations

import os

import xarray as xr

from ..analysis.snapshots import snapshot_indices
from ..contract.errors import ParameterError
from ..contract.writer import write_atomically
from ._docs import fill_doc

__all__ = ["write_csv", "CSV_COLUMNS", "KIND_NAMES"]

CSV_COLUMNS = {
    "snapshot": "index of the snapshot along time",
    "time_s": "time of the snapshot (s)",
    "i": "first body (particle index)",
    "j": "second body (particle index, or N + wall index for a wall)",
    "kind": "simple (one contact point) or double (two points: an edge facing an edge)",
    "wall": "True when j is a wall",
    "loaded": "True when f_n > 0 (the force-bearing network); False for a pair without force, e.g. a near pair",
    "fn_N": "normal force exerted by i on j, compression > 0 (N)",
    "ft_N": "tangential force exerted by i on j along t = (-n_y, n_x) (N)",
    "normal_x": "unit contact normal from i to j, x component",
    "normal_y": "unit contact normal from i to j, y component",
    "point_x_m": "application point of the contact force, x (m)",
    "point_y_m": "application point of the contact force, y (m)",
    "branch_x_m": "branch vector, centre of i to centre of j (to the contact point for walls), x (m)",
    "branch_y_m": "branch vector, y (m)",
    "gap_m": "smallest separation of the contact's points along the normal, negative: overlap (m; files with gaps)",
}
"""The columns of ``contacts.csv``, in order, and what each holds (units in the names)."""
KIND_NAMES = {1: "simple", 2: "double"}
"""The contract's contact kinds as the CSV writes them."""

_CSV_NAMES = {"time": "time_s", "fn": "fn_N", "ft": "ft_N", "point_x": "point_x_m", "point_y": "point_y_m",
              "branch_x": "branch_x_m", "branch_y": "branch_y_m", "gap": "gap_m"}


CSV_BLOCK_SLOTS = 200_000
"""Contact slots read at once by :func:`write_csv`: the snapshots of a block are read together
(one read per variable, not one per snapshot) and written as one piece of the table."""

_CSV_VARIABLES = ("contact_count", "i", "j", "kind", "fn", "ft", "normal", "point", "branch", "gap")
"""The variables :func:`grainview.analysis.tables.contacts_table` reads."""


@fill_doc
def write_csv(ds: xr.Dataset, out_dir, every: int = 1, overwrite: bool = False, progress=None) -> str:
    """Write ``contacts.csv``: the tidy contact table of every ``every``-th snapshot.

    The table is :func:`grainview.analysis.tables.contacts_table`'s, with columns ``snapshot`` and
    ``time_s`` first, the units in the column names, ``kind`` as "simple" or "double" and a
    column ``loaded`` (f_n > 0) that tells the force-bearing contacts from the pairs without
    force (:data:`CSV_COLUMNS`). The snapshots are read in blocks of about
    :data:`CSV_BLOCK_SLOTS` contact slots and the table is written block by block, so that
    neither the reading nor the table's memory grows with the number of snapshots.

    Parameters
    ----------
    {written}
    overwrite : bool, default False
        Replace an existing ``contacts.csv``.
    progress : bool, optional
        Show a progress bar over the snapshots (default: none).

    Returns
    -------
    str
        The path of ``contacts.csv``.

    Raises
    ------
    grainview.contract.errors.ParameterError
        When ``contacts.csv`` exists and ``overwrite`` is False.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eqs. 1-2 and Sec. II.A (the contact frame, simple and double contacts);
    docs/conventions.md §0.
    """
    import pandas as pd

    from ..analysis.tables import contacts_table

    indices = snapshot_indices(ds, every)
    path = os.path.join(out_dir, "contacts.csv")
    if os.path.exists(path) and not overwrite:
        raise ParameterError(f"{path} exists; pass overwrite=True to replace it")
    os.makedirs(out_dir, exist_ok=True)
    names = [name for name in _CSV_VARIABLES if name in ds]
    keep = [name for name in ("radius",) if name in ds]  # the particle count, for the wall column
    per_block = max(1, CSV_BLOCK_SLOTS // max(1, ds.sizes.get("contact", 1)))
    kinds = {code: name for code, name in KIND_NAMES.items()}

    def table_of(block, k, local):
        table = contacts_table(block, time=local)
        table.insert(0, "time", table.attrs["time"])
        table.insert(0, "snapshot", int(k))
        table.insert(table.columns.get_loc("fn"), "loaded", table["fn"] > 0)
        codes = table["kind"].to_numpy()
        table["kind"] = [kinds.get(int(code), str(int(code))) for code in codes] if len(codes) else codes
        return table.rename(columns=_CSV_NAMES)

    def write(temporary):
        bar = None
        if progress:
            from tqdm.auto import tqdm

            bar = tqdm(total=len(indices), desc="CSV export", unit="snapshot")
        try:
            with open(temporary, "w", newline="") as stream:
                if not len(indices):
                    pd.DataFrame(columns=[c for c in CSV_COLUMNS if c != "gap_m" or "gap" in ds]).to_csv(
                        stream, index=False)
                for start in range(0, len(indices), per_block):
                    chosen = indices[start:start + per_block]
                    block = ds[names + keep].isel(time=chosen).load()
                    frames = [table_of(block, k, local) for local, k in enumerate(chosen)]
                    pd.concat(frames, ignore_index=True).to_csv(stream, index=False, header=start == 0)
                    if bar is not None:
                        bar.update(len(chosen))
        finally:
            if bar is not None:
                bar.close()

    write_atomically(path, overwrite, write)
    return path
