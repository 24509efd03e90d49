"""Ensembles: many runs as one lazy Dataset along a ``run`` dimension, and statistics over seeds.

:func:`open_ensemble` opens files of the contract (a list, a glob pattern or a folder) and
concatenates them along a new dimension ``run``, lazily, chunked by run and by time. The runs
may differ in everything a study varies — seed, friction, size, confining stress — so:

* ``time`` becomes positional: snapshot k of every run lies at index k; each run's own times
  are the coordinate ``run_time(run, time)`` (s) and its snapshot count ``run_snapshots(run)``;
  a shorter run is padded at the end;
* ``particle`` and ``contact`` are padded to the largest run (``run_particles(run)``,
  ``run_contacts(run)`` give each run's own sizes); the padding takes the contract's empty-slot
  values (i, j = -1, kind = 0, NaN otherwise; integer variables along time or particle 0);
* global attributes equal in every file stay attributes; those that differ (or that some files
  lack: a file written by an older version) become coordinates along ``run`` named
  ``attr_<name>``, holding each file's own value (object dtype, :data:`ABSENT` where a file
  has none); the parameters a user groups by get short typed names: :data:`RUN_PARAMETERS`
  (``shape``, ``particles``, ``seed``, ``friction``, ``sigma0_Pa``, ``preparation``,
  ``velocity_m_s``), and ``group`` labels the runs that share every setting but the seed
  (:data:`SETTING_PREFIXES`, :data:`SETTINGS`): the unit over which seeds are pooled.

Nothing is lost: :func:`run_dataset` gives back run k exactly as :func:`grainview.open_dataset`
opens its file alone (values, dtypes, attributes). The ``ds.grain`` accessor uses it: on an
ensemble every analysis runs per run, unchanged, and the results come back along ``run``
(:func:`map_runs`; time series on the positional ``time`` with their ``eps_q`` per run).
:func:`seed_statistics` reduces such results over the seeds of each group — mean, standard
deviation (ddof = 1), standard error and count — on a common strain axis (eps_q bins).
"""

from __future__ import annotations

import glob
import os
from pathlib import Path

import numpy as np
import xarray as xr

from ..contract.errors import ParameterError
from ..contract.schema import EMPTY_ID, EMPTY_KIND

RUN_PARAMETERS = {
    "shape": ("preparation_shape",),
    "particles": ("preparation_particles", "n_particles"),
    "seed": ("preparation_seed", "solver_seed"),
    "friction": ("solver_friction",),
    "sigma0_Pa": ("sigma0_Pa",),
    "preparation": ("preparation_name",),
    "velocity_m_s": ("wall_velocity_m_s",),
}
"""Short run coordinates and the global attributes they are read from (the first present)."""

PADDED_DIMS = ("time", "particle", "contact")
"""Dimensions whose size may differ between runs (padded to the largest)."""
RUN_SIZES = {"time": "run_snapshots", "particle": "run_particles", "contact": "run_contacts"}
"""Per-run size coordinate of each padded dimension."""
SETTING_PREFIXES = ("solver_", "preparation_")
"""Global attributes that set up a run (the solver's parameters, the sample's preparation)..."""
SETTINGS = ("strain_target", "wall_velocity_m_s", "sigma0_Pa", "scene", "snapshot_every")
"""...and these: runs that differ in any of them (the seed and version aside) are not seeds of
one setting."""
NOT_SETTINGS = ("preparation_seed", "solver_seed", "solver_version")
ABSENT = "<absent>"
"""Value of an ``attr_<name>`` coordinate for a run whose file has no such attribute."""
ATTR_PREFIX = "attr_"
"""Prefix of the coordinates along ``run`` that hold the global attributes differing between runs."""
ENSEMBLE_ATTR = "grainview_ensemble_attrs"
"""Global attribute of an ensemble naming the attributes that differ between its runs."""


def _paths(paths) -> list[str]:
    if isinstance(paths, (str, os.PathLike)):
        text = os.fspath(paths)
        if os.path.isdir(text):
            found = sorted(glob.glob(os.path.join(text, "*.nc")))
            where = f"folder {text}"
        else:
            found = sorted(glob.glob(text))
            where = f"pattern {text!r}"
        if not found:
            raise ParameterError(f"{where}: no netCDF file found; expected files of the grainview contract")
        return found
    found = [os.fspath(p) for p in paths]
    if not found:
        raise ParameterError("paths is empty: expected netCDF files of the grainview contract")
    return found


