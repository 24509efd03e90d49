"""Body-space ADMM (benchmarks/research/body_admm.py) on problems whose answer is known by hand, and on a
random problem against the NLGS."""

import numpy as np
import pytest
from scipy import sparse

from benchmarks.research import body_admm
from grainview.contract.errors import ParameterError
from solver.contact_problem import solve_contact_problem
from solver.contact_solution import contact_solution

# One particle (body 0: m = 2 kg, I = 0.5 kg m2) on a floor (body 1: a wall, M^-1 = 0), one
# point under its centre: n = (0, 1), t = (-1, 0), lever arm (0, -R), R = 0.5 m. Rows of H
# (module docstring of solver.matrix_form): normal (0, 1, 0) on the particle and (0, -1, 0) on
# the wall; tangential (-1, 0, -R) on the particle, (1, 0, 0) on the wall. So W_nn = 1/m = 0.5,
# W_tt = 1/m + R^2/I = 1, W_nt = 0, and q = H v_free + (bias, 0).
R = 0.5
H_ONE = sparse.csr_matrix(np.array([[0.0, 1.0, 0.0, 0.0, -1.0, 0.0],
                                    [-1.0, 0.0, -R, 1.0, 0.0, 0.0]]))
MINV_ONE = sparse.diags([0.5, 0.5, 2.0, 0.0, 0.0, 0.0]).tocsr()


def _solve(H, minv, v_free, bias, mu, initial=None, **options):
    options.setdefault("tolerance", 1e-11)
    return body_admm.solve(H, minv, np.asarray(v_free, float), np.atleast_1d(np.asarray(bias, float)), mu,
                           max_iterations=5000, initial=initial, **options)


@pytest.mark.parametrize("v_free, bias, mu, expected, velocity", [
    # open: the particle leaves the floor, which rises slower: u_n = 1 - 0.2 > 0, no impulse
    ([0.0, 1.0, 0.0, 0.0, 0.2, 0.0], 0.0, 0.5, [0.0, 0.0], [0.8, 0.0]),
    # sticking: the floor rises at 3 m/s, shift 0.5: q = (-2.5, -0.1); r = (2.5 / 0.5, 0.1 / 1),
    # |r_t| = 0.1 <= 0.5 * 5
    ([0.1, 0.0, 0.0, 0.0, 3.0, 0.0], 0.5, 0.5, [5.0, 0.1], [0.0, 0.0]),
    # sliding: q = (-2, 3); sticking would need r_t = -3 beyond mu r_n = 2, so r_t = -2 and
    # u_t = W_tt r_t + q_t = 1 > 0, opposite to r_t
    ([-3.0, -2.0, 0.0, 0.0, 0.0, 0.0], 0.0, 0.5, [4.0, -2.0], [0.0, 1.0]),
])
def test_a_particle_on_a_floor_gets_its_hand_computed_impulse(v_free, bias, mu, expected, velocity):
    result = _solve(H_ONE, MINV_ONE, v_free, bias, mu)
    assert result.converged and result.local_law_residual <= 1e-11
    np.testing.assert_allclose(result.impulse[0], expected, atol=1e-9)
    np.testing.assert_allclose(result.velocity[0], velocity, atol=1e-9)


def test_two_stacked_bodies_one_sliding_on_the_other():
    # bodies 0 (1 kg) and 1 (2 kg) stacked on a floor (body 2), rotations held (I^-1 = 0),
    # g h = 1 m/s downwards; the top one thrown at 5 m/s along x, mu = 0.3 everywhere.
    # Normal: r_n = (m0 + m1) g h = 3 under body 0, m1 g h = 2 between the two. The top slides
    # (u_t = -(v1x - v0x) < 0): r_t = +mu 2 = 0.6, v1x = 5 - 0.6 / 2 = 4.7; body 0 then sticks on
    # the floor with r_t = 0.6 <= 0.3 * 3.
    rows = [
        # point 0: floor (a = 2) under body 0 (b = 0), n = (0, 1), t = (-1, 0)
        {(0, 1): 1.0, (2, 1): -1.0}, {(0, 0): -1.0, (2, 0): 1.0},
        # point 1: body 0 (a) under body 1 (b)
        {(1, 1): 1.0, (0, 1): -1.0}, {(1, 0): -1.0, (0, 0): 1.0},
    ]
    H = np.zeros((4, 9))
    for i, row in enumerate(rows):
        for (body, dof), value in row.items():
            H[i, 3 * body + dof] = value
    H[1, 2], H[3, 2], H[3, 5] = -0.3, 0.3, -0.4  # lever arms on the rotations, which cannot move
    minv = sparse.diags([1.0, 1.0, 0.0, 0.5, 0.5, 0.0, 0.0, 0.0, 0.0]).tocsr()
    v_free = np.array([0.0, -1.0, 0.0, 5.0, -1.0, 0.0, 0.0, 0.0, 0.0])
    result = _solve(sparse.csr_matrix(H), minv, v_free, np.zeros(2), 0.3)
    assert result.converged
    np.testing.assert_allclose(result.impulse, [[3.0, 0.6], [2.0, 0.6]], atol=1e-9)
    np.testing.assert_allclose(result.velocity, [[0.0, 0.0], [0.0, -4.7]], atol=1e-9)


