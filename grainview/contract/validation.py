"""Checking a dataset against the data contract.

:func:`validate` collects every problem it finds and raises them together as one
:class:`~grainview.contract.errors.SchemaError`. On a dask-backed dataset the value checks are lazy
reductions computed in a single pass over the chunks, so a file larger than memory is checked
without being loaded, and nothing is ever written back.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .cell import CELL_POSITIONS, branch_problems, cell_problems, fractional
from .errors import SchemaError
from .file_checks import (COUNT_OUT_OF_RANGE, NON_FINITE_FORCES, foreign_file_problems, negative_force_problem,
                          order_problems)
from .schema import KIND_DOUBLE, KIND_SIMPLE, VARIABLES, structure_problems, unit_problems
from .shapes import shape_problems
from .schema import missing_units as _missing_units

if TYPE_CHECKING:
    import xarray as xr

UNIT_NORMAL_TOLERANCE = 1e-6
"""Largest accepted | |n| - 1 | for an occupied contact normal."""


def _metadata(ds: xr.Dataset):
    """(variables: name -> (dims, dtype), units: name -> units attribute or None) of ``ds``."""
    variables = {name: (ds[name].dims, ds[name].dtype) for name in ds.variables}
    units = {name: ds[name].attrs.get("units", ds[name].encoding.get("units")) for name in ds.variables}
    return variables, units


def _structure_problems(ds: xr.Dataset) -> list[str]:
    return foreign_file_problems(ds.variables) or structure_problems(_metadata(ds)[0], dict(ds.sizes))


def check_structure(ds: xr.Dataset, source: str | None = None) -> None:
    """Raise :class:`SchemaError` for structural problems only (missing variables, dims,
    dtypes): cheap, reads no data. The analyses call it before computing anything."""
    import xarray as xr

    if not isinstance(ds, xr.Dataset):
        raise SchemaError(f"expected an xarray.Dataset, got {type(ds).__name__}", source)
    problems = _structure_problems(ds)
    if problems:
        raise SchemaError(problems, source or ds.encoding.get("source"))


def occupied(ds: xr.Dataset) -> xr.DataArray:
    """Boolean (time, contact): True in the slots that hold a contact, ``slot <
    contact_count[time]`` (docs/schema.md: a snapshot's contacts fill its first slots); lazy on
    dask input."""
    import xarray as xr

    slot = xr.DataArray(np.arange(ds.sizes["contact"], dtype="i4"), dims="contact")
    return slot < ds["contact_count"]


def _duplicate_counts(keys):
    """Per row (last axis: slots), how many occupied slots (key >= 0) repeat an earlier key."""
    ordered = np.sort(keys, axis=-1)
    same = (ordered[..., 1:] == ordered[..., :-1]) & (ordered[..., 1:] >= 0)
    return same.sum(axis=-1)


def _unit_problems(ds: xr.Dataset) -> list[str]:
    """Variables whose ``units`` attribute differs from the contract's
    (:func:`grainview.contract.schema.unit_problems`)."""
    return unit_problems(_metadata(ds)[1])


def missing_units(ds: xr.Dataset) -> list[str]:
    """Contract variables of ``ds`` that carry no ``units`` attribute (taken in the contract's
    units by :func:`validate`; ``grainview info`` reports them)."""
    return _missing_units(_metadata(ds)[1])


def _value_checks(ds: xr.Dataset) -> dict[str, xr.DataArray]:
    """Lazy counts of bad entries, keyed by the message to show when the count is > 0."""
    n = ds.sizes["particle"]
    n_walls = ds.sizes.get("wall", 0)
    checks = {}
    radius = ds["radius"]
    checks["radius: {} particle(s) with negative or non-finite radius"] = (~(np.isfinite(radius) & (radius > 0))).sum()
    if "vertices" not in ds.variables:  # with them, the shapes' checks say it (_shape_problems)
        nv = ds["n_vertices"]
        checks["n_vertices: {} particle(s) with a value that is neither 0 (disk) nor >= 3"] = (
            (nv != 0) & (nv < 3)).sum()
    for name in ("mass", "inertia"):
        checks[f"{name}: {{}} particle(s) with negative or non-finite {name}"] = (~(np.isfinite(ds[name]) & (ds[name] > 0))).sum()
    for name in ("position", "angle"):
        checks[f"{name}: {{}} non-finite value(s)"] = (~np.isfinite(ds[name])).sum()
    count = ds["contact_count"]
    checks[COUNT_OUT_OF_RANGE.format(count="{}", slots=ds.sizes["contact"])] = (
        (count < 0) | (count > ds.sizes["contact"])).sum()
    occ = occupied(ds)
    i, j = ds["i"], ds["j"]
    bad_i = occ & ((i < 0) | (i >= n))
    bad_j = occ & ((j < 0) | (j >= n + n_walls))
    checks[f"i: {{}} occupied slot(s) with a particle id outside [0, {n})"] = bad_i.sum()
    checks[f"j: {{}} occupied slot(s) with a body id outside [0, {n + n_walls}) "
           f"(particles 0..{n - 1}, walls {n}..{n + n_walls - 1})"] = bad_j.sum()
    checks["i, j: {} particle pair(s) with i >= j (expected i < j)"] = (occ & (j < n) & (i >= j)).sum()
    checks[f"kind: {{}} occupied slot(s) with a kind other than {KIND_SIMPLE} (simple) or {KIND_DOUBLE} (double)"] = (
        occ & (ds["kind"] != KIND_SIMPLE) & (ds["kind"] != KIND_DOUBLE)).sum()
    for name in ("fn", "ft"):
        checks[NON_FINITE_FORCES.format(name=name, count="{}")] = (occ & ~np.isfinite(ds[name])).sum()
    for name in ("point", "branch"):
        checks[f"{name}: {{}} non-finite vector(s) in occupied slots"] = (
            occ & ~np.isfinite(ds[name]).all("xy")).sum()
    norm = np.sqrt((ds["normal"] ** 2).sum("xy"))
    checks[f"normal: {{}} occupied slot(s) whose normal is not a unit vector (| |n| - 1 | > {UNIT_NORMAL_TOLERANCE:g}, or NaN)"] = (
        occ & ~(abs(norm - 1) <= UNIT_NORMAL_TOLERANCE)).sum()
    for name, var in VARIABLES.items():
        if not var.required and not var.is_integer and name in ds.variables and "vertex" not in var.dims:
            bad = ~np.isfinite(ds[name])
            if "contact" in var.dims:  # empty slots hold the fill value
                bad = bad & occ
                checks[f"{name}: {{}} non-finite value(s) in occupied slots"] = bad.sum()
            else:
                checks[f"{name}: {{}} non-finite value(s)"] = bad.sum()
    import xarray as xr

    keys = xr.where(occ, i.astype(np.int64) * (n + n_walls) + j.astype(np.int64), -1)
    duplicates = xr.apply_ufunc(_duplicate_counts, keys, input_core_dims=[["contact"]], dask="parallelized",
                                output_dtypes=[np.int64])
    checks["i, j: {} slot(s) repeating a pair already stored in the same snapshot (a pair is stored once, "
           "a double contact with its resultant)"] = duplicates.sum()
    if "cell" in ds.variables and "periodic" in ds.variables:
        checks.update(_cell_checks(ds, occ))
    box_ok = (np.isfinite(ds["box_min"]) & np.isfinite(ds["box_max"]) & (ds["box_max"] > ds["box_min"])).all("xy")
    checks["box_min, box_max: {} snapshot(s) where the box is not finite with box_max above box_min "
           "in x and y"] = (~box_ok).sum()
    return checks


def _branch_counts(position, i, j, branch, count, cell, radius, periodic, gap=None):
    """:func:`grainview.contract.cell.branch_problems` of a block of snapshots, for apply_ufunc."""
    return branch_problems(position, i, j, branch, count, cell, radius, periodic, gap)


def _cell_checks(ds: xr.Dataset, occ) -> dict:
    """Lazy counts of a periodic file's bad branches and of the centres outside a wrapped cell."""
    import xarray as xr

    periodic = np.asarray(ds["periodic"].values).astype(bool)
    if periodic.shape != (2,):
        return {}
    args = [ds["position"], ds["i"], ds["j"], ds["branch"], ds["contact_count"], ds["cell"]]
    core = [["particle", "xy"], ["contact"], ["contact"], ["contact", "xy"], [], ["cell_vector", "xy"]]
    if "gap" in ds.variables:
        args.append(ds["gap"])
        core.append(["contact"])

    def counts(position, i, j, branch, count, cell, *gap):
        return _branch_counts(position, i, j, branch, count, cell, ds["radius"].values, periodic, *gap)

    bad = xr.apply_ufunc(counts, *args, input_core_dims=core, output_core_dims=[["problem"]], dask="parallelized",
                         output_dtypes=[np.int64], dask_gufunc_kwargs={"output_sizes": {"problem": 2}})
    checks = {
        "branch: {} particle pair(s) whose branch is not the minimum image of their centres in the periodic cell "
        "(x_j - x_i moved by whole cell vectors to its shortest)": bad.isel(problem=0).sum(),
        "branch: {} particle pair(s) whose branch is longer than the particles allow (r_i + r_j, plus the gap of a "
        "near contact): a branch across the periodic cell instead of its minimum image?": bad.isel(problem=1).sum(),
    }
    if ds.attrs.get("cell_positions", "wrapped") == "wrapped":
        st = xr.apply_ufunc(fractional, ds["position"] - ds["box_min"], ds["cell"],
                            input_core_dims=[["xy"], ["cell_vector", "xy"]], output_core_dims=[["xy"]],
                            dask="parallelized", output_dtypes=[float])
        outside = ((st < -1e-9) | (st > 1 + 1e-9)) & xr.DataArray(periodic, dims="xy")
        checks["position: {} centre(s) outside the periodic cell although the file says cell_positions = "
               "'wrapped' (0 <= s, t <= 1 along the periodic vectors)"] = outside.any("xy").sum()
    return checks


def _cell_problems(ds: xr.Dataset) -> list[str]:
    """The problems of a periodic file's ``cell``, ``periodic`` and ``cell_positions``
    (:func:`grainview.contract.cell.cell_problems`)."""
    if "cell" not in ds.variables or "periodic" not in ds.variables:
        return []
    problems = cell_problems(ds["cell"].values, ds["box_min"].values, ds["box_max"].values, ds["periodic"].values)
    positions = ds.attrs.get("cell_positions", "wrapped")
    if positions not in CELL_POSITIONS:
        problems.append(f"global attribute cell_positions={positions!r}: expected one of {CELL_POSITIONS}")
    return problems


def _shape_problems(ds: xr.Dataset) -> list[str]:
    """The problems of the file's ``vertices`` (:func:`grainview.contract.shapes.shape_problems`:
    their NaN padding, convex and counter-clockwise polygons centred on their centroid, ``radius``
    the farthest vertex); none for a file without them (regular polygons)."""
    if "vertices" not in ds.variables:
        return []
    return shape_problems(ds["radius"].values, ds["n_vertices"].values, ds["vertices"].values)


def _per_snapshot(ds: xr.Dataset) -> dict[str, xr.DataArray]:
    """Lazy per-snapshot arrays that the order and sign checks read: ``time`` and ``step``
    (where the file has it), and the number of negative normal forces in occupied slots."""
    arrays = {"time": ds["time"].variable, "negative_fn": (occupied(ds) & (ds["fn"] < 0)).sum("contact")}
    if "step" in ds.variables:
        arrays["step"] = ds["step"]
    return arrays


def _per_snapshot_problems(ds: xr.Dataset, values: dict) -> list[str]:
    """The lines of :func:`_per_snapshot`'s arrays, computed: ``time`` and ``step``
    increasing strictly, no negative normal force (the first one named: its snapshot is read
    again, only when there is one)."""
    problems = order_problems("time", values["time"], " s")
    if "step" in values:
        problems += order_problems("step", values["step"])
    negative = np.asarray(values["negative_fn"])
    if negative.any():
        k = int(np.flatnonzero(negative)[0])
        snap = ds[["fn", "i", "j"]].isel(time=k)
        fn = np.asarray(snap["fn"].values)
        slot = int(np.flatnonzero(np.asarray(occupied(ds.isel(time=k)).values) & (fn < 0))[0])
        problems.append(negative_force_problem(int(negative.sum()), k, slot, int(snap["i"].values[slot]),
                                               int(snap["j"].values[slot]), float(fn[slot])))
    return problems


def validate(ds: xr.Dataset, source: str | None = None) -> xr.Dataset:
    """Check ``ds`` against the contract; raise one :class:`SchemaError` listing every problem.

    Checked: every required variable present with its dims and an integer/float dtype as the
    contract says; no negative radius, mass or inertia; ``n_vertices`` 0 or >= 3; the
    polygons' ``vertices``, where the file has them, convex, counter-clockwise, centred on
    their centroid, ``radius`` their farthest vertex, NaN beyond each one's count
    (:func:`grainview.contract.shapes.shape_problems`); finite
    positions; ``contact_count`` within the slots; in occupied slots: ids in range and
    ``i < j`` for particle pairs, each pair at most once per snapshot, kind 1 or 2, finite
    forces, normal forces >= 0 (the first negative one named by snapshot, slot and bodies),
    finite points and branches, unit normals; a box of positive size; in a periodic file, its
    cell (:func:`grainview.contract.cell.cell_problems`), every particle pair's branch the
    minimum image of its centres and no longer than the particles allow, and the centres inside
    the cell when the file says they are wrapped; ``time`` (and ``step``,
    where the file has it) increasing strictly, so no snapshot is repeated; every variable's
    ``units`` those of the contract. A file holding none of the contract's variables gets one
    problem, that it is not a grainview file. On a dask-backed dataset the value checks are computed
    in one pass over the chunks.

    Parameters
    ----------
    ds : xarray.Dataset
        A dataset of the contract (docs/schema.md), eager or chunked along ``time``.
    source : str, optional
        The file name to put in the error (default: ``ds.encoding["source"]``).

    Returns
    -------
    xarray.Dataset
        ``ds`` unchanged, so that calls can be chained.

    Raises
    ------
    SchemaError
        Every problem found, listed together.
    """
    import dask
    import xarray as xr

    source = source or (ds.encoding.get("source") if isinstance(ds, xr.Dataset) else None)
    check_structure(ds, source)  # values cannot be checked reliably on a malformed structure
    problems = _unit_problems(ds) + _shape_problems(ds) + _cell_problems(ds)
    checks = _value_checks(ds)
    per_snapshot = _per_snapshot(ds)
    values = list(checks.values()) + list(per_snapshot.values())
    if any(dask.is_dask_collection(v) for v in values):
        (values,) = dask.compute(values)  # one pass over the chunks
    values = [np.asarray(getattr(v, "values", v)) for v in values]
    for message, value in zip(checks, values):
        value = int(value)
        if value:
            problems.append(message.format(value))
    problems += _per_snapshot_problems(ds, dict(zip(per_snapshot, values[len(checks):])))
    if problems:
        raise SchemaError(problems, source)
    return ds