def _fill(var: xr.DataArray, name: str):
    """Empty-slot value of a padded variable (the contract's for contacts)."""
    if name in ("i", "j"):
        return EMPTY_ID
    if name == "kind":
        return EMPTY_KIND
    return np.nan if var.dtype.kind == "f" else 0


def _pad(ds: xr.Dataset, sizes: dict) -> xr.Dataset:
    """``ds`` padded at the end of each dimension of :data:`PADDED_DIMS` to ``sizes``."""
    out = {}
    for name, var in ds.variables.items():
        widths = {d: (0, sizes[d] - ds.sizes[d]) for d in var.dims if d in sizes and sizes[d] > ds.sizes[d]}
        if widths:
            padded = var.pad(widths, constant_values=_fill(var, name))
            padded.attrs, padded.encoding = dict(var.attrs), dict(var.encoding)
            var = padded
        out[name] = var
    padded = xr.Dataset({k: v for k, v in out.items() if k not in ds.coords},
                        coords={k: v for k, v in out.items() if k in ds.coords}, attrs=ds.attrs)
    return padded


def _differs(a, b) -> bool:
    try:
        return not np.array_equal(np.asarray(a), np.asarray(b))
    except (TypeError, ValueError):
        return a != b


def open_ensemble(paths, chunks="auto", validate: bool = False, names=None) -> xr.Dataset:
    """Open runs of the contract as one lazy Dataset along ``run`` (see the module docstring).

    Every file must have the same walls and variables. Each accessor works on the result per
    run (``ens.grain.stress_invariants()`` has a ``run`` dimension), and :func:`run_dataset`
    gives one run back as its file opens alone.

    Parameters
    ----------
    paths : str, path-like or sequence of them
        A list of files, a glob pattern (``"study/*.nc"``) or a folder (its ``*.nc``).
    chunks : int, dict, "auto" or None, default "auto"
        Snapshots per dask chunk of each run, as :func:`grainview.open_dataset`.
    validate : bool, default False
        Check every file against the contract first.
    names : sequence of str, optional
        The ``run`` coordinate (default: the file names without ``.nc``).

    Returns
    -------
    xarray.Dataset
        The runs along ``run`` (its coordinate: ``names``), lazy unless ``chunks=None``.

    Raises
    ------
    grainview.contract.errors.ParameterError
        When no file is found, ``names`` does not match the files, two runs share a name, or
        the files differ in variables or walls.

    Examples
    --------
    >>> ens = open_ensemble("study/*.nc")                                   # doctest: +SKIP
    >>> seed_statistics(ens.grain.fabric_anisotropy()["a"], eps_q_bins=np.arange(0, 0.7, 0.05))  # doctest: +SKIP
    """
    from ..contract.io import open_dataset

    files = _paths(paths)
    if names is None:
        names = [Path(f).stem for f in files]
        if len(set(names)) != len(names):  # the same file name in several folders: the paths
            names = [os.path.splitext(f)[0] for f in files]
    names = [str(n) for n in names]
    if len(names) != len(files):
        raise ParameterError(f"names has {len(names)} entries for {len(files)} files")
    if len(set(names)) != len(names):
        raise ParameterError(f"two runs share a name among {names} (the same file twice?)")
    runs = [open_dataset(f, chunks=chunks, validate=validate) for f in files]
    first = runs[0]
    for f, ds in zip(files, runs):
        if set(ds.data_vars) != set(first.data_vars):
            missing = sorted(set(first.data_vars) ^ set(ds.data_vars))
            raise ParameterError(f"{f}: its variables differ from {files[0]}'s ({missing}); an ensemble needs "
                                 "files written the same way")
        for coord in ("xy", "wall"):
            if coord in first.coords and not np.array_equal(ds[coord].values, first[coord].values):
                raise ParameterError(f"{f}: its {coord} coordinate differs from {files[0]}'s")
    sizes = {d: max(ds.sizes.get(d, 0) for ds in runs) for d in PADDED_DIMS}
    keys = list(dict.fromkeys(k for ds in runs for k in ds.attrs))
    varying = [k for k in keys if any(k not in ds.attrs or _differs(ds.attrs[k], first.attrs.get(k)) for ds in runs)]
    pieces = []
    for ds in runs:
        times = ds["time"]
        one = ds.drop_vars("time").assign_coords(run_time=("time", times.values, times.attrs))
        one = _pad(one, sizes)
        coords = {RUN_SIZES[d]: ds.sizes[d] for d in PADDED_DIMS}
        coords["source"] = ds.encoding.get("source", "")
        pieces.append(one.assign_coords(coords))
    ens = xr.concat(pieces, dim="run", data_vars="all", coords="all", compat="equals", join="exact",
                    combine_attrs="override")  # the variables' attributes: the same in every file
    ens = ens.assign_coords(run=names)
    if chunks is not None:  # the analyses need particle and contact whole in each chunk, as in one file
        ens = ens.assign({name: var.chunk({d: -1 for d in ("particle", "contact") if d in var.dims})
                          for name, var in ens.data_vars.items() if var.chunks is not None})
    for name in ("xy", "wall"):  # index coordinates, the same in every run
        if name in first.coords:
            ens = ens.assign_coords({name: first[name]})
    per_run = {}
    for k in varying:  # each file's own value, type and all (object dtype), or ABSENT
        values = np.empty(len(runs), dtype=object)
        for r, ds in enumerate(runs):
            values[r] = ds.attrs.get(k, ABSENT)
        per_run[ATTR_PREFIX + k] = ("run", values)
    ens = ens.assign_coords(per_run)
    ens.attrs = {k: v for k, v in first.attrs.items() if k not in varying}
    ens.attrs[ENSEMBLE_ATTR] = " ".join(varying)
    return _with_parameters(ens, runs, varying)


