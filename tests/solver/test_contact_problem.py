"""The problem-level entry point: u = W r + q solved by the NLGS, on problems solved by hand."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import sparse

from grainview.contract.errors import ParameterError
from solver import nlgs
from solver.solve_records import Velocities
from solver.contact_problem import solve_contact_problem


def check(solution, impulse, velocity):
    np.testing.assert_allclose(solution.impulse, impulse, atol=1e-12)
    np.testing.assert_allclose(solution.velocity, velocity, atol=1e-12)
    assert solution.converged and solution.local_law_residual < 1e-12


def test_sticking():
    # W = I, q = (-1, 0.2), mu = 0.5: r = -q = (1, -0.2) lies inside the cone, u = 0
    check(solve_contact_problem(np.eye(2), [-1.0, 0.2], 0.5), [[1.0, -0.2]], [[0.0, 0.0]])


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_sliding_at_the_edge_of_the_cone(sign):
    # q_t = +-3 exceeds mu |q_n|: r_n = 1 closes the gap, r_t = -mu r_n sign(u_t), u_t = q_t + r_t
    s = solve_contact_problem(np.eye(2), [-1.0, 3.0 * sign], 0.5)
    check(s, [[1.0, -0.5 * sign]], [[0.0, 2.5 * sign]])


def test_an_opening_contact_carries_nothing():
    check(solve_contact_problem(np.eye(2), [0.5, 1.0], 0.5), [[0.0, 0.0]], [[0.5, 1.0]])


def test_two_coupled_contacts_both_closed():
    # normal coupling [[2, 1], [1, 2]] r_n = (3, 3): r_n = (1, 1); tangents uncoupled and free of load
    W = np.zeros((4, 4))
    W[np.ix_([0, 2], [0, 2])] = [[2.0, 1.0], [1.0, 2.0]]
    W[1, 1] = W[3, 3] = 2.0
    check(solve_contact_problem(sparse.csr_matrix(W), [-3.0, 0.0, -3.0, 0.0], 0.3, tolerance=1e-15),
          [[1.0, 0.0], [1.0, 0.0]], [[0.0, 0.0], [0.0, 0.0]])


def test_two_coupled_contacts_one_lifted_by_the_other():
    # q = (-1, ., +1, .): point 0 closes with r_n = 1/2; it pushes point 1 open, u_n1 = 1 + 1/2
    W = np.zeros((4, 4))
    W[np.ix_([0, 2], [0, 2])] = [[2.0, 1.0], [1.0, 2.0]]
    W[1, 1] = W[3, 3] = 2.0
    check(solve_contact_problem(W, [-1.0, 0.0, 1.0, 0.0], 0.3, tolerance=1e-15),
          [[0.5, 0.0], [0.0, 0.0]], [[0.0, 0.0], [1.5, 0.0]])


def test_a_frictional_block_with_normal_tangential_coupling():
    """W with an off-diagonal n-t term (a point off the line of centres); checked against the
    conditions themselves rather than a hand value."""
    W = np.array([[1.5, 0.4], [0.4, 2.0]])
    s = solve_contact_problem(W, [-2.0, 1.0], 0.2)
    (rn, rt), (un, ut) = s.impulse[0], s.velocity[0]
    assert rn > 0 and un == pytest.approx(0, abs=1e-12)
    assert ut > 0 and rt == pytest.approx(-0.2 * rn, rel=1e-12)  # sliding, friction opposes u_t
    assert s.local_law_residual < 1e-12


def test_same_solution_as_the_time_steppers_nlgs_on_a_random_system():
    """A system of bodies built as the stepper builds it: W assembled from the Delassus data
    of solver.nlgs, solved by both entry points to the same impulses."""
    rng = np.random.default_rng(1)
    bodies, points = 6, 12
    a = rng.integers(0, bodies, points)
    b = (a + rng.integers(1, bodies, points)) % bodies
    angle = rng.uniform(0, 2 * np.pi, points)
    nx, ny = np.cos(angle), np.sin(angle)
    rax, ray, rbx, rby = (rng.uniform(-0.5, 0.5, points) for _ in range(4))
    minv = rng.uniform(0.5, 2.0, bodies)
    iinv = rng.uniform(1.0, 4.0, bodies)
    mu = np.full(points, 0.4)
    v0 = rng.normal(size=(bodies, 3))
    # the linear map r -> u, column by column, with the stepper's own kernels
    problem = nlgs.ContactProblem(a, b, nx, ny, rax, ray, rbx, rby, np.zeros(points), mu, minv, np.zeros(bodies),
                                  minv, iinv)

    def local_velocity(pn, pt):
        velocities = Velocities(v0[:, 0].copy(), v0[:, 1].copy(), v0[:, 2].copy())
        for k in range(points):
            nlgs.apply_impulse_change(k, pn[k], pt[k], problem, velocities)
        return np.array([nlgs.relative_velocity(k, problem, velocities) for k in range(points)]).reshape(-1)

    q = local_velocity(np.zeros(points), np.zeros(points))
    W = np.column_stack([local_velocity(*np.eye(2 * points)[c].reshape(points, 2).T) - q for c in range(2 * points)])
    matrix = solve_contact_problem(W, q, mu, tolerance=1e-13, max_iterations=100_000)
    pn, pt = np.zeros(points), np.zeros(points)
    vx, vy, w = v0[:, 0].copy(), v0[:, 1].copy(), v0[:, 2].copy()
    nlgs.solve_problem(problem, pn, pt, vx, vy, w, tolerance=1e-13, max_tolerance=1e-12, max_iterations=100_000)
    assert matrix.converged and matrix.local_law_residual < 1e-9
    # u = W r + q: the same velocities; and the same impulses where the solution is unique
    np.testing.assert_allclose(matrix.velocity.reshape(-1), local_velocity(pn, pt), atol=1e-8)


@pytest.mark.parametrize("W, q, mu, match", [
    (np.eye(2), [1.0, 2.0, 3.0], 0.5, "2 finite local velocities"),
    (np.eye(4), [1.0, 2.0], 0.5, "shape"),
    (np.diag([0.0, 1.0]), [1.0, 2.0], 0.5, "W_nn > 0"),
    (np.eye(2), [1.0, 2.0], -0.1, "mu"),
])
def test_bad_problems_are_named(W, q, mu, match):
    with pytest.raises(ParameterError, match=match):
        solve_contact_problem(W, q, mu)
