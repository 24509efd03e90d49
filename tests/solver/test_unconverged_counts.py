"""The steps whose NLGS did not converge, as a run's file records them: each snapshot holds how
many steps since the previous snapshot stopped at the sweep cap (or the stall test), and the
largest stopping norm and local-law residual among them (solver.stepper.Unconverged,
solver.output.Recorder). Checked against the stepper's own report of each step: its
ConvergenceWarning and its StepInfo."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import grainview
from grainview.contract.errors import ConvergenceWarning
from solver import compaction_sample, isotropic_compaction
from solver.output import Recorder

EVERY = 4
STEPS = 42


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """40 pentagons compacted for 140 steps, then 42 steps written every 4 (and at the last),
    with a cap of 4 sweeps a step, so that some steps stop at the cap and others converge.
    Returns (file, per recorded step: (StepInfo, whether it warned), steps before the file)."""
    sim = compaction_sample(40, "pentagon", seed=1, max_iterations=4)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConvergenceWarning)
        isotropic_compaction(sim, max_steps=140)
    before = sim.counters["unconverged_steps"]
    path = tmp_path_factory.mktemp("unconverged") / "run.nc"
    steps = []
    with Recorder(path, sim, compress=False) as rec:
        rec.write()
        for k in range(1, STEPS + 1):
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                info = sim.step()
            steps.append((info, any(issubclass(w.category, ConvergenceWarning) for w in caught)))
            if k % EVERY == 0 or k == STEPS:
                rec.write()
    return path, steps, before


def test_each_snapshot_counts_the_unconverged_steps_since_the_previous_one(recorded):
    path, steps, before = recorded
    warned = np.array([w for _, w in steps])
    unconverged = np.array([not info.converged for info, _ in steps])
    np.testing.assert_array_equal(warned, unconverged)  # the stepper's two reports agree
    assert 0 < unconverged.sum() < STEPS and before > 0  # a mix, and some before the file
    ends = [k for k in range(1, STEPS + 1) if k % EVERY == 0 or k == STEPS]
    starts = [0, *ends[:-1]]
    expected = [int(warned[a:b].sum()) for a, b in zip(starts, ends)]
    assert 0 in expected and max(expected) > 0
    with grainview.open_dataset(path, chunks=None, validate=True) as ds:
        counts = ds["nlgs_unconverged_steps"].values
        largest = ds["nlgs_unconverged_residual"].values
        law = ds["nlgs_unconverged_local_law_residual"].values
        attrs = ds["nlgs_unconverged_steps"].attrs
    # the first snapshot: none of the compaction's unconverged steps, which were before the file
    np.testing.assert_array_equal(counts, [0, *expected])
    assert largest[0] == 0.0 and law[0] == 0.0
    for n, (a, b) in enumerate(zip(starts, ends), start=1):
        window = [info for info, _ in steps[a:b] if not info.converged]
        assert largest[n] == max((i.residual for i in window), default=0.0)
        assert law[n] == max((i.local_law_residual for i in window), default=0.0)
    # a step stopped by its cap of 4 sweeps misses the tolerance of its quadratic norm or of its max norm
    assert all(i.iterations == 4 for i, w in steps if w)
    assert attrs["units"] == "1" and "sweep cap" in attrs["long_name"]


def test_a_file_without_the_counts_still_opens_and_validates(recorded, tmp_path):
    path, _, _ = recorded
    with grainview.open_dataset(path, chunks=None) as ds:
        older = ds.drop_vars(["nlgs_unconverged_steps", "nlgs_unconverged_residual",
                              "nlgs_unconverged_local_law_residual"]).load()
    older.to_netcdf(tmp_path / "older.nc")
    with grainview.open_dataset(tmp_path / "older.nc", chunks=None, validate=True) as ds:
        assert "nlgs_unconverged_steps" not in ds and ds.sizes["time"] == 12