def _is_setting(name: str) -> bool:
    return (name.startswith(SETTING_PREFIXES) or name in SETTINGS) and name not in NOT_SETTINGS


def _with_parameters(ens: xr.Dataset, runs, varying) -> xr.Dataset:
    """Add :data:`RUN_PARAMETERS` and ``group`` as coordinates along ``run``."""
    params = {}
    for short, sources in RUN_PARAMETERS.items():
        values = []
        for ds in runs:
            key = next((k for k in sources if k in ds.attrs), None)
            values.append(ds.attrs[key] if key is not None else np.nan)
        if short == "particles":
            values = [ds.sizes["particle"] for ds in runs]
        if short == "shape" and all(isinstance(v, float) and np.isnan(v) for v in values):
            from .sample import shape_name

            values = [shape_name(ds) for ds in runs]
        params[short] = ("run", np.asarray(values))
    ens = ens.assign_coords(params)
    short = [k for k in RUN_PARAMETERS if k != "seed" and len(np.unique(ens[k].values.astype(str))) > 1]
    covered = {source for k in RUN_PARAMETERS for source in RUN_PARAMETERS[k]}
    # a setting that some files lack but all others agree on is not a difference: files of an
    # older version, written before the parameter existed, ran with what is now its default
    others = [k for k in varying if _is_setting(k) and k not in covered
              and len({repr(ds.attrs[k]) for ds in runs if k in ds.attrs}) > 1]
    labels = []
    for r in range(ens.sizes["run"]):
        parts = [_label(k, ens[k].values[r]) for k in short or ["shape"]]
        parts += [_label(k, runs[r].attrs.get(k, ABSENT)) for k in others]
        labels.append(", ".join(parts))
    return ens.assign_coords(group=("run", np.asarray(labels)))


def _label(key, value) -> str:
    if key == "shape":
        return str(value)
    if key == "particles":
        return f"N={value}"
    if isinstance(value, (float, np.floating)):
        return f"{key} {value:.6g}"
    if isinstance(value, np.ndarray):
        return f"{key} {np.array2string(value, separator=',')}"
    return f"{key} {value}"


def is_ensemble(ds) -> bool:
    """Whether ``ds`` is an ensemble of :func:`open_ensemble` (has a ``run`` dimension).

    Parameters
    ----------
    ds : object
        Anything; a Dataset or DataArray is looked at for a ``run`` dimension.

    Returns
    -------
    bool
        True when ``ds`` has a ``run`` dimension.
    """
    return "run" in getattr(ds, "dims", ())


