"""Per-particle fields of every snapshot, for connectivity maps (docs/analysis.md).

For each snapshot and particle (``time``, ``particle``), lazily like the input:

* ``c``: force-bearing contacts (a double contact counts once; walls with ``walls=True``);
* ``m_s``, ``m_d``: of which simple and double (paper Sec. VI, Fig. 21);
* ``strong``: contacts carrying more than the snapshot's mean normal force <f_n> (Sec. V);
* ``rattler``: c < ``min_contacts`` (the rattler rule of z and P(c), docs/conventions.md §7);
* ``rotation`` (rad) and ``displacement`` (m): the particle's rotation and the length of its
  displacement since the ``reference`` snapshot (followed across a periodic cell's boundary,
  :func:`unwrapped_positions`).
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ._lift import with_attrs
from .connectivity import _check_min, counts_of
from .contacts import selection, snapshot_index
from ._docs import fill_doc
from .arrays.periodic import unwrapped_trajectory

__all__ = ["particle_fields", "unwrapped_positions"]


@fill_doc
def particle_fields(ds: xr.Dataset, reference: int = 0, walls: bool = True, near=None,
                    min_contacts: int = 1) -> xr.Dataset:
    """The per-particle fields of every snapshot as a Dataset (time, particle).

    For each snapshot and particle, lazily like the input:

    * ``c``: force-bearing contacts (a double contact counts once; walls with ``walls=True``);
    * ``m_s``, ``m_d``: of which simple and double (paper Sec. VI, Fig. 21);
    * ``strong``: contacts carrying more than the snapshot's mean normal force <f_n> (Sec. V);
    * ``rattler``: c < ``min_contacts`` (the rattler rule of z and P(c), docs/conventions.md §7);
    * ``rotation`` (rad) and ``displacement`` (m): the particle's rotation and the length of its
      displacement since the ``reference`` snapshot. In a periodic cell whose centres are
      stored wrapped (``cell_positions = "wrapped"``) a particle that crosses the boundary
      jumps by a cell: the displacement then adds up the minimum images of the steps between
      consecutive snapshots (:func:`unwrapped_positions`), right while no particle moves half
      a cell between two snapshots.

    Parameters
    ----------
    {ds}
    reference : int, default 0
        Snapshot index the rotation and displacement are measured from (negative counts from
        the end).
    walls : bool, default True
        Include the particle–wall contacts; ``False`` leaves them out.
    {near}
    min_contacts : int, default 1
        A particle with fewer contacts c is a rattler.

    Returns
    -------
    xarray.Dataset
        ``c``, ``m_s``, ``m_d``, ``strong`` (counts), ``rattler`` (boolean), ``rotation`` (rad)
        and ``displacement`` (m) over (time, particle); the attributes record ``reference``,
        ``walls`` and ``min_contacts``.

    Raises
    ------
    grainview.contract.errors.ParameterError
        When ``min_contacts`` is not an integer >= 1, or ``reference`` not a snapshot index.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. IV.A (connectivity and rattlers), Sec. V (strong contacts) and Sec. VI, Fig. 21
    (m_s, m_d); docs/conventions.md §7.
    """
    _check_min(min_contacts)
    reference = snapshot_index(ds, reference, "reference")
    network = selection(ds, walls=walls, near=near)
    mean_fn = ds["fn"].where(network).mean("contact")
    c = counts_of(ds, network)
    out = xr.Dataset({
        "c": with_attrs(c, "c", "1", "force-bearing contacts of the particle"),
        "m_s": with_attrs(counts_of(ds, selection(ds, walls=walls, kind="simple", near=near)), "m_s", "1",
                          "simple contacts of the particle"),
        "m_d": with_attrs(counts_of(ds, selection(ds, walls=walls, kind="double", near=near)), "m_d", "1",
                          "double contacts of the particle"),
        "strong": with_attrs(counts_of(ds, network & (ds["fn"] > mean_fn)), "strong", "1",
                             "contacts of the particle carrying more than the mean normal force"),
        "rattler": with_attrs(c < min_contacts, "rattler", "1", f"fewer than {min_contacts} contacts"),
    })
    start = ds.isel(time=reference)
    out["rotation"] = with_attrs(ds["angle"] - start["angle"], "rotation", "rad",
                                 "rotation since the reference snapshot")
    step = _unwrapped(ds) - _unwrapped(ds).isel(time=reference) if _wrapped_cell(ds) else \
        ds["position"] - start["position"]
    out["displacement"] = with_attrs(np.hypot(step.isel(xy=0, drop=True), step.isel(xy=1, drop=True)),
                                     "displacement", "m", "displacement since the reference snapshot")
    out = out.drop_vars([v for v in out.coords if v not in ("time", "particle")])
    out.attrs.update(reference=reference, walls=int(walls), min_contacts=min_contacts)
    return out.transpose("time", "particle")


def _wrapped_cell(ds: xr.Dataset) -> bool:
    return "cell" in ds.variables and ds.attrs.get("cell_positions", "wrapped") == "wrapped"


def _unwrapped(ds: xr.Dataset) -> xr.DataArray:
    return unwrapped_positions(ds)


@fill_doc
def unwrapped_positions(ds: xr.Dataset) -> xr.DataArray:
    """The particles' centres followed across a periodic cell's boundary (time, particle, xy), m.

        u_0 = x_0,    u_k = u_(k-1) + minimum_image(x_k - u_(k-1))

    in the cell of snapshot k with its tilt made continuous across flips
    (:func:`grainview.analysis.arrays.periodic.unwrapped_trajectory`): ``u_k = x_k + m a + n b_k``
    with the whole cells (m, n) the particle has crossed, so that in a sheared cell an image
    across the top or bottom edge keeps moving with the tilt. Exact as long as no particle moves
    half a cell between two snapshots. A file without a cell, or whose centres are stored
    unwrapped, gives its ``position`` as it is.

    Parameters
    ----------
    {ds}

    Returns
    -------
    xarray.DataArray
        ``position`` (time, particle, xy), m; lazy on dask input (one task over the snapshots:
        each snapshot follows from the one before).
    """
    if not _wrapped_cell(ds):
        return ds["position"]
    position = ds["position"]
    periodic = np.asarray(ds["periodic"].values, bool)
    out = xr.apply_ufunc(unwrapped_trajectory, position, ds["cell"],
                         input_core_dims=[["time", "particle", "xy"], ["time", "cell_vector", "xy"]],
                         output_core_dims=[["time", "particle", "xy"]], kwargs={"periodic": periodic},
                         dask="parallelized", output_dtypes=[float], dask_gufunc_kwargs={"allow_rechunk": True})
    return out.transpose(*position.dims).rename("position").assign_attrs(position.attrs)
