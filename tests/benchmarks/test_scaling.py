"""benchmarks/solver_bench/scaling.py (section a of RESULTS.md): the timed window is the shear
itself, step for step, and its counts add up."""

import os

import numpy as np
import pytest

from .conftest import load_benchmark as load, load_solver_bench, shear_sweeps


@pytest.fixture(scope="module")
def scaling():
    return load_solver_bench("scaling")


@pytest.mark.parametrize("domains", [1, 2])
def test_the_window_counts_add_up(scaling, pentagon_sample, domains):
    r = scaling.dense_case(pentagon_sample, domains, 5, 12)
    assert r["n"] == 60 and r["domains"] == domains
    assert len(r["seconds"]) == len(r["sweeps"]) == len(r["points"]) == 12
    # the simulation's meters cover the timed window only
    assert r["counters"]["steps"] == 12
    assert r["counters"]["sweeps"] == r["sweeps"].sum()
    assert np.all(r["seconds"] > 0) and r["timings"]["solve"] < r["seconds"].sum()
    assert np.all(r["law"] >= 0) and r["converged"].dtype == bool


def test_the_timed_window_is_the_shear(scaling, pentagon_sample):
    """Steps 6-17 of the measured serial shear take the sweeps of the same steps of an
    unmeasured shear from the same sample (the measure times the steps, it does not change them)."""
    sim, _ = load("common").load_sample(pentagon_sample)
    sweeps = shear_sweeps(sim, 17)
    r = scaling.dense_case(pentagon_sample, 1, 5, 12)
    np.testing.assert_array_equal(r["sweeps"], sweeps[5:])


def test_sample_path_names_shape_and_size(scaling):
    path = scaling.sample_path("disk", 14400)
    assert os.path.basename(path) == "disk_14400_fast.pkl"
    assert os.path.basename(os.path.dirname(path)) == "samples"