def run_dataset(ens: xr.Dataset, run) -> xr.Dataset:
    """Run ``run`` of an ensemble, exactly as :func:`grainview.open_dataset` opens its file alone.

    ``run`` is an index, or a name of the ``run`` coordinate. Padding is removed; the run gets
    its own ``time`` coordinate and its global attributes.

    Parameters
    ----------
    ens : xarray.Dataset
        An ensemble of :func:`open_ensemble`.
    run : int or str
        Position along ``run``, or a value of the ``run`` coordinate.

    Returns
    -------
    xarray.Dataset
        The run alone (lazy where the ensemble is), identical to opening its file.

    Examples
    --------
    >>> ens = grainview.open_ensemble("ensemble/*.nc")            # doctest: +SKIP
    >>> grainview.analysis.ensemble.run_dataset(ens, 0).grain.stress_invariants()  # doctest: +SKIP
    """
    if not is_ensemble(ens):
        raise ParameterError("not an ensemble: expected a Dataset with a 'run' dimension (open_ensemble)")
    if isinstance(run, str):
        names = list(ens["run"].values)
        if run not in names:
            raise ParameterError(f"run={run!r}: expected one of {names}")
        run = names.index(run)
    one = ens.isel(run=int(run))
    trims = {d: slice(0, int(one[RUN_SIZES[d]])) for d in PADDED_DIMS if d in one.dims}
    one = one.isel(trims)
    per_run = ens.attrs.get(ENSEMBLE_ATTR, "").split()
    attrs = {k: v for k, v in ens.attrs.items() if k != ENSEMBLE_ATTR}
    for k in per_run:
        value = one[ATTR_PREFIX + k].values[()]
        if not (isinstance(value, str) and value == ABSENT):
            attrs[k] = value
    times = one["run_time"]
    drop = [name for name in one.coords
            if "run" in ens[name].dims and name not in one.dims or name.startswith(ATTR_PREFIX) or name == "run"]
    one = one.drop_vars(list(dict.fromkeys(drop)))
    one = one.assign_coords(time=("time", times.values, times.attrs))
    one.attrs = attrs
    source = str(ens["source"].values[int(run)]) if "source" in ens.coords else ""
    if source:
        one.encoding["source"] = source
    return one


def run_parameters(ens: xr.Dataset) -> list[str]:
    """Coordinates along ``run`` only (the run's parameters and sizes).

    Parameters
    ----------
    ens : xarray.Dataset
        An ensemble of :func:`open_ensemble`.

    Returns
    -------
    list of str
        The names of the coordinates whose only dimension is ``run``.
    """
    return [name for name, c in ens.coords.items() if c.dims == ("run",)]


def _positional(result):
    """A per-run result with ``time`` made positional (its times kept as ``run_time``)."""
    if "time" in result.indexes:
        times = result["time"]
        result = result.drop_vars("time").assign_coords(run_time=("time", times.values, times.attrs))
    return result


def combine_runs(results, ens: xr.Dataset):
    """Per-run xarray results along a new ``run`` dimension with the ensemble's run coordinates.

    Dimensions without an index (``time``, ``contact_event``...) are padded with NaN to the
    longest run.

    Parameters
    ----------
    results : sequence of xarray.Dataset or xarray.DataArray
        One result per run, in the ensemble's run order.
    ens : xarray.Dataset
        The ensemble they come from (its ``run`` coordinates are attached).

    Returns
    -------
    xarray.Dataset or xarray.DataArray
        The results along a new leading ``run`` dimension.
    """
    results = [_positional(r) for r in results]
    sizes = {}
    for r in results:
        for d, n in r.sizes.items():
            if d not in r.indexes:
                sizes[d] = max(sizes.get(d, 0), n)
    padded = []
    for r in results:
        widths = {d: (0, sizes[d] - r.sizes[d]) for d in r.dims if d in sizes and sizes[d] > r.sizes[d]}
        padded.append(r.pad(widths) if widths else r)
    out = xr.concat(padded, dim="run", coords="all", join="outer", combine_attrs="override")  # compares nothing: lazy
    return out.assign_coords({name: ens[name] for name in run_parameters(ens)}).assign_coords(run=ens["run"])


def map_runs(ens: xr.Dataset, func):
    """``func(run_dataset(ens, k))`` for every run, combined along ``run``.

    xarray results are combined along ``run`` (:func:`combine_runs`), any other result is
    returned as a dict {run name: result}.

    Parameters
    ----------
    ens : xarray.Dataset
        An ensemble of :func:`open_ensemble`.
    func : callable
        Called with each run's dataset.

    Returns
    -------
    xarray.Dataset or xarray.DataArray or dict
        The results along ``run`` (padded to the longest run), or {run name: result}.
    """
    results = [func(run_dataset(ens, k)) for k in range(ens.sizes["run"])]
    if all(isinstance(r, (xr.DataArray, xr.Dataset)) for r in results):
        return combine_runs(results, ens)
    return dict(zip((str(n) for n in ens["run"].values), results))


