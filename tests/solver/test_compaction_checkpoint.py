"""A compaction stopped or killed part-way resumes from its checkpoint and ends on the state an
uninterrupted compaction reaches, bit for bit (solver.compaction_checkpoint)."""

from __future__ import annotations

import os
import signal

import numpy as np
import pytest

from grainview.contract.errors import FileFormatError
from solver import stepper
from solver.compaction_checkpoint import CompactionCheckpoint, describe
from solver.preparation import preparation, prepare_sample

PREP = preparation("paper", particles=40, shape="pentagon", seed=3)


@pytest.fixture(scope="module")
def uninterrupted():
    return prepare_sample(PREP)


def _same_state(a, b):
    for name in ("position", "angle", "velocity", "angular_velocity", "impulse"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert np.array_equal(a.walls.point, b.walls.point) and np.array_equal(a.walls.velocity, b.walls.velocity)
    assert np.array_equal(a.walls.stress, b.walls.stress) and np.array_equal(a.walls.max_speed, b.walls.max_speed)
    assert (a.time, a.step_index) == (b.time, b.step_index)
    assert a.history.attrs() == b.history.attrs()
    assert np.array_equal(a.history.compaction_stress, b.history.compaction_stress)


def _act_at(monkeypatch, step_index, action):
    """Run ``action()`` right after the step that brings a simulation to ``step_index``."""
    original = stepper.Simulation.step

    def step(self):
        info = original(self)
        if self.step_index == step_index:
            action()
        return info

    monkeypatch.setattr(stepper.Simulation, "step", step)


def _checkpoint(path, every=100):
    return CompactionCheckpoint(path, of=describe(PREP, {}), every_steps=every)


class Killed(Exception):
    """A kill between two checkpoints (nothing of the run's own handling runs)."""


def _kill():
    raise Killed


def test_killed_and_stopped_compactions_resume_bit_for_bit(tmp_path, monkeypatch, uninterrupted):
    path = tmp_path / "pentagons.compaction.nc"
    assert uninterrupted.history.compaction_steps > 400  # the interruptions below fall inside the compaction
    with monkeypatch.context() as m:  # killed at step 250: the checkpoint of step 200 is left
        _act_at(m, 250, _kill)
        with pytest.raises(Killed):
            prepare_sample(PREP, checkpoint=_checkpoint(path))
    assert _checkpoint(path).load()[1].steps == 200
    with monkeypatch.context() as m:  # SIGTERM at step 333: the compaction writes its state and stops
        _act_at(m, 333, lambda: os.kill(os.getpid(), signal.SIGTERM))
        with pytest.raises(SystemExit) as stopped:
            prepare_sample(PREP, checkpoint=_checkpoint(path))
    assert stopped.value.code == 143
    sim, progress = _checkpoint(path).load()
    assert progress.steps == sim.step_index == 333 and len(progress.stresses) == 200
    resumed = prepare_sample(PREP, checkpoint=_checkpoint(path))
    _same_state(resumed, uninterrupted)
    assert os.listdir(tmp_path) == [path.name]  # no temporary file left


def test_a_checkpoint_path_resumes_with_the_default_interval(tmp_path, monkeypatch, uninterrupted):
    path = tmp_path / "c.nc"
    with monkeypatch.context() as m:  # Ctrl-C at step 120: the only checkpoint is the one written on stopping
        _act_at(m, 120, lambda: os.kill(os.getpid(), signal.SIGINT))
        with pytest.raises(KeyboardInterrupt):
            prepare_sample(PREP, checkpoint=path)
    assert _checkpoint(path).load()[1].steps == 120
    _same_state(prepare_sample(PREP, checkpoint=path), uninterrupted)


def test_a_checkpoint_of_another_sample_is_refused(tmp_path, monkeypatch):
    path = tmp_path / "c.nc"
    with monkeypatch.context() as m:
        _act_at(m, 50, lambda: os.kill(os.getpid(), signal.SIGTERM))
        with pytest.raises(SystemExit):
            prepare_sample(PREP, checkpoint=path)
    before = path.read_bytes()
    with pytest.raises(FileFormatError, match="another sample or with other settings"):
        prepare_sample(preparation(PREP, seed=4), checkpoint=path)
    with pytest.raises(FileFormatError, match="another sample or with other settings"):
        prepare_sample(PREP, checkpoint=path, tolerance=1e-4)
    assert path.read_bytes() == before


def test_a_kill_while_a_checkpoint_is_written_keeps_the_previous_one(tmp_path, monkeypatch):
    from solver import output

    path = tmp_path / "c.nc"
    checkpoint = _checkpoint(path, every=100)
    original = output.Recorder.write

    def write(self):
        if self.sim.step_index == 200:
            raise Killed
        return original(self)

    monkeypatch.setattr(output.Recorder, "write", write)
    with pytest.raises(Killed):
        prepare_sample(PREP, checkpoint=checkpoint)
    assert checkpoint.written == 1 and _checkpoint(path).load()[1].steps == 100
    assert os.listdir(tmp_path) == [path.name]


def test_an_ensemble_run_killed_in_its_compaction_resumes_from_its_checkpoint(tmp_path, monkeypatch):
    import netCDF4

    from grainview.app.ensemble import RunSpec, run_one

    spec = RunSpec(shape="pentagon", particles=30, seed=1, strain=0.004, every=10)
    (tmp_path / "reference").mkdir()
    reference = run_one(spec, tmp_path / "reference", progress=False)
    folder = tmp_path / "runs"
    folder.mkdir()
    monkeypatch.setattr(CompactionCheckpoint, "due", lambda self, steps: steps % 100 == 0)
    with monkeypatch.context() as m:
        _act_at(m, 250, _kill)
        with pytest.raises(Killed):
            run_one(spec, folder, progress=False)
    checkpoint = folder / f".{spec.name}.compaction.nc"
    assert CompactionCheckpoint(checkpoint).load()[1].steps == 200 and not (folder / f"{spec.name}.nc").exists()
    result = run_one(spec, folder, progress=False)
    assert result["action"] == "ran" and os.listdir(folder) == [f"{spec.name}.nc"]
    with netCDF4.Dataset(result["path"]) as a, netCDF4.Dataset(reference["path"]) as b:
        for name in ("position", "angle", "velocity", "normal_impulse", "time", "step"):
            assert np.array_equal(a[name][...], b[name][...]), name
        assert a.getncattr("compaction_steps") == b.getncattr("compaction_steps") > 250


def test_what_a_checkpoint_is_of():
    from solver.parameters import Parameters

    assert describe(PREP, {}) == describe(PREP, {"tolerance": Parameters().tolerance})  # a default given
    assert describe(PREP, {}) != describe(PREP, {"tolerance": 1e-4})
    assert describe(PREP, {}) != describe(preparation(PREP, seed=4), {})
