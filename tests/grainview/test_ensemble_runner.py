"""The ensemble runner on a dask.distributed LocalCluster of processes: a worker killed in the
middle of a run, the run resumed by the scheduler's retry and equal, snapshot for snapshot, to
an uninterrupted run; open_ensemble equal to each file opened alone; a failing run reported
while the others finish; a changed command line refused before anything runs."""

from __future__ import annotations

import os
import re
import signal

import numpy as np
import pytest
import xarray as xr

import grainview
from grainview.analysis.ensemble import run_dataset
from grainview.contract.errors import ParameterError
from grainview.contract.writer import is_compressed
from grainview.app import ensemble
from grainview.app.ensemble import RunSpec, grid, run_ensemble, run_one

distributed = pytest.importorskip("distributed")

TINY = dict(shapes=("disk",), particles=(40,), strain=0.05, every=25)
"""Runs of a second or two: the workers report progress at most twice a second, and the kill
below needs a report from the middle of the victim's biaxial test."""
COMPARED = ("position", "angle", "velocity", "fn", "ft", "i", "j", "normal_impulse", "wall_position", "step")


@pytest.fixture(scope="module")
def killed(tmp_path_factory):
    """A 2-seed ensemble in which the worker running seed 0 is SIGKILLed once mid-test."""
    folder = tmp_path_factory.mktemp("ensemble")
    specs = grid(seeds=2, **TINY)
    victim = specs[0].name
    kills = []

    def kill_once(event):
        if (not kills and event["run"] == victim and event["stage"] == "biaxial test"
                and 0 < event["n"] < 0.8 * event["total"]):
            kills.append(event["n"])
            os.kill(event["pid"], signal.SIGKILL)

    cluster = ensemble.local_cluster(workers=2)
    with distributed.Client(cluster) as client:
        results = run_ensemble(specs, folder, client=client, progress=False, on_event=kill_once)
    cluster.close()
    return specs, results, kills, folder


def test_killed_worker_run_is_resumed_and_exact(killed, tmp_path):
    specs, results, kills, folder = killed
    assert len(kills) == 1, "the worker was not killed mid-test"
    assert [r.get("error") for r in results] == [None, None]
    assert results[0]["action"] == "resumed" and results[1]["action"] == "ran"
    reference = run_one(specs[0], tmp_path)  # the same run, uninterrupted, in this process
    assert reference["action"] == "ran"
    resumed = grainview.open_dataset(results[0]["path"], chunks=None)
    alone = grainview.open_dataset(reference["path"], chunks=None)
    assert resumed.sizes == alone.sizes
    for name in COMPARED:
        np.testing.assert_array_equal(resumed[name].values, alone[name].values, err_msg=name)
    # finished runs are kept compressed, the resumed one too; compress=False keeps netCDF-3
    assert all(is_compressed(r["path"]) for r in results) and is_compressed(reference["path"])
    (tmp_path / "plain").mkdir()
    plain = run_one(specs[0], tmp_path / "plain", compress=False)
    assert not is_compressed(plain["path"])
    with grainview.open_dataset(plain["path"], chunks=None) as ds:
        np.testing.assert_array_equal(ds["position"].values, alone["position"].values)


def test_open_ensemble_equals_each_file(killed):
    specs, results, _, folder = killed
    ens = grainview.open_ensemble(folder)
    assert list(ens["run"].values) == sorted(s.name for s in specs)
    assert list(ens["seed"].values) == [0, 1] and set(ens["group"].values) == {"disk"}
    q = ens.grain.stress_invariants()["q_over_p"].compute()
    for k, name in enumerate(ens["run"].values):
        alone = grainview.open_dataset(folder / f"{name}.nc")
        xr.testing.assert_identical(run_dataset(ens, k).compute(), alone.compute())
        expected = alone.grain.stress_invariants()["q_over_p"].values
        np.testing.assert_array_equal(q.isel(run=k, time=slice(0, expected.size)).values, expected)


def test_rerun_skips_finished_and_refuses_changed_settings(killed):
    specs, _, _, folder = killed
    again = run_ensemble(specs, folder, workers=1, progress=False)
    assert [r["action"] for r in again] == ["finished already"] * 2
    changed = grid(seeds=1, **{**TINY, "strain": 0.06})
    with pytest.raises(FileExistsError, match="strain_target"):
        run_ensemble(changed, folder, workers=1, progress=False)
    redo = run_ensemble(changed, folder, workers=1, progress=False, overwrite=True)
    assert [r["action"] for r in redo] == ["ran"]  # removed first, then run from its deposit
    assert grainview.open_dataset(redo[0]["path"]).attrs["strain_target"] == 0.06


