"""benchmarks/common.py's problem capture and the words for a row's solver: both read the
solver registry (solver.contact_solvers) and the stepper's public contact_problem()."""

import warnings

import numpy as np
import pytest

from .conftest import load_benchmark as load


@pytest.mark.parametrize("row, words", [
    ({"solver": "anderson", "anderson_period": 2, "stall_sweeps": 200}, "anderson, period 2, stall 200"),
    ({"acceleration": "anderson", "anderson_period": 1, "domains": 2}, "anderson, period 1, 2 domains"),
    ({"acceleration": "off", "anderson_period": 1}, "nlgs"),  # a row written before 'solver'
    ({}, "nlgs"),  # a row written before 'acceleration'
])
def test_way_of_solving_names_the_rows_solver(row, words):
    assert load("common").way_of_solving(row) == words


@pytest.mark.parametrize("solver", ["anderson", "nlgs"])
def test_captured_problems_are_the_steps_own_whatever_the_solver(solver):
    """Three steps captured: each warm start is the previous step's solution at the same
    points, and the steps run as without capture (same positions bit for bit)."""
    import copy

    from solver import compaction_sample, isotropic_compaction

    sim = compaction_sample(30, "pentagon", seed=3, solver=solver)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        isotropic_compaction(sim, max_steps=600, progress=False)
        twin = copy.deepcopy(sim)
        seen = load("common").capture_contact_problems(sim, 3)
        for _ in range(3):
            twin.step()
    np.testing.assert_array_equal(sim.position, twin.position)
    assert len(seen) == 3
    problem, pn, pt, vx, vy, w, options = seen[-1]
    assert options == dict(tolerance=sim.parameters.tolerance, max_tolerance=sim.parameters.max_tolerance,
                           max_iterations=sim.parameters.max_iterations, stall=sim.parameters.stall_sweeps)
    assert pn.size == problem.a.size > 20 and vx.size == sim.n_particles + sim.n_walls
    assert np.any(pn > 0)  # warm-started from the step before
