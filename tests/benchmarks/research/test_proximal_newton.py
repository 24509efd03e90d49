"""benchmarks/research/proximal_newton.py: proximal-point steps around the semi-smooth Newton, on problems
solved by hand (one point open, sticking, sliding; two bodies stacked on a floor) and on random
systems of bodies against the NLGS; each result's residual recomputed here from its impulses."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import sparse

from benchmarks.research import proximal_newton
from grainview.contract.errors import ParameterError
from solver.contact_problem import solve_contact_problem

from ...solver.conftest import independent_residual, random_body_problem


def prox(W, q, mu, tolerance=1e-12, initial=None, max_iterations=100, **options):
    W = sparse.csr_matrix(np.asarray(W, float))
    W.sort_indices()
    q = np.asarray(q, float)
    n = q.size // 2
    mu = np.broadcast_to(np.asarray(mu, float), (n,)).copy()
    initial = np.zeros((n, 2)) if initial is None else np.asarray(initial, float).reshape(n, 2)
    return proximal_newton.solve_recorded(W, q, mu, tolerance, max_iterations, initial, **options)


def stacked(m1=2.0, m2=1.0, g_h=0.5, slip=0.1):
    """Body 1 on a floor, body 2 on body 1 (translations only, dofs v1x, v1y, v2x, v2y): contact A
    floor-body 1, contact B body 1-body 2, normals up. Free velocities: both falling at g h, body
    2 moving sideways at ``slip``. Sticking answer: both bodies stop, so r_B = (m2 g h, -m2 slip)
    and r_A = ((m1 + m2) g h, -m2 slip)."""
    H = np.array([[0.0, 1, 0, 0], [1, 0, 0, 0], [0, -1, 0, 1], [-1, 0, 1, 0]])
    minv = np.diag([1 / m1, 1 / m1, 1 / m2, 1 / m2])
    v_free = np.array([0.0, -g_h, slip, -g_h])
    answer = np.array([[(m1 + m2) * g_h, -m2 * slip], [m2 * g_h, -m2 * slip]])
    return H @ minv @ H.T, H @ v_free, answer


# (W, q, mu, initial, impulse, velocity), solved by hand: W diagonal per point, so r_n = -q_n / W_nn
# when closed, r_t = -q_t / W_tt when that stays in the cone, else -mu r_n sign(u_t)
HAND_MADE = {
    "open": (np.diag([2.0, 4.0]), [0.5, 1.0], 0.5, [[1.0, 0.2]], [[0.0, 0.0]], [[0.5, 1.0]]),
    "sticking": (np.diag([2.0, 4.0]), [-4.0, 1.0], 0.5, [[0.0, 0.0]], [[2.0, -0.25]], [[0.0, 0.0]]),
    "sliding": (np.diag([2.0, 4.0]), [-4.0, 8.0], 0.5, [[0.0, 0.0]], [[2.0, -1.0]], [[0.0, 4.0]]),
    "sliding back": (np.diag([2.0, 4.0]), [-4.0, -8.0], 0.5, [[0.5, 0.0]], [[2.0, 1.0]], [[0.0, -4.0]]),
}


@pytest.mark.parametrize("case", sorted(HAND_MADE))
def test_one_point_solved_by_hand(case):
    W, q, mu, initial, impulse, velocity = HAND_MADE[case]
    s, history = prox(W, q, mu, initial=initial)
    np.testing.assert_allclose(s.impulse, impulse, atol=1e-12)
    np.testing.assert_allclose(s.velocity, velocity, atol=1e-12)
    assert s.converged and s.local_law_residual <= 1e-12
    assert s.iterations == history.outer_steps >= 1
    assert independent_residual(W, q, mu, s.impulse) == pytest.approx(s.local_law_residual, abs=1e-15)


def test_two_bodies_stacked_on_a_floor_carry_their_weights():
    W, q, answer = stacked()
    s, history = prox(W, q, 0.4)
    np.testing.assert_allclose(s.impulse, answer, rtol=1e-11)
    np.testing.assert_allclose(s.velocity, 0.0, atol=1e-11)
    assert s.converged
    assert independent_residual(W, q, 0.4, s.impulse) == pytest.approx(s.local_law_residual, abs=1e-15)
    # the residual history starts at r = 0 (infinite: F != 0 there) and ends at the answer's
    assert history.residuals[0] == np.inf and history.residuals[-1] == pytest.approx(s.local_law_residual)


def test_two_bodies_stacked_slide_where_friction_is_too_weak():
    # mu g h < slip: body 2 slides on body 1 with r_B,t = -mu m2 g h, and body 1, pushed by that
    # impulse alone, sticks to the floor: r_A,t = r_B,t; body 2 keeps slip - mu g h
    W, q, _ = stacked(slip=0.5)
    s, _ = prox(W, q, 0.2)
    np.testing.assert_allclose(s.impulse, [[1.5, -0.1], [0.5, -0.1]], rtol=1e-11)
    np.testing.assert_allclose(s.velocity, [[0.0, 0.0], [0.0, 0.5 - 0.2 * 0.5]], atol=1e-11)


def test_at_the_answer_no_outer_step_is_taken():
    W, q, answer = stacked()
    s, history = prox(W, q, 0.4, initial=answer)
    assert history.outer_steps == 0 and s.iterations == 0 and s.converged
    np.testing.assert_array_equal(s.impulse, answer)


def test_the_weight_follows_the_inner_solves():
    # alpha starts at the given value and is divided by 10 after each converged inner solve
    W, q, answer = stacked()
    _, history = prox(W, q, 0.4, tolerance=1e-14, initial=0.5 * answer, max_iterations=3, alpha=2.0)
    assert history.outer_steps == 3 and all(history.inner_converged)
    np.testing.assert_allclose(history.alphas, [2.0, 0.2, 0.02])
    # each inner solve is given a tenth of the outer error it starts from (here all above 1e-13)
    errors = np.array(history.residuals[:-1])
    assert errors.min() > 1e-12
    np.testing.assert_allclose(history.inner_tolerances, errors / 10)


def random_bodies(seed, bodies, points):
    """(W, q, mu): ``points`` random points between ``bodies`` random rigid bodies, mu 0.3
    (:func:`conftest.random_body_problem`)."""
    return random_body_problem(seed, bodies=bodies, points=points, friction=0.3)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_random_problem_as_the_nlgs_solves_it(seed):
    # 6 points between 8 bodies: W positive definite, so the impulses themselves must agree
    W, q, mu = random_bodies(seed, 8, 6)
    assert np.linalg.eigvalsh(W).min() > 1e-2
    reference = solve_contact_problem(W, q, mu, method="nlgs", tolerance=1e-14, max_iterations=200_000)
    s, history = prox(W, q, mu, tolerance=1e-11)
    assert s.converged and s.local_law_residual <= 1e-11
    assert independent_residual(W, q, mu, s.impulse) == pytest.approx(s.local_law_residual, rel=1e-9, abs=1e-15)
    assert history.residuals[-1] == s.local_law_residual
    scale = np.abs(reference.impulse).max()
    np.testing.assert_allclose(s.impulse, reference.impulse, atol=1e-8 * scale)
    np.testing.assert_allclose(s.velocity, reference.velocity, atol=1e-8 * np.abs(q).max())


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_more_points_than_degrees_of_freedom(seed):
    # 12 points between 6 bodies: W singular; the velocities, unique where the impulses are
    # not, agree with the NLGS's
    W, q, mu = random_bodies(seed, 6, 12)
    reference = solve_contact_problem(W, q, mu, method="nlgs", tolerance=1e-14, max_iterations=200_000)
    s, _ = prox(W, q, mu, tolerance=1e-11, max_iterations=200)
    assert s.converged and s.local_law_residual <= 1e-11
    assert independent_residual(W, q, mu, s.impulse) == pytest.approx(s.local_law_residual, rel=1e-9, abs=1e-15)
    np.testing.assert_allclose(s.velocity, reference.velocity, atol=1e-8 * np.abs(q).max())


def test_factorisations_are_counted():
    W, q, mu = random_bodies(2, 6, 12)
    s, history = prox(W, q, mu, tolerance=1e-11, max_iterations=200)
    # every Newton step factorises at least once; the count is the number of splu calls made
    assert all(lu >= steps for lu, steps in zip(history.factorisations, history.newton_steps))
    assert history.total_factorisations == sum(history.factorisations) >= s.iterations
    # a cap on the factorisations stops the outer steps once reached
    _, capped = prox(W, q, mu, tolerance=1e-30, max_iterations=1000, max_factorisations=5)
    assert capped.total_factorisations >= 5 and sum(capped.factorisations[:-1]) < 5


@pytest.mark.parametrize("option, value, words", [("alpha", 0.0, "alpha=0.0: expected a finite number > 0"),
                                                   ("grow", 0.5, "grow=0.5: expected a finite number >= 1"),
                                                   ("inner_steps", 0, "inner_steps=0: expected an integer >= 1")])
def test_bad_options_are_named(option, value, words):
    W, q, _ = stacked()
    with pytest.raises(ParameterError, match=words):
        prox(W, q, 0.4, **{option: value})


@pytest.mark.parametrize("tolerance, max_iterations, initial, words", [
    (-1.0, 20, np.zeros((2, 2)), "tolerance=-1.0, max_iterations=20: expected a positive tolerance"),  # was: 20 steps
    (1e-10, 0, np.zeros((2, 2)), "max_iterations=0: expected a positive tolerance and at least one outer step"),
    (1e-10, 20, np.zeros(3), r"initial must hold 2 finite impulses per point \(4 values\), got 3"),  # was: numpy's
])
def test_bad_arguments_are_refused_in_one_line(tolerance, max_iterations, initial, words):
    W, q, _ = stacked()
    with pytest.raises(ParameterError, match=words) as caught:
        proximal_newton.solve(sparse.csr_matrix(np.asarray(W, float)), np.asarray(q, float), np.full(2, 0.4),
                              tolerance, max_iterations, initial)
    assert "\n" not in str(caught.value)