def test_failed_run_reported_others_finish(tmp_path, monkeypatch):
    """A run that raises is reported in one line; the other finishes; a second call runs only
    the failed one (a thread in this process, so that the failure can be injected; one thread:
    two would write netCDF files at once, which HDF5 does not support and which crashed this
    test once, and such a worker is refused)."""
    specs = grid(seeds=2, **{**TINY, "strain": 0.01})
    real = ensemble.run_one

    def flaky(spec, folder, **kw):
        if spec.seed == 1:
            raise RuntimeError("disk full (simulated)")
        return real(spec, folder, **kw)

    monkeypatch.setattr(ensemble, "run_one", flaky)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None) as cl, \
            distributed.Client(cl) as client:
        with pytest.raises(ParameterError, match="one thread per worker"):
            run_ensemble(specs, tmp_path, client=client, progress=False)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None) as cl, \
            distributed.Client(cl) as client:
        lines = []
        first = run_ensemble(specs, tmp_path, client=client, progress=False, log=lines.append)
        assert first[0]["action"] == "ran" and first[1]["error"] == "RuntimeError: disk full (simulated)"
        assert any("FAILED (RuntimeError: disk full (simulated))" in line for line in lines)
        monkeypatch.setattr(ensemble, "run_one", real)
        second = run_ensemble(specs, tmp_path, client=client, progress=False)
    assert [r["action"] for r in second] == ["finished already", "ran"]


def test_specs_are_checked():
    with pytest.raises(ParameterError, match="strain"):
        RunSpec(strain=1.5).validate()
    with pytest.raises(ParameterError, match="seed"):
        RunSpec(seed=-1).validate()
    with pytest.raises(ParameterError, match="time_step=0.0005 s: the top wall of the test"):
        RunSpec(velocity=100.0).validate()  # 5 cm per step against radii of 1.25 cm
    with pytest.raises(ParameterError, match="same run twice"):
        grid(seeds=(0, 0))
    with pytest.raises(ParameterError, match="workers"):
        ensemble.local_cluster(workers=0)
    assert RunSpec(shape="disk", particles=40, friction=0.2, seed=3).name == "disk_n40_mu0.2_s3"


def test_seeds_count_from_the_first_seed_and_none_is_refused():
    specs = grid(seeds=3, first_seed=5, shapes=("disk",), particles=(12,))
    assert [s.seed for s in specs] == [5, 6, 7]
    assert [s.seed for s in grid(seeds=(2, 9), shapes=("disk",), particles=(12,))] == [2, 9]
    for seeds in (0, -2, ()):
        with pytest.raises(ParameterError, match=r"^seeds=.*: expected at least 1 seed$"):
            grid(seeds=seeds)


@pytest.mark.parametrize("scheduler, workers, words", [
    (None, 0, "workers=0: expected at least 1 worker process"),
    (None, 1.5, "workers=1.5: expected at least 1 worker process"),
    ("tcp://x:1", 2, "workers= applies to the local cluster only"),
])
def test_the_cluster_is_checked_once_before_any_work(tmp_path, scheduler, workers, words):
    """run_ensemble refuses an impossible cluster before it touches the folder (the command
    line calls the same check before it prints anything)."""
    folder = tmp_path / "runs"
    with pytest.raises(ParameterError, match=re.escape(words)):
        ensemble.check_cluster(scheduler, workers)
    with pytest.raises(ParameterError, match=re.escape(words)):
        ensemble.run_ensemble(grid(seeds=1, **TINY), folder, scheduler=scheduler, workers=workers)
    assert not folder.exists()
    ensemble.check_cluster("tcp://x:1", None)
    ensemble.check_cluster(None, 2)


def test_a_finished_run_whose_compression_was_stopped_is_compressed_on_rerun(killed, tmp_path):
    """A worker killed while compressing a finished run leaves it netCDF-3, with the
    compression's temporary file and the lock's note: running the ensemble again finds it
    finished, compresses it and removes what the dead worker left."""
    import subprocess
    import sys

    from grainview.contract.writer import decompress_file

    specs, results, _, _ = killed
    path = tmp_path / os.path.basename(results[1]["path"])
    path.write_bytes(open(results[1]["path"], "rb").read())
    decompress_file(path)
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    stray = tmp_path / f".{path.name}.{int(dead.stdout)}.convert"
    stray.write_bytes(b"half a compressed copy")
    (tmp_path / f".{path.name}.writer").write_text(f"process {int(dead.stdout)} on a machine")
    result = run_one(specs[1], tmp_path)
    assert result["action"] == "finished already" and result["steps"] == 0
    assert is_compressed(path)
    assert sorted(p.name for p in tmp_path.iterdir()) == [path.name]
    with grainview.open_dataset(path, chunks=None) as ds, \
            grainview.open_dataset(results[1]["path"], chunks=None) as done:
        xr.testing.assert_identical(ds, done)
