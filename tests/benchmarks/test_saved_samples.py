"""A sample compacted by benchmarks/compaction.py ``--save`` is the one that
benchmarks/archive/time_to_strain.py ``--sample`` shears: the pickle holds the compacted simulation
whole (its steps, its particles, its state), the shear starts from it, and a sample of another
size or shape is refused with one line."""

import os
import pickle

import numpy as np
import pytest

from .conftest import load_benchmark as load


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    compaction = load("compaction")
    path = str(tmp_path_factory.mktemp("samples") / "pentagons.pkl")
    row = compaction.compact("pentagon", 60, 0, "fast", acceleration="anderson", save=path)
    return row, path


def test_the_saved_sample_is_the_compacted_one(saved):
    row, path = saved
    with open(path, "rb") as fh:
        sim, seconds = pickle.load(fh)
    assert not os.path.exists(path + ".part")
    assert row["settled"] and sim.settled
    assert sim.compaction_steps == row["steps"] == sim.step_index
    assert sim.n_particles == 60 and np.all(sim.n_vertices == 5)
    assert seconds == pytest.approx(row["seconds"], abs=0.05)
    lo, hi = sim.walls.box_bounds()
    solid = float((sim.mass / (sim.parameters.density * sim.parameters.thickness)).sum())
    assert solid / float(np.prod(hi - lo)) == pytest.approx(row["solid_fraction"], abs=5e-5)
    assert "step" not in vars(sim)  # the benchmark's counting wrapper is not saved with it


def test_the_shear_starts_from_the_saved_sample(saved, monkeypatch, tmp_path):
    row, path = saved
    time_to_strain = load("archive.time_to_strain")
    monkeypatch.setattr(time_to_strain, "OUT", str(tmp_path))
    result = time_to_strain.measure("pentagon", "anderson", particles=60, until=0.002, sample=path)
    steps = result.pop("per_step")
    assert result["sample"] == "pentagons.pkl"
    assert result["compaction_steps"] == row["steps"]
    assert len(steps["sweeps"]) == len(steps["eps_q"]) == len(steps["seconds"]) == result["shear_steps"] > 0
    assert steps["eps_q"][-1] >= 0.002 > steps["eps_q"][-2]
    assert result["sweeps_median"] == np.median(steps["sweeps"])
    assert os.listdir(tmp_path) == []  # the shear's file is removed


def test_a_sample_of_another_size_is_refused(saved):
    _, path = saved
    time_to_strain = load("archive.time_to_strain")
    with pytest.raises(SystemExit, match="holds 60 particles, expected 80 pentagons"):
        time_to_strain.measure("pentagon", "anderson", particles=80, until=0.002, sample=path)
    with pytest.raises(SystemExit, match="expected 60 disks"):
        time_to_strain.measure("disk", "anderson", particles=60, until=0.002, sample=path)
