"""The methods of solver.contact_solvers on problems solved by hand: the NLGS's hand-made
(W, q, mu) problems, a column of disks on the floor (the weights carried down, an answer whose
NLGS sweeps grow with the column's height) and a random system of bodies; each result's
local-law residual recomputed here from its impulses."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import sparse

from grainview.contract.errors import ParameterError
from solver import contact_solvers
from solver.contact_problem import solve_contact_problem

from .conftest import independent_residual, random_body_problem

NEW_METHODS = ["newton", "pcg"]


def coupled():
    W = np.zeros((4, 4))
    W[np.ix_([0, 2], [0, 2])] = [[2.0, 1.0], [1.0, 2.0]]
    W[1, 1] = W[3, 3] = 2.0
    return W


# (W, q, mu, impulse, velocity): the hand-solved cases of tests/solver/test_contact_problem.py
HAND_MADE = {
    "sticking": (np.eye(2), [-1.0, 0.2], 0.5, [[1.0, -0.2]], [[0.0, 0.0]]),
    "sliding+": (np.eye(2), [-1.0, 3.0], 0.5, [[1.0, -0.5]], [[0.0, 2.5]]),
    "sliding-": (np.eye(2), [-1.0, -3.0], 0.5, [[1.0, 0.5]], [[0.0, -2.5]]),
    "opening": (np.eye(2), [0.5, 1.0], 0.5, [[0.0, 0.0]], [[0.5, 1.0]]),
    "both closed": (coupled(), [-3.0, 0.0, -3.0, 0.0], 0.3, [[1.0, 0.0], [1.0, 0.0]], [[0.0, 0.0], [0.0, 0.0]]),
    "one lifted": (coupled(), [-1.0, 0.0, 1.0, 0.0], 0.3, [[0.5, 0.0], [0.0, 0.0]], [[0.0, 0.0], [1.5, 0.0]]),
}


@pytest.mark.parametrize("method", NEW_METHODS)
@pytest.mark.parametrize("case", sorted(HAND_MADE))
def test_the_hand_made_problems(method, case):
    W, q, mu, impulse, velocity = HAND_MADE[case]
    s = solve_contact_problem(W, q, mu, method=method, tolerance=1e-14)
    np.testing.assert_allclose(s.impulse, impulse, atol=1e-12)
    np.testing.assert_allclose(s.velocity, velocity, atol=1e-12)
    assert s.converged and s.local_law_residual < 1e-12
    assert independent_residual(W, q, mu, s.impulse) == pytest.approx(s.local_law_residual, rel=1e-9, abs=1e-15)


@pytest.mark.parametrize("method", NEW_METHODS)
def test_a_frictional_block_with_normal_tangential_coupling(method):
    # sliding with an n-t coupling: u_n = 0 gives r_n (1.5 - 0.2 * 0.4) = 2, r_t = -0.2 r_n,
    # u_t = 1 + 0.4 r_n - 2 * 0.2 r_n = 1
    W = np.array([[1.5, 0.4], [0.4, 2.0]])
    s = solve_contact_problem(W, [-2.0, 1.0], 0.2, method=method, tolerance=1e-14)
    rn = 2.0 / (1.5 - 0.2 * 0.4)
    np.testing.assert_allclose(s.impulse, [[rn, -0.2 * rn]], rtol=1e-12)
    np.testing.assert_allclose(s.velocity, [[0.0, 1.0]], atol=1e-12)
    assert independent_residual(W, [-2.0, 1.0], 0.2, s.impulse) < 1e-12


def column_of_disks(n, radius=0.5, mass=2.0, g=9.81, h=1e-3):
    """(W, q, mu, impulses): n disks stacked on a floor, all falling at g h at the start of the
    step; point 0 the floor's, point k between disks k-1 and k (normal +y, lever arms +-R).
    The answer: every disk at rest, point k carrying the weight impulse of the n - k disks above."""
    inertia = 0.5 * mass * radius**2
    H = np.zeros((2 * n, 3 * n))  # local velocity (n, t) of each point from the disks' (vx, vy, w)
    for k in range(n):
        H[2 * k, 3 * k + 1] = 1.0  # u_n: vy of the upper disk ...
        H[2 * k + 1, 3 * k] = -1.0  # u_t along t = (-n_y, n_x) = (-1, 0): -vx ...
        H[2 * k + 1, 3 * k + 2] = -radius  # ... and its rotation at its lowest point, lever (0, -R)
        if k:
            H[2 * k, 3 * (k - 1) + 1] = -1.0  # ... minus the lower disk's
            H[2 * k + 1, 3 * (k - 1)] = 1.0
            H[2 * k + 1, 3 * (k - 1) + 2] = -radius  # its highest point, lever (0, +R)
    minv = np.tile([1.0 / mass, 1.0 / mass, 1.0 / inertia], n)
    W = sparse.csr_matrix(H @ np.diag(minv) @ H.T)
    free = np.tile([0.0, -g * h, 0.0], n)
    q = H @ free
    load = mass * g * h * (n - np.arange(n))
    return W, q, np.full(n, 0.4), np.stack([load, np.zeros(n)], -1)


@pytest.mark.parametrize("method", NEW_METHODS)
@pytest.mark.parametrize("n", [5, 60])
def test_a_column_of_disks_carries_its_weight(method, n):
    W, q, mu, load = column_of_disks(n)
    s = solve_contact_problem(W, q, mu, method=method, tolerance=1e-13, max_iterations=5000)
    assert s.converged
    np.testing.assert_allclose(s.impulse, load, rtol=1e-10, atol=1e-14 * load.max())
    np.testing.assert_allclose(s.velocity, 0.0, atol=1e-10)
    assert independent_residual(W, q, mu, s.impulse) < 1e-12


def test_newton_steps_do_not_grow_with_the_column_while_sweeps_do():
    """The column is solved by Newton in the same few steps at 10 and 100 disks; the NLGS's
    sweeps to the same answer grow with the height (a load travelling down point by point)."""
    steps, sweeps = [], []
    for n in (10, 100):
        W, q, mu, load = column_of_disks(n)
        newton = solve_contact_problem(W, q, mu, method="newton", tolerance=1e-12)
        nlgs = solve_contact_problem(W, q, mu, method="nlgs", tolerance=1e-12, max_iterations=200_000)
        assert newton.converged and nlgs.converged
        np.testing.assert_allclose(newton.impulse, load, rtol=1e-9)
        steps.append(newton.iterations)
        sweeps.append(nlgs.iterations)
    assert steps[1] <= steps[0] + 1 and steps[1] <= 4
    assert sweeps[1] > 20 * sweeps[0]


def random_bodies(seed):
    """(W, q, mu) of 12 points between 6 random bodies, mu 0.4 (:func:`conftest.random_body_problem`)."""
    return random_body_problem(seed, bodies=6, points=12, friction=0.4)


@pytest.mark.parametrize("method", NEW_METHODS)
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_random_system_of_bodies_as_the_nlgs_solves_it(method, seed):
    """More points than the bodies' degrees of freedom (W singular): the velocities, unique
    where the impulses are not, agree with the NLGS's to its accuracy."""
    W, q, mu = random_bodies(seed)
    reference = solve_contact_problem(W, q, mu, tolerance=1e-14, max_iterations=200_000)
    s = solve_contact_problem(W, q, mu, method=method, tolerance=1e-11, max_iterations=20_000)
    assert s.converged and s.local_law_residual <= 1e-11
    assert independent_residual(W, q, mu, s.impulse) == pytest.approx(s.local_law_residual, rel=1e-6, abs=1e-15)
    np.testing.assert_allclose(s.velocity, reference.velocity, atol=1e-8 * np.abs(q).max())


@pytest.mark.parametrize("method", contact_solvers.matrix_methods())
def test_every_registered_method_warm_started_at_the_answer_stays_there(method):
    W, q, mu, load = column_of_disks(8)
    s = solve_contact_problem(W, q, mu, method=method, tolerance=1e-12, initial=load)
    np.testing.assert_allclose(s.impulse, load, rtol=1e-12)
    assert s.iterations <= 2 and s.converged


def test_an_unknown_method_or_option_is_named():
    with pytest.raises(ParameterError, match="method='cg': expected one of newton, nlgs, pcg"):
        solve_contact_problem(np.eye(2), [-1.0, 0.0], 0.5, method="cg")
    with pytest.raises(ParameterError, match="method='newton' has no option max_tolerance"):
        solve_contact_problem(np.eye(2), [-1.0, 0.0], 0.5, method="newton", max_tolerance=1e-3)
