"""The stall test of the NLGS stopping rules (solver.nlgs, module docstring): after every W
sweeps, stop when the best quadratic norm so far has fallen by less than 5% since the previous
check. Checked against the rule applied by hand to the norms of plain sweeps, and, for every
solver, against the same solver stopped by its sweep cap at the same sweep."""

from __future__ import annotations

import copy
import warnings

import numpy as np
import pytest

from grainview.contract.errors import ConvergenceWarning
from solver import acceleration, nlgs, parallel_nlgs
from solver.solve_records import Impulses, Velocities

from .conftest import compacted_problem

TIGHT = dict(tolerance=1e-9, max_tolerance=1e-9, max_iterations=20_000)
WINDOW = 200


@pytest.fixture(scope="module")
def problem():
    """The contact problem of a step of 120 pentagons compacted under 10 kPa: at a tolerance of
    1e-9 its sweeps creep for thousands of sweeps, the case the stall test is for."""
    sim, prob, impulse, v_free, omega_free = compacted_problem(3)
    state = [impulse[:, 0].copy(), impulse[:, 1].copy(), v_free[:, 0].copy(), v_free[:, 1].copy(), omega_free.copy()]
    return sim, prob, state

def _copy(state):
    return [s.copy() for s in state]


def expected_stop(norms, window, tolerance, improvement=nlgs.STALL_IMPROVEMENT):
    """The sweep (1-based) at which the rule stops a run with these quadratic norms, or None."""
    best, previous = np.inf, np.inf
    for it, quad in enumerate(norms, start=1):
        best = min(best, quad)
        if it % window == 0 and quad > tolerance:
            if best > (1 - improvement) * previous:
                return it
            previous = best
    return None


def test_plain_sweeps_stop_where_the_rule_says(problem):
    _, prob, state = problem
    # the norms of plain sweeps, one by one
    pn, pt, vx, vy, w = _copy(state)
    impulses, velocities = Impulses(pn, pt), Velocities(vx, vy, w)
    blocks = nlgs.delassus(prob)
    nlgs.velocities_from_impulses(prob, impulses, velocities)
    order = np.arange(prob.a.size)
    norms = []
    for _ in range(6000):
        sums = nlgs.sweep(order, prob, impulses, velocities, blocks)
        norms.append(nlgs.sweep_norms(*sums)[0])
    stop = expected_stop(norms, WINDOW, TIGHT["tolerance"])
    assert stop is not None and 2 * WINDOW <= stop < 6000 and min(norms) > TIGHT["tolerance"]
    got = _copy(state)
    result = nlgs.solve_problem(prob, *got, stall=WINDOW, **TIGHT)
    assert result.iterations == stop
    assert result.residual == pytest.approx(norms[stop - 1], rel=1e-12)
    # without the test the same problem runs on, and the stop is that of the cap at that sweep
    capped = _copy(state)
    nlgs.solve_problem(prob, *capped, **{**TIGHT, "max_iterations": stop})
    for x, y in zip(got, capped):
        np.testing.assert_array_equal(x, y)
    assert nlgs.solve_problem(prob, *_copy(state), **{**TIGHT, "max_iterations": stop + 1}).iterations == stop + 1


def test_a_met_quadratic_norm_never_stalls(problem):
    """With the quadratic norm within its tolerance only the max norm is left to meet: the
    stall test must not stop the sweeps then, whatever the quadratic norm does."""
    _, prob, state = problem
    loose = dict(tolerance=1.0, max_tolerance=1e-9, max_iterations=1000)  # the quadratic norm is met at once
    with_test, without = _copy(state), _copy(state)
    r1 = nlgs.solve_problem(prob, *with_test, stall=WINDOW, **loose)
    r0 = nlgs.solve_problem(prob, *without, **loose)
    assert r1 == r0 and r0.residual <= 1.0
    assert expected_stop([0.5] * 1000, WINDOW, 1.0) is None and expected_stop([0.5] * 1000, WINDOW, 0.1) == 2 * WINDOW


@pytest.mark.parametrize("how", ["domains", "anderson", "anderson-domains"])
def test_every_solver_stalls_like_its_own_sweep_cap(problem, how):
    sim, prob, state = problem
    x = sim.position[:, 0]

    def solve(stall, max_iterations):
        s = _copy(state)
        limits = {**TIGHT, "max_iterations": max_iterations, "stall": stall}
        if how == "domains":
            r = parallel_nlgs.solve_problem_domains(prob, x, *s, domains=2, **limits)
        else:
            r = acceleration.solve_problem_anderson(prob, *s, domains=2 if how == "anderson-domains" else 1, x=x,
                                                    **limits)
        return r, s

    stalled, s1 = solve(WINDOW, TIGHT["max_iterations"])
    assert stalled.iterations % WINDOW == 0 and stalled.iterations < TIGHT["max_iterations"]
    assert stalled.residual > TIGHT["tolerance"]
    capped, s2 = solve(0, stalled.iterations)
    assert capped == stalled
    for a, b in zip(s1, s2):
        np.testing.assert_array_equal(a, b)


def test_a_stalled_step_warns_that_it_stalled(problem):
    sim = copy.deepcopy(problem[0])
    for name, value in {**TIGHT, "stall_sweeps": WINDOW}.items():
        setattr(sim.parameters, name, value)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        info = sim.step()
    messages = [str(w.message) for w in caught if issubclass(w.category, ConvergenceWarning)]
    assert not info.converged and info.iterations % WINDOW == 0 and info.iterations < TIGHT["max_iterations"]
    assert len(messages) == 1 and "stall" in messages[0] and f"after {info.iterations} sweeps" in messages[0]
