"""Nothing lost (issue 6): a biaxial run killed with SIGKILL at random moments leaves a file
that opens, validates and holds only complete snapshots, each equal to the uninterrupted
run's; resuming such a file gives the uninterrupted run's file byte for byte; Ctrl-C stops
cleanly and prints the command that resumes the run.

The run: 40 pentagons, 300 steps of isotropic compaction, a biaxial test of 128 steps with a
snapshot every 2 steps (65 snapshots). The interrupted runs are subprocesses running
``CHILD``, which prints a line after each snapshot is written, so that the kill moments are
drawn (seeded) in snapshot counts plus a few milliseconds, whatever the machine's speed.
"""

import os
import shlex
import signal
import subprocess
import sys
import time
import warnings
from pathlib import Path

import netCDF4
import numpy as np
import pytest

import grainview
from grainview.contract.errors import FileFormatError
from grainview.contract.schema import VARIABLES
from solver import biaxial_test, compaction_sample, isotropic_compaction
from solver.output import Recorder, point_impulses
from solver.restart import load_state, resume

REPO = Path(__file__).resolve().parents[2]
SNAPSHOTS = 65  # 1 + 128 steps / every 2
TIME_VARIABLES = {name for name, var in VARIABLES.items() if "time" in var.dims} | {"time"}
RUN = dict(n=40, seed=2, compaction_steps=300, strain=0.002, every=2)

CHILD = """
import sys, warnings
warnings.simplefilter("ignore")
from solver import biaxial_test, compaction_sample, isotropic_compaction
from solver.output import Recorder

path, n, seed, compaction_steps, strain, every = sys.argv[1], *map(float, sys.argv[2:])
sim = compaction_sample(int(n), "pentagon", seed=int(seed))
isotropic_compaction(sim, max_steps=int(compaction_steps), progress=False)
write = Recorder.write

def write_and_report(recorder):
    write(recorder)
    print("snapshot", flush=True)

Recorder.write = write_and_report
biaxial_test(sim, path, strain=strain, every=int(every), progress=False)
print("done", flush=True)
"""