def _random_problem(seed, bodies=6, points=9):
    """A random 2D multi-body problem: ``bodies`` free bodies and one fixed wall (the last),
    ``points`` points between random pairs with random normals and lever arms."""
    rng = np.random.default_rng(seed)
    a = rng.integers(0, bodies + 1, points)
    b = (a + rng.integers(1, bodies + 1, points)) % (bodies + 1)
    angle = rng.uniform(0, 2 * np.pi, points)
    n = np.stack([np.cos(angle), np.sin(angle)], -1)
    t = np.stack([-n[:, 1], n[:, 0]], -1)
    lever_a, lever_b = rng.uniform(-0.5, 0.5, (points, 2)), rng.uniform(-0.5, 0.5, (points, 2))
    H = np.zeros((2 * points, 3 * (bodies + 1)))
    for k in range(points):
        for e, vector in enumerate((n[k], t[k])):
            for body, lever, sign in ((b[k], lever_b[k], 1.0), (a[k], lever_a[k], -1.0)):
                H[2 * k + e, 3 * body:3 * body + 3] += sign * np.array(
                    [vector[0], vector[1], lever[0] * vector[1] - lever[1] * vector[0]])
    mass = rng.uniform(0.5, 2.0, bodies)
    minv = sparse.diags(np.concatenate([np.stack([1 / mass, 1 / mass, 1 / (0.1 * mass)], -1).ravel(),
                                        np.zeros(3)])).tocsr()
    v_free = np.concatenate([rng.normal(0, 1, 3 * bodies), [0.2, -0.1, 0.0]])
    bias = rng.uniform(-0.2, 0.2, points)
    return sparse.csr_matrix(H), minv, v_free, bias, np.full(points, 0.3)


def test_a_random_problem_matches_the_nlgs_and_reports_its_true_residual():
    H, minv, v_free, bias, mu = _random_problem(3)
    W = (H @ minv @ H.T).tocsr()
    q = H @ v_free
    q[0::2] += bias
    reference = solve_contact_problem(W, q, mu, method="nlgs", tolerance=1e-13, max_iterations=200_000)
    assert reference.local_law_residual < 1e-9
    states = set()
    for r, u, m in zip(reference.impulse, reference.velocity, mu):
        states.add("open" if r[0] == 0 else "sliding" if abs(abs(r[1]) - m * r[0]) < 1e-9 * r[0] else "sticking")
    assert len(states) >= 2  # the problem mixes the laws' cases
    record = {}
    result = _solve(H, minv, v_free, bias, mu, tolerance=1e-10, record=record)
    assert result.converged and result.iterations > 5  # the ADMM iterated
    np.testing.assert_allclose(result.velocity, reference.velocity, atol=1e-6 * np.abs(reference.velocity).max())
    recomputed = contact_solution(W, q, mu, result.impulse, 0, True)
    assert result.local_law_residual == pytest.approx(recomputed.local_law_residual, rel=1e-9, abs=1e-15)
    np.testing.assert_allclose(result.velocity, recomputed.velocity, atol=1e-12)
    assert record["factorisations"] >= 1 and record["checks"][-1][1] <= 1e-10


def test_the_warm_start_is_kept_when_it_solves_the_problem():
    record = {}
    result = _solve(H_ONE, MINV_ONE, [-3.0, -2.0, 0.0, 0.0, 0.0, 0.0], 0.0, 0.5, initial=[[4.0, -2.0]],
                    record=record)
    assert result.iterations == 0 and result.converged and record["factorisations"] == 0


def test_the_dual_cone_projection_is_moreaus_complement_of_the_cones():
    # K* of mu = 0.5 is {|t| <= 2 n}, its edges along e = (1, +-2) / sqrt(5): (1, 1) is inside and
    # stays; (-1, 0.1) is in -K (|t| <= 0.5 |n|) and goes to 0; (0, 1) goes to (w . e) e =
    # (2 / 5) (1, 2); (1, -3) to (7 / 5) (1, -2).
    wn, wt, mu = np.array([1.0, -1.0, 0.0, 1.0]), np.array([1.0, 0.1, 1.0, -3.0]), np.full(4, 0.5)
    zn, zt = np.empty(4), np.empty(4)
    body_admm.dual_cone_projection(wn, wt, mu, zn, zt)
    expected = [[1.0, 1.0], [0.0, 0.0], [0.4, 0.8], [1.4, -2.8]]
    np.testing.assert_allclose(np.stack([zn, zt], -1), expected, atol=1e-12)


@pytest.mark.parametrize("change, words", [
    (dict(minv=sparse.eye(5).tocsr()), "minv has shape (5, 5): expected (6, 6)"),
    (dict(bias=np.zeros(2)), "bias 2: expected 6 (3 per body) and 1 (1 per point)"),
    (dict(minv=sparse.csr_matrix(np.eye(6) + 0.5 * (np.eye(6, k=3) + np.eye(6, k=-3)))), "block diagonal"),
    (dict(rho=0.0), "rho=0.0: expected a finite penalty > 0"),  # was: no error, the start returned
    (dict(rho=-1.0), "rho=-1.0: expected a finite penalty > 0"),  # was: SuperLU's 'exactly singular'
    (dict(initial=np.zeros(3)), "initial must hold 2 finite impulses per point (2 values), got 3"),
    (dict(fixed_shift=np.zeros(3)), "fixed_shift must hold one finite shift per point (1 values), got 3"),
    (dict(check_every=0), "expected check_every >= 1"),  # was: never checked, the start returned
])
def test_bad_input_is_refused_in_one_line(change, words):
    arguments = dict(H=H_ONE, minv=MINV_ONE, v_free=np.zeros(6), bias=np.zeros(1), mu=0.5)
    arguments.update(change)
    with pytest.raises(ParameterError) as caught:
        body_admm.solve(**arguments)
    assert words in str(caught.value) and "\n" not in str(caught.value)
