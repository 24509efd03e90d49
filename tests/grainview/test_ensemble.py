"""open_ensemble and the statistics over seeds, on synthetic runs of different sizes: every run
of the ensemble equals its file opened alone, the accessor works per run and lazily, and the
spread over seeds equals numpy's on the per-run values."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import xarray as xr

import grainview
from grainview.contract.dataset import netcdf_encoding
from grainview.analysis.ensemble import run_dataset, seed_statistics
from grainview.contract.errors import ParameterError
from grainview.datasets import harmonic_series

from .conftest import raise_if_dask_computes

# (snapshots, contacts, seed, friction): two settings (the second also larger: 90 particles
# against 80), the first with three seeds of different lengths
RUNS = [(6, 40, 0, 0.4), (8, 40, 1, 0.4), (5, 40, 2, 0.4), (7, 45, 0, 0.2)]
FIRST, SECOND = "N=80, friction 0.4", "N=90, friction 0.2"


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("ensemble")
    paths = []
    for n_snap, n_contacts, seed, friction in RUNS:
        ds = harmonic_series(n_snapshots=n_snap, n_contacts=n_contacts, seed=seed + 10 * int(friction * 10))
        ds.attrs.update(preparation_seed=np.int32(seed), solver_friction=np.float64(friction),
                        preparation_shape="pentagon")
        path = folder / f"run_mu{friction}_s{seed}.nc"
        # netCDF-3, as the solver writes: reopening NETCDF4 files that were opened and closed before
        # crashes netCDF4 1.7.5 / HDF5 2.2 on this machine (docs/ensembles.md)
        ds.to_netcdf(path, encoding=netcdf_encoding(ds), format="NETCDF3_64BIT")
        paths.append(path)
    return paths


def test_every_run_is_its_file_opened_alone(files):
    ens = grainview.open_ensemble(files, chunks=2)
    assert ens.sizes["run"] == 4 and ens.sizes["time"] == 8 and ens.sizes["contact"] == 45 and ens.sizes["particle"] == 90
    assert list(ens["run_snapshots"].values) == [n for n, *_ in RUNS]
    assert list(ens["seed"].values) == [s for *_, s, _ in RUNS]
    assert list(ens["group"].values) == [FIRST] * 3 + [SECOND]
    assert ens["fn"].chunks[0] == (1, 1, 1, 1)  # chunked by run...
    assert max(ens["fn"].chunks[1]) == 2  # ...and by time
    for k, path in enumerate(files):
        one, alone = run_dataset(ens, k).compute(), grainview.open_dataset(path, chunks=None)
        xr.testing.assert_identical(one, alone)
        assert one.attrs.keys() == alone.attrs.keys()
        for key, value in alone.attrs.items():
            assert np.array_equal(one.attrs[key], value), key
        assert all(one[v].dtype == alone[v].dtype for v in alone.variables)
    # the padding takes the contract's empty-slot values
    assert int(ens["i"].isel(run=0, time=0, contact=-1)) == -1 and int(ens["kind"].isel(run=0, time=0, contact=-1)) == 0
    assert np.isnan(ens["radius"].isel(run=0, particle=-1))


def test_accessor_per_run_lazily(files):
    ens = grainview.open_ensemble(files, chunks=2)
    with raise_if_dask_computes():
        q = ens.grain.stress_invariants()["q_over_p"]
        a = ens.grain.fabric_anisotropy()["a"]
    assert q.dims == ("run", "time") and "eps_q" in q.coords and "friction" in q.coords
    for k, path in enumerate(files):
        alone = grainview.open_dataset(path)
        n = RUNS[k][0]
        np.testing.assert_array_equal(q.isel(run=k, time=slice(0, n)).values,
                                      alone.grain.stress_invariants()["q_over_p"].values)
        np.testing.assert_array_equal(a.isel(run=k, time=slice(0, n)).values, alone.grain.fabric_anisotropy()["a"].values)
        assert np.isnan(q.isel(run=k, time=slice(n, None)).values).all()  # the shorter runs' padding
    tables = ens.grain.contacts_table(time=0)  # a pandas result: one per run
    assert list(tables) == [str(r) for r in ens["run"].values]


def test_seed_statistics_against_numpy(files):
    ens = grainview.open_ensemble(files)
    q = ens.grain.stress_invariants()["q_over_p"]
    bins = np.array([0.0, 0.02, 0.05, 0.1, 0.2])
    stats = seed_statistics(q, eps_q_bins=bins)
    per_run = []  # each file alone, binned by hand
    for path in files:
        alone = grainview.open_dataset(path, chunks=None)
        qp = alone.grain.stress_invariants()["q_over_p"].values
        eps = alone.grain.strains()["eps_q"].values
        per_run.append([qp[(eps >= lo) & (eps < hi)].mean() if ((eps >= lo) & (eps < hi)).any() else np.nan
                        for lo, hi in zip(bins[:-1], bins[1:])])
    per_run = np.array(per_run)
    seeds = per_run[:3]
    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # an empty bin: NaN, as expected
        n = np.isfinite(seeds).sum(0)
        mean, std = np.nanmean(seeds, 0), np.nanstd(seeds, 0, ddof=1)
    std = np.where(n > 1, std, np.nan)
    s = stats.sel(group=FIRST)
    np.testing.assert_allclose(s["mean"].values, mean, rtol=1e-12)
    np.testing.assert_allclose(s["std"].values, std, rtol=1e-12)
    np.testing.assert_allclose(s["sem"].values, std / np.sqrt(n), rtol=1e-12)
    np.testing.assert_array_equal(s["n"].values, n)
    np.testing.assert_allclose(stats.sel(group=SECOND)["mean"].values, per_run[3], rtol=1e-12)
    assert np.isnan(stats.sel(group=SECOND)["std"].values).all()  # one seed: no spread


def test_ensemble_report_spread_against_numpy(files, tmp_path):
    from grainview.app.ensemble_report import write_ensemble_report
    from grainview.app.report import run_summary

    ens = grainview.open_ensemble(files)
    result = write_ensemble_report(ens, tmp_path / "report", residual_strain=0.0)
    stats = result["statistics"][FIRST]
    alone = [run_summary(grainview.open_dataset(p), residual_strain=0.0) for p in files[:3]]
    for row in ("q/p (residual)", "a (residual)", "z (initial)", "weak fraction"):
        values = np.array([float(s[row]) for s in alone])
        assert stats.loc[row, "mean"] == pytest.approx(values.mean(), rel=1e-12)
        assert stats.loc[row, "std"] == pytest.approx(values.std(ddof=1), rel=1e-12)
        assert stats.loc[row, "sem"] == pytest.approx(values.std(ddof=1) / np.sqrt(3), rel=1e-12)
        assert stats.loc[row, "n"] == 3
    q = stats.loc["q/p (residual)"]
    assert f"{q['mean']:.3f} ± {q['std']:.3f} (3 seeds)" in (tmp_path / "report" / "headline.md").read_text()
    assert (tmp_path / "report" / "fig_ensemble_q_over_p.png").stat().st_size > 0
    with pytest.raises(FileExistsError, match="overwrite"):
        write_ensemble_report(ens, tmp_path / "report", residual_strain=0.0)


def test_open_ensemble_errors(files, tmp_path):
    with pytest.raises(ParameterError, match="no netCDF file"):
        grainview.open_ensemble(tmp_path)
    with pytest.raises(ParameterError, match="share a name"):
        grainview.open_ensemble([files[0], files[0]])
    odd = harmonic_series(n_snapshots=3, n_contacts=10).drop_vars("kind")
    odd.to_netcdf(tmp_path / "odd.nc", format="NETCDF3_64BIT")
    with pytest.raises(ParameterError, match="variables differ"):
        grainview.open_ensemble([files[0], tmp_path / "odd.nc"])
    with pytest.raises(ParameterError, match="not an ensemble"):
        run_dataset(grainview.open_dataset(files[0]), 0)
    ens = grainview.open_ensemble(files)
    with pytest.raises(ParameterError, match="increasing"):
        seed_statistics(ens.grain.stress_invariants()["q_over_p"], eps_q_bins=[0.1, 0.0])
    with pytest.raises(ParameterError, match="not an ensemble"):
        ens.grain.plot
    with pytest.raises(ParameterError, match="per-run result"):
        seed_statistics(grainview.open_dataset(files[0]).grain.stress_invariants()["q_over_p"])


def test_files_of_different_versions_and_settings(files, tmp_path):
    """A file without an attribute the others have (an older version) opens as written and does
    not split its group; a setting that differs (here the NLGS tolerance) does."""
    paths = []
    for k, (attrs, drop) in enumerate([({"solver_tolerance": 1e-4, "solver_domains": np.int32(1)}, False),
                                       ({"solver_tolerance": 1e-4}, False),
                                       ({"solver_tolerance": 1e-5, "solver_domains": np.int32(1)}, False)]):
        ds = harmonic_series(n_snapshots=4, n_contacts=30, seed=k)
        ds.attrs.update(preparation_seed=np.int32(k), preparation_shape="pentagon", **attrs)
        paths.append(tmp_path / f"v{k}.nc")
        ds.to_netcdf(paths[-1], encoding=netcdf_encoding(ds), format="NETCDF3_64BIT")
    ens = grainview.open_ensemble(paths)
    assert list(ens["attr_solver_domains"].values) == [1, "<absent>", 1]
    assert list(ens["group"].values) == ["pentagon, solver_tolerance 0.0001"] * 2 + ["pentagon, solver_tolerance 1e-05"]
    for k, path in enumerate(paths):
        alone = grainview.open_dataset(path, chunks=None)
        one = run_dataset(ens, k).compute()
        xr.testing.assert_identical(one, alone)
        assert one.attrs.keys() == alone.attrs.keys()
        assert all(type(one.attrs[key]) is type(alone.attrs[key]) for key in alone.attrs)