def _run_in_process(path):
    sim = compaction_sample(RUN["n"], "pentagon", seed=RUN["seed"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        isotropic_compaction(sim, max_steps=RUN["compaction_steps"], progress=False)
        return biaxial_test(sim, path, strain=RUN["strain"], every=RUN["every"], progress=False)


def _start_child(path):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")]))
    args = [sys.executable, "-c", CHILD, str(path), *(str(RUN[k]) for k in ("n", "seed", "compaction_steps",
                                                                             "strain", "every"))]
    return subprocess.Popen(args, cwd=REPO, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _wait_for_snapshots(child, count):
    """Read the child's report lines until ``count`` snapshots are written (or it ended)."""
    seen = 0
    while seen < count:
        line = child.stdout.readline()
        if not line:
            break
        seen += line.strip() == "snapshot"
    return seen


def _variables(path):
    """Every variable of the file as numpy arrays (complete snapshots only), and the attributes."""
    with grainview.open_dataset(path, chunks=None) as ds:
        return {name: ds[name].values.copy() for name in ds.variables}, dict(ds.attrs)


def _assert_prefix_of(data, reference_data):
    """Each per-snapshot variable of ``data`` equals the first snapshots of the reference's,
    bit for bit; the static ones are equal."""
    n = data["time"].size
    assert data.keys() == reference_data.keys()
    for name, value in data.items():
        expected = reference_data[name]
        np.testing.assert_array_equal(value, expected[:n] if name in TIME_VARIABLES else expected, err_msg=name)


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The uninterrupted run, in this process (it also fills the numba cache for the children)."""
    path = tmp_path_factory.mktemp("reference") / "a.nc"
    steps = _run_in_process(path)
    assert steps == 128
    return path


def test_reference_run_holds_the_restart_state(reference):
    with netCDF4.Dataset(reference) as nc:
        assert nc.data_model == "NETCDF4_CLASSIC"  # a finished run is kept compressed
    data, attrs = _variables(reference)
    assert data["time"].size == SNAPSHOTS
    np.testing.assert_array_equal(data["step"], data["step"][0] + 2 * np.arange(SNAPSHOTS))
    assert attrs["biaxial_steps"] == 128 and attrs["snapshot_every"] == 2
    np.testing.assert_array_equal(attrs["wall_mode"], [0, 2, 1, 0])  # bottom, right (sigma0), top (velocity), left
    np.testing.assert_array_equal(attrs["wall_max_speed_m_s"], np.inf)  # lifted after compaction
    np.testing.assert_array_equal(data["wall_velocity"][:, 2], np.tile([0.0, -0.01], (SNAPSHOTS, 1)))
    np.testing.assert_array_equal(data["wall_velocity"][:, [0, 3]], 0.0)
    # the points' impulses add up to the resultant forces: f = (p_1 + p_2) / h
    h = attrs["solver_time_step"]
    occupied = data["i"] >= 0
    np.testing.assert_allclose(data["normal_impulse"].sum(-1)[occupied] / h, data["fn"][occupied], rtol=1e-12)
    np.testing.assert_allclose(data["tangential_impulse"].sum(-1)[occupied] / h, data["ft"][occupied],
                               rtol=1e-12, atol=1e-12 * np.nanmax(data["fn"]))
    # a simple contact has one point; empty slots carry no impulse
    simple = data["kind"] == 1
    assert np.all(data["normal_impulse"][simple, 1] == 0) and np.all(data["normal_impulse"][~occupied] == 0)
    double_loaded = (data["kind"] == 2) & (data["normal_impulse"] > 0).all(-1)
    assert double_loaded.sum() > 10  # double contacts with both points loaded: the resultant alone would not do


def test_restored_simulation_is_the_state_of_the_last_snapshot(reference, tmp_path):
    """load_state gives back the state the uninterrupted run had at that snapshot, exactly,
    including the warm start (same keys, same impulses)."""
    sim = compaction_sample(RUN["n"], "pentagon", seed=RUN["seed"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        isotropic_compaction(sim, max_steps=RUN["compaction_steps"], progress=False)
        biaxial_test(sim, tmp_path / "b.nc", strain=RUN["strain"], every=RUN["every"], progress=False)
    restored, test = load_state(tmp_path / "b.nc")
    assert test == {"first_step": sim.step_index - 128, "n_steps": 128, "every": 2, "snapshots": SNAPSHOTS}
    assert (restored.time, restored.step_index) == (sim.time, sim.step_index)
    for name in ("position", "angle", "velocity", "angular_velocity", "mass", "inertia", "alert", "skin"):
        np.testing.assert_array_equal(getattr(restored, name), getattr(sim, name), err_msg=name)
    for name in ("point", "velocity", "mode", "stress", "mass", "max_speed", "length_axis", "normal"):
        np.testing.assert_array_equal(getattr(restored.walls, name), getattr(sim.walls, name), err_msg=name)
    assert restored.parameters_dict() == sim.parameters_dict()
    # warm start: every nonzero impulse of the last step under the same key
    nonzero = np.any(sim._impulse != 0, axis=1)
    order = np.argsort(restored._keys)
    where = np.searchsorted(restored._keys[order], sim._keys[nonzero])
    np.testing.assert_array_equal(restored._keys[order][where], sim._keys[nonzero])
    np.testing.assert_array_equal(restored._impulse[order][where], sim._impulse[nonzero])
    assert np.count_nonzero(np.any(restored._impulse != 0, axis=1)) == np.count_nonzero(nonzero)


def test_point_impulses_follow_the_slots_of_pair_contacts():
    """A hand-made last step: three pairs, the second not loaded (not written)."""
    sim = compaction_sample(6, "disk", seed=0)
    sim.points = type("Points", (), dict(pair=np.array([0, 0, 1, 2, 2]), n_pairs=3))()
    sim.impulse = np.array([[1.0, 0.1], [2.0, -0.2], [0.0, 0.0], [3.0, 0.3], [0.0, 0.0]])
    normal, tangential = point_impulses(sim, n_slots=4)
    np.testing.assert_array_equal(normal, [[1.0, 2.0], [3.0, 0.0], [0, 0], [0, 0]])
    np.testing.assert_array_equal(tangential, [[0.1, -0.2], [0.3, 0.0], [0, 0], [0, 0]])


def _check_complete_snapshots(path, reference_data):
    """The file opens, validates, and each snapshot is complete and equal to the reference's."""
    ds = grainview.open_dataset(path, validate=True, chunks=None)
    n_particles, n_walls = ds.sizes["particle"], ds.sizes["wall"]
    count = ds["contact_count"].values
    i, j, kind, fn = ds["i"].values, ds["j"].values, ds["kind"].values, ds["fn"].values
    ds.close()
    slots = np.arange(i.shape[1])[None, :]
    occupied = slots < count[:, None]
    assert np.all((i[occupied] >= 0) & (i[occupied] < n_particles))
    assert np.all((j[occupied] > i[occupied]) & (j[occupied] < n_particles + n_walls))
    assert np.all(np.isin(kind[occupied], [1, 2])) and np.all(fn[occupied] > 0)
    assert np.all(i[~occupied] == -1) and np.all(kind[~occupied] == 0) and np.all(np.isnan(fn[~occupied]))
    data, _ = _variables(path)
    assert np.all(np.diff(data["time"]) > 0)
    assert np.all(data["complete"] == 1)
    _assert_prefix_of(data, reference_data)
    return data["time"].size


def test_sigkill_at_random_moments_leaves_complete_snapshots_and_resumes_bitwise(reference, tmp_path):
    reference_data, _ = _variables(reference)
    reference_bytes = reference.read_bytes()
    rng = np.random.default_rng(6)
    kills = sorted(rng.choice(np.arange(1, SNAPSHOTS - 4), size=4, replace=False))
    for k, reported in enumerate(kills):
        path = tmp_path / f"killed{k}.nc"
        child = _start_child(path)
        try:
            written = _wait_for_snapshots(child, reported)
            time.sleep(rng.uniform(0.0, 0.006))  # a moment within the next snapshot's steps or its writing
            child.send_signal(signal.SIGKILL)
            child.wait(timeout=60)
        finally:
            if child.poll() is None:
                child.kill()
            child.stdout.close()
            stderr = child.stderr.read()
            child.stderr.close()
        assert written == reported, stderr
        assert child.returncode == -signal.SIGKILL
        n = _check_complete_snapshots(path, reference_data)
        assert n >= written, f"a snapshot reported as written is missing ({n} < {written})"
        # resume: the file becomes the uninterrupted run's file, byte for byte
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            steps = resume(path, progress=False)
        assert steps == 128 - 2 * (n - 1)
        assert path.read_bytes() == reference_bytes, f"kill after {reported} snapshots: resumed file differs"


@pytest.mark.parametrize("stop, reason", [(signal.SIGINT, "interrupted"), (signal.SIGTERM, "terminated (SIGTERM)")])
def test_sigint_or_sigterm_stops_cleanly_and_prints_the_resume_command(reference, tmp_path, stop, reason):
    """Ctrl-C, and SIGTERM as a batch scheduler sends it at a wall-time limit."""
    reference_data, _ = _variables(reference)
    path = tmp_path / "interrupted.nc"
    child = _start_child(path)
    try:
        _wait_for_snapshots(child, 20)
        child.send_signal(stop)
        _, stderr = child.communicate(timeout=60)
    finally:
        if child.poll() is None:
            child.kill()
    # the uncaught KeyboardInterrupt ends Python the conventional way, by SIGINT; SIGTERM ends it
    # with the shell's code 143 (solver.interrupt.Terminated), quietly
    assert child.returncode == (-signal.SIGINT if stop == signal.SIGINT else 143), stderr
    assert stop == signal.SIGINT or "Traceback" not in stderr
    assert f"{reason} after step" in stderr
    stopped_at = int(stderr.split(f"{reason} after step ")[1].split(":")[0])
    command = next(line for line in stderr.splitlines() if line.startswith("resume it with:"))
    command = shlex.split(command.split(":", 1)[1])
    assert command == [sys.executable, "-m", "solver.restart", str(path.resolve())]
    assert f"from solver.restart import resume; resume({str(path.resolve())!r})" in stderr
    # closed cleanly: no record beyond the complete snapshots; those are the reference's
    n = _check_complete_snapshots(path, reference_data)
    with netCDF4.Dataset(path) as nc:
        assert nc.dimensions["time"].size == n
        assert nc.data_model == "NETCDF3_64BIT_OFFSET"  # a stopped run is not compressed: it resumes in place
    last_step = int(reference_data["step"][n - 1])
    assert 0 <= stopped_at - last_step < RUN["every"]  # stopped after a whole step, no due snapshot skipped
    assert n < SNAPSHOTS
    # the printed command finishes the run: the uninterrupted run's file, byte for byte
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")]))
    done = subprocess.run(command, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "complete" in done.stdout
    assert path.read_bytes() == reference.read_bytes()


def test_resuming_a_finished_run_changes_nothing(reference, tmp_path):
    path = tmp_path / "finished.nc"
    path.write_bytes(reference.read_bytes())
    assert resume(path, progress=False) == 0
    assert path.read_bytes() == reference.read_bytes()


def test_files_that_cannot_be_resumed_say_why(reference, tmp_path):
    # a file without the restart state (here: another scene, written by the Recorder directly)
    sim = compaction_sample(6, "disk", seed=0)
    other = tmp_path / "rest.nc"
    with Recorder(other, sim, attrs={"scene": "rest"}) as rec:
        rec.write()
    with pytest.raises(FileFormatError, match="lacks .*biaxial_steps"):
        resume(other)
    # a biaxial file stopped before its first snapshot was complete
    empty = tmp_path / "empty.nc"
    empty.write_bytes(reference.read_bytes())
    with netCDF4.Dataset(empty, "a") as nc:
        nc.variables["complete"][:] = 0
    with pytest.raises(FileFormatError, match="no complete snapshot"):
        resume(empty)
    with pytest.raises(FileFormatError, match="no such file"):
        resume(tmp_path / "missing.nc")


CREATE_AND_DIE = """
import os, signal, sys
import grainview.contract.writer as writer
from solver import compaction_sample
from solver.output import Recorder

def die(*args, **kwargs):  # SIGKILL in the middle of creating the file, its header half written
    os.kill(os.getpid(), signal.SIGKILL)

writer.global_attrs = die
Recorder(sys.argv[1], compaction_sample(6, "disk", seed=0))
"""


def test_a_run_killed_while_creating_its_file_leaves_no_partial_file(tmp_path):
    """The file is created under a temporary name and moved into place once its header is
    written: a kill while it is created leaves nothing at ``path`` (no file that a reader or
    a resume would trip over)."""
    path = tmp_path / "new.nc"
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")]))
    child = subprocess.run([sys.executable, "-c", CREATE_AND_DIE, str(path)], cwd=REPO, env=env,
                           capture_output=True, text=True, timeout=120)
    assert child.returncode == -signal.SIGKILL, child.stderr
    assert not path.exists()
    leftovers = sorted(p.name for p in tmp_path.iterdir())  # the hidden temporary file and the lock's note
    assert leftovers == [f".new.nc.{child_pid(leftovers)}.part", ".new.nc.writer"]
    # the next run on the path takes the lock over and removes the dead creator's strays
    with Recorder(path, compaction_sample(6, "disk", seed=0), compress=False) as rec:
        rec.write()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["new.nc"]
    with grainview.open_dataset(path) as ds:
        assert ds.sizes["time"] == 1


def child_pid(names):
    """The process id in the name ``.<name>.<pid>.part`` of a temporary file."""
    return next(n.split(".")[-2] for n in names if n.endswith(".part"))


@pytest.mark.parametrize("method", ["nlgs", "anderson"])
def test_the_solver_is_recorded_and_older_files_load_with_the_solver_they_ran(tmp_path, method):
    """A file records its solver (solver_solver) and loads with it; a file from before that
    attribute names it by solver_acceleration ('off': plain sweeps); one from before both ran
    plain sweeps."""
    from solver import load_sample

    sim = compaction_sample(20, "disk", seed=1, solver=method, anderson_memory=4, anderson_period=3,
                            stall_sweeps=300)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for _ in range(5):
            sim.step()
    path = tmp_path / "sample.nc"
    with Recorder(str(path), sim, attrs={"scene": "isotropic"}) as rec:
        rec.write()
    with netCDF4.Dataset(path) as nc:
        assert nc.getncattr("solver_solver") == method and "solver_acceleration" not in nc.ncattrs()
    loaded = load_sample(path)
    assert loaded.parameters.solver == method and loaded.parameters.anderson_memory == 4
    assert loaded.parameters.anderson_period == 3 and loaded.parameters.stall_sweeps == 300
    with netCDF4.Dataset(path, "a") as nc:  # a file written before the solver's name was recorded
        nc.delncattr("solver_solver")
        nc.setncattr("solver_acceleration", {"nlgs": "off", "anderson": "anderson"}[method])
    assert load_sample(path).parameters.solver == method
    with netCDF4.Dataset(path, "a") as nc:  # a file written before the parameters existed
        nc.delncattr("solver_acceleration")
        nc.delncattr("solver_anderson_memory")
        nc.delncattr("solver_anderson_period")
        nc.delncattr("solver_stall_sweeps")
    older = load_sample(path)
    assert older.parameters.solver == "nlgs" and older.parameters.anderson_memory == 5
    assert older.parameters.anderson_period == 1 and older.parameters.stall_sweeps == 0


def test_a_file_from_before_the_solver_attribute_resumes_bit_for_bit(reference, tmp_path):
    """The reference run (Anderson sweeps) cut short and its solver named the former way
    (solver_acceleration = 'anderson', no solver_solver): resumed, every snapshot is the
    uninterrupted run's, bit for bit."""
    path = _nearly_finished(reference, tmp_path / "run.nc")
    with netCDF4.Dataset(path, "a") as nc:
        assert nc.getncattr("solver_solver") == "anderson"
        nc.delncattr("solver_solver")
        nc.setncattr("solver_acceleration", "anderson")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert resume(path, progress=False) == 6
    data, attrs = _variables(path)
    reference_data, reference_attrs = _variables(reference)
    _assert_prefix_of(data, reference_data)
    assert data["time"].size == SNAPSHOTS
    assert attrs["solver_acceleration"] == "anderson" and "solver_solver" not in attrs


def test_the_resume_command_runs_without_warnings(tmp_path):
    """``python -m solver.restart`` executes its module once (no runpy RuntimeWarning)."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")]))
    done = subprocess.run([sys.executable, "-W", "error::RuntimeWarning", "-m", "solver.restart",
                           str(tmp_path / "missing.nc")], cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 2 and done.stderr.strip().endswith("no such file"), done.stderr
    assert "RuntimeWarning" not in done.stderr


def test_a_full_disk_ends_in_one_line_and_a_valid_resumable_file(tmp_path, monkeypatch):
    """ENOSPC simulated in the middle of a snapshot (netCDF4 reports it as RuntimeError): the
    run stops with an OutputError naming the file and the snapshots kept; the file opens with
    them and the run resumes."""
    import grainview
    from grainview.contract.errors import OutputError
    from grainview.contract.writer import SnapshotWriter

    sim = compaction_sample(RUN["n"], "pentagon", seed=RUN["seed"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        isotropic_compaction(sim, max_steps=RUN["compaction_steps"], progress=False)
    path = tmp_path / "full.nc"
    real = SnapshotWriter._append
    calls = {"n": 0}

    def filling(self, **snapshot):
        calls["n"] += 1
        if calls["n"] == 6:  # the disk fills during the sixth snapshot, after part of it is written
            self._nc.variables["position"][self.n_snapshots] = snapshot["position"]
            raise RuntimeError("NetCDF: HDF error (No space left on device)")
        return real(self, **snapshot)

    monkeypatch.setattr(SnapshotWriter, "_append", filling)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(OutputError, match="could not write snapshot 5 .*keeps its 5 complete snapshots"):
            biaxial_test(sim, path, strain=RUN["strain"], every=RUN["every"], progress=False)
    monkeypatch.setattr(SnapshotWriter, "_append", real)
    ds = grainview.open_dataset(path, chunks=None, validate=True)
    assert ds.sizes["time"] == 5
    ds.close()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert resume(path, progress=False) > 0
    with grainview.open_dataset(path, chunks=None) as done:
        assert done.sizes["time"] == SNAPSHOTS


# --- two resumes, a stopped compression, a file-size limit (issue 34) ----------------------
def _env():
    return dict(os.environ, PYTHONPATH=os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")]))


def _restart(path, *python_args, timeout=120):
    """``python -m solver.restart PATH`` in a subprocess."""
    return subprocess.run([sys.executable, *python_args, "-m", "solver.restart", str(path), "--progress", "off"],
                          cwd=REPO, env=_env(), capture_output=True, text=True, timeout=timeout)


def _nearly_finished(reference, path, missing=3):
    """The reference run as a run killed ``2 * missing`` steps before its end leaves it:
    netCDF-3, its last ``missing`` snapshots not complete."""
    from grainview.contract.writer import decompress_file

    path.write_bytes(reference.read_bytes())
    decompress_file(path)
    with netCDF4.Dataset(path, "a") as nc:
        nc.variables["complete"][-missing:] = 0
    return path


def _finished_uncompressed(reference, path):
    """The reference run as a run stopped during its final compression leaves it."""
    from grainview.contract.writer import decompress_file

    path.write_bytes(reference.read_bytes())
    decompress_file(path)
    return path


PAUSED_RESUME = """
import sys, warnings
warnings.simplefilter("ignore")
import solver.restart as restart

real = restart.load_state

def load_and_wait(path):  # the state read, the test decides when the run goes on
    state = real(path)
    print("read", flush=True)
    sys.stdin.readline()
    return state

restart.load_state = load_and_wait
sys.exit(restart.main([sys.argv[1], "--progress", "off"]))
"""


def test_a_second_resume_of_a_file_being_resumed_is_refused_and_the_file_ends_right(reference, tmp_path):
    """Two resumes of one file: the first, paused between reading the last snapshot and
    appending, holds the file; the second is refused in one line naming it instead of appending
    the same tail (the first would then have appended it again, to a file finished meanwhile)."""
    path = _nearly_finished(reference, tmp_path / "run.nc")
    first = subprocess.Popen([sys.executable, "-c", PAUSED_RESUME, str(path)], cwd=REPO, env=_env(),
                             stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert first.stdout.readline().strip() == "read"
        second = _restart(path)
        out, err = first.communicate("\n", timeout=120)
    finally:
        if first.poll() is None:
            first.kill()
            first.wait()
    assert second.returncode == 2, second.stderr
    assert second.stderr.count("\n") == 1 and "Traceback" not in second.stderr
    assert f"being written by process {first.pid}" in second.stderr
    assert first.returncode == 0, err
    assert out.strip().endswith("resumed for 6 steps, complete")
    assert path.read_bytes() == reference.read_bytes()  # 65 snapshots, the uninterrupted run's bytes
    third = _restart(path)
    assert third.returncode == 0 and third.stdout.strip().endswith("already complete"), third.stderr
    assert path.read_bytes() == reference.read_bytes()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.nc"]


def test_appending_a_state_the_file_has_moved_past_is_refused_and_the_file_untouched(reference, tmp_path):
    """Recorder.append_to checks, under the lock, that the file still ends at the state's step:
    a state read before another process finished (and compressed) the file is refused."""
    path = _nearly_finished(reference, tmp_path / "run.nc")
    sim, _ = load_state(path)  # step of snapshot 61
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert resume(path, progress=False) == 6  # meanwhile another resume finished the run
    with pytest.raises(FileFormatError, match=f"last snapshot is at step {sim.step_index + 6}, not at step "
                                              f"{sim.step_index} .*read the state again"):
        Recorder.append_to(path, sim)
    assert path.read_bytes() == reference.read_bytes()  # neither decompressed nor appended to
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.nc"]  # the lock released


STOPPED_COMPRESSING = """
import os, signal, sys, time, warnings
warnings.simplefilter("ignore")
real = os.replace

def stop_before_rename(src, dst):  # the compressed copy is written, not yet renamed into place
    if str(src).endswith(".convert"):
        os.kill(os.getpid(), getattr(signal, sys.argv[2]))
        time.sleep(10)
    return real(src, dst)

os.replace = stop_before_rename
import solver.restart as restart
sys.exit(restart.main([sys.argv[1], "--progress", "off"]))
"""


@pytest.mark.parametrize("stop", ["SIGKILL", "SIGTERM"])
def test_a_run_stopped_while_compressing_is_compressed_by_the_next_resume(reference, tmp_path, stop):
    """SIGKILL during the final compression leaves the finished run netCDF-3 with the
    compression's temporary file and the lock's note; SIGTERM stops it with one line, cleaned
    up. Either way the file holds the whole run, and the next resume compresses it (removing
    what a killed process left): the uninterrupted run's bytes."""
    reference_data, _ = _variables(reference)
    path = _nearly_finished(reference, tmp_path / "run.nc")
    child = subprocess.run([sys.executable, "-c", STOPPED_COMPRESSING, str(path), stop], cwd=REPO, env=_env(),
                           capture_output=True, text=True, timeout=120)
    assert "Traceback" not in child.stderr
    if stop == "SIGKILL":
        assert child.returncode == -signal.SIGKILL, child.stderr
        left = sorted(p.name for p in tmp_path.iterdir())
        assert left[1:] == [".run.nc.writer", "run.nc"] and left[0].startswith(".run.nc.")
        assert left[0].endswith(".convert"), left
    else:
        assert child.returncode == 143, child.stderr
        assert child.stderr.count("\n") == 1 and "terminated (SIGTERM) while compressing" in child.stderr
        assert "python -m solver.restart" in child.stderr
        assert sorted(p.name for p in tmp_path.iterdir()) == ["run.nc"]
    with netCDF4.Dataset(path) as nc:
        assert nc.data_model == "NETCDF3_64BIT_OFFSET"
    assert _check_complete_snapshots(path, reference_data) == SNAPSHOTS
    done = _restart(path)
    assert done.returncode == 0 and done.stdout.strip().endswith("already complete"), done.stderr
    assert path.read_bytes() == reference.read_bytes()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.nc"]


def test_sigterm_while_a_compressed_run_is_made_netcdf3_again_leaves_it_as_it_was(reference, tmp_path):
    """A resume of a compressed, unfinished run first rewrites it netCDF-3: SIGTERM then stops
    it with one line, the compressed file unchanged and no temporary file left."""
    from grainview.contract.writer import compress_file

    path = _nearly_finished(reference, tmp_path / "run.nc")
    compress_file(path)
    before = path.read_bytes()
    child = subprocess.run([sys.executable, "-c", STOPPED_COMPRESSING, str(path), "SIGTERM"], cwd=REPO, env=_env(),
                           capture_output=True, text=True, timeout=120)
    assert child.returncode == 143 and "Traceback" not in child.stderr, child.stderr
    assert child.stderr.count("\n") == 1 and "terminated (SIGTERM) before the run went on" in child.stderr
    assert path.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.nc"]
    assert _restart(path).returncode == 0
    assert path.read_bytes() == reference.read_bytes()


LIMITED = """
import os, resource, signal, sys
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write beyond the limit fails with EFBIG
limit = int(sys.argv[1])
resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
os.execv(sys.executable, [sys.executable, *sys.argv[2:]])
"""


def _restart_limited(path, limit):
    """``python -m solver.restart PATH`` under a file-size limit (``ulimit -f``) of ``limit`` bytes."""
    return subprocess.run([sys.executable, "-c", LIMITED, str(limit), "-m", "solver.restart", str(path),
                           "--progress", "off"], cwd=REPO, env=_env(), capture_output=True, text=True, timeout=120)


def test_a_file_size_limit_ends_a_resume_in_one_line_and_leaves_the_file_resumable(reference, tmp_path):
    """EFBIG while a finished run is compressed, and while a compressed run is made netCDF-3
    again to be resumed: one line each, the file unchanged and without strays; the run then
    resumes to the uninterrupted run's bytes."""
    from grainview.contract.writer import compress_file

    packed_size = reference.stat().st_size
    finished = _finished_uncompressed(reference, tmp_path / "finished.nc")
    before = finished.read_bytes()
    assert len(before) > 1.5 * packed_size
    done = _restart_limited(finished, packed_size // 2)
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    assert done.stderr.count("\n") == 1
    assert "the run is complete but could not be compressed" in done.stderr
    assert "kept uncompressed" in done.stderr and f"ulimit -f, is {packed_size // 2} bytes" in done.stderr
    assert finished.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["finished.nc"]
    assert _restart(finished).returncode == 0
    assert finished.read_bytes() == reference.read_bytes()

    partial = _nearly_finished(reference, tmp_path / "partial.nc")
    compress_file(partial)
    before = partial.read_bytes()
    done = _restart_limited(partial, len(before) // 2)
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr  # was a segmentation fault
    assert done.stderr.count("\n") == 1 and "could not be rewritten uncompressed" in done.stderr
    assert "the file is unchanged" in done.stderr
    assert partial.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["finished.nc", "partial.nc"]
    assert _restart(partial).returncode == 0
    assert partial.read_bytes() == reference.read_bytes()