def _bin_strain(da: xr.DataArray, bins) -> xr.DataArray:
    """Each run's time series averaged within eps_q ``bins`` (dimension ``eps_q_bin``, its
    coordinate the bin centre)."""
    if "eps_q" not in da.coords:
        raise ParameterError(f"{da.name or 'the result'} has no eps_q coordinate to bin (a time series of the "
                             "accessor has one)")
    bins = np.asarray(bins, dtype=float)
    if bins.ndim != 1 or bins.size < 2 or not np.all(np.isfinite(bins)) or not np.all(np.diff(bins) > 0):
        raise ParameterError(f"eps_q_bins={bins.tolist()}: expected at least two increasing finite edges")
    eps = da["eps_q"].broadcast_like(da).values
    values = da.values
    t = da.get_axis_num("time")
    values, eps = np.moveaxis(values, t, -1), np.moveaxis(eps, t, -1)
    which = np.digitize(eps, bins) - 1
    which[eps == bins[-1]] = bins.size - 2  # the last bin is closed: [e_{n-1}, e_n]
    shape = values.shape[:-1] + (bins.size - 1,)
    total, count = np.zeros(shape), np.zeros(shape)
    ok = (which >= 0) & (which < bins.size - 1) & np.isfinite(values)
    index = np.nonzero(ok)
    np.add.at(total, index[:-1] + (which[ok],), values[ok])
    np.add.at(count, index[:-1] + (which[ok],), 1)
    with np.errstate(invalid="ignore"):
        mean = np.where(count > 0, total / np.maximum(count, 1), np.nan)
    dims = [d for d in da.dims if d != "time"] + ["eps_q_bin"]
    coords = {k: v for k, v in da.coords.items() if "time" not in v.dims}
    coords["eps_q_bin"] = ("eps_q_bin", 0.5 * (bins[1:] + bins[:-1]), {"units": "1", "long_name": "eps_q bin centre"})
    return xr.DataArray(mean, dims=dims, coords=coords, name=da.name, attrs=da.attrs)


def seed_statistics(result, eps_q_bins=None) -> xr.Dataset:
    """Mean, spread and standard error over the seeds of each ``group`` of a per-run result.

    The runs of a ``group`` are the seeds of one setting. With ``eps_q_bins`` (increasing
    edges; each bin [e_k, e_k+1), the last one closed), a time series is first averaged within
    each bin of shear strain eps_q run by run, so that runs of different heights, rates or
    lengths share one strain axis; without, the runs are compared snapshot by snapshot (or the
    result has no ``time``). Returns, per group:

        mean,    std (sample standard deviation, ddof = 1),    sem = std / sqrt(n),

    and ``n`` (runs with a value); for a Dataset, ``<name>_mean``... for each variable. NaN
    values (a run without snapshots in a bin) are left out.

    Parameters
    ----------
    result : xarray.DataArray or xarray.Dataset
        A per-run result of an ensemble (``ens.grain.<analysis>()``): a ``run`` dimension and
        the ``group`` coordinate.
    eps_q_bins : array_like, optional
        Increasing edges of the shear-strain bins (1); bins are [e_k, e_k+1), the last closed.

    Returns
    -------
    xarray.Dataset
        ``mean``, ``std``, ``sem`` (in the result's units) and ``n`` along ``group`` (and
        ``eps_q_bin``, the bin centres, with bins).

    Raises
    ------
    grainview.contract.errors.ParameterError
        When ``result`` has no ``run`` dimension or ``group`` coordinate, or, with
        ``eps_q_bins``, no ``eps_q`` coordinate or bins that are not increasing finite edges.
    """
    if isinstance(result, xr.Dataset):
        out = xr.Dataset()
        for name, da in result.data_vars.items():
            if "run" in da.dims:
                stats = seed_statistics(da, eps_q_bins)
                out.update({f"{name}_{k}": v for k, v in stats.data_vars.items()})
        return out
    if "run" not in result.dims or "group" not in result.coords:
        raise ParameterError("expected a per-run result of an ensemble (a 'run' dimension and a 'group' "
                             "coordinate: ens.grain.<analysis>() on open_ensemble's Dataset)")
    da = result.compute()
    if eps_q_bins is not None:
        da = _bin_strain(da, eps_q_bins)
    keep = [name for name in da.coords if "run" in da[name].dims and name != "group"]
    da = da.drop_vars(keep)
    grouped = da.groupby("group")
    n = da.notnull().groupby("group").sum("run")
    std = grouped.std("run", ddof=1, skipna=True).where(n > 1)
    out = xr.Dataset({"mean": grouped.mean("run", skipna=True), "std": std, "sem": std / np.sqrt(n), "n": n})
    for name in ("mean", "std", "sem"):
        out[name].attrs = dict(result.attrs)
    out["n"].attrs = {"units": "1", "long_name": "runs (seeds) with a value"}
    return out


__all__ = ["open_ensemble", "run_dataset", "map_runs", "combine_runs", "seed_statistics", "is_ensemble",
           "run_parameters", "RUN_PARAMETERS"]
