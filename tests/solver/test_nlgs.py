"""The NLGS contact solver: the exact local solver against the Signorini-Coulomb conditions,
and whole sweeps against a brute-force (enumerated active sets) solution of the frictionless
contact problem built with plain numpy."""

import itertools

import numpy as np
import pytest

from solver import nlgs
from solver.solve_records import Impulses, Limits, Velocities


def _check_local(wnn, wnt, wtt, ufn, uft, bias, mu, pn, pt):
    """The Signorini-Coulomb conditions of one point, to round-off."""
    scale = abs(ufn) + abs(uft) + abs(bias)
    un = ufn + bias + wnn * pn + wnt * pt
    ut = uft + wnt * pn + wtt * pt
    tol = 1e-10 * scale
    assert pn >= 0.0
    assert un >= -tol
    assert pn * un <= tol * max(pn, 1e-300)  # complementarity
    assert abs(pt) <= mu * pn * (1 + 1e-12) + 1e-300
    if abs(pt) < mu * pn * (1 - 1e-9):  # strictly inside the cone: sticking
        assert abs(ut) <= tol
    elif pn > 0 and abs(ut) > tol:  # sliding: friction opposes the slip, at the cone's edge
        assert pt * ut <= 0 and (mu == 0 or pt * ut < 0)
        assert abs(pt) == pytest.approx(mu * pn, rel=1e-12)


def test_local_solver_satisfies_signorini_and_coulomb_on_random_problems():
    rng = np.random.default_rng(1)
    cases = 0
    for _ in range(3000):
        a = rng.normal(size=(2, 2))
        w = a @ a.T + 0.05 * np.eye(2)  # symmetric positive definite Delassus block
        ufn, uft = rng.normal(size=2)
        bias = max(0.0, rng.normal()) * rng.integers(0, 2)
        mu = rng.choice([0.0, 0.1, 0.4, 1.0])
        pn, pt = nlgs.local_solve(ufn, uft, bias, w[0, 0], w[0, 1], w[1, 1], mu)
        _check_local(w[0, 0], w[0, 1], w[1, 1], ufn, uft, bias, mu, pn, pt)
        cases += pn > 0
    assert cases > 1000  # most cases are in contact: the test exercised stick and slip


def test_local_solver_hand_cases():
    m, h, g = 2.0, 1e-3, 9.81
    # a disk resting on a floor: W_nn = 1/m, free normal velocity -g h -> impulse m g h
    pn, pt = nlgs.local_solve(-g * h, 0.0, 0.0, 1 / m, 0.0, 1 / m + 4 / m, 0.4)
    assert pn == pytest.approx(m * g * h, rel=1e-15) and pt == 0.0
    # an open gap that the free motion does not close: no impulse
    assert nlgs.local_solve(-1.0, 0.3, 2.0, 1.0, 0.0, 1.0, 0.4) == (0.0, 0.0)
    # sliding block (W = I/m, no coupling): p_n = m |u_n|, p_t = -mu p_n sign(u_t)
    pn, pt = nlgs.local_solve(-1.0, 3.0, 0.0, 1 / m, 0.0, 1 / m, 0.5)
    assert pn == pytest.approx(m, rel=1e-15) and pt == pytest.approx(-0.5 * m, rel=1e-15)
    # sticking: the tangential velocity is cancelled inside the cone
    pn, pt = nlgs.local_solve(-1.0, 0.2, 0.0, 1 / m, 0.0, 1 / m, 0.5)
    assert pn == pytest.approx(m) and pt == pytest.approx(-0.2 * m)


def _random_frictionless_system(rng):
    """Three disks and a fixed body (index 3), four contact points with random unit normals
    and lever arms; returns the arrays nlgs.solve takes and the dense numpy Delassus matrix."""
    n_bodies = 4
    a = np.array([0, 1, 0, 2])
    b = np.array([1, 2, 3, 3])
    angle = rng.uniform(0, 2 * np.pi, 4)
    nx, ny = np.cos(angle), np.sin(angle)
    ra = rng.normal(scale=0.01, size=(4, 2))
    rb = rng.normal(scale=0.01, size=(4, 2))
    inv_mass = np.array([1 / 2.0, 1 / 1.5, 1 / 3.0, 0.0])
    inv_inertia = np.array([1 / 1e-4, 1 / 2e-4, 1 / 3e-4, 0.0])
    # H: (points, 3 * bodies) maps body velocities (vx, vy, w) to the normal relative velocity
    H = np.zeros((4, 3 * n_bodies))
    for k in range(4):
        n = np.array([nx[k], ny[k]])
        for body, r, sign in ((b[k], rb[k], 1.0), (a[k], ra[k], -1.0)):
            H[k, 3 * body:3 * body + 2] += sign * n
            H[k, 3 * body + 2] += sign * (r[0] * n[1] - r[1] * n[0])
    minv = np.diag(np.repeat(np.stack([inv_mass, inv_mass, inv_inertia], -1), 1, axis=0).reshape(-1))
    W = H @ minv @ H.T
    return a, b, nx, ny, ra, rb, inv_mass, inv_inertia, H, minv, W


def _lcp_by_enumeration(W, q):
    """p >= 0, u = q + W p >= 0, p.u = 0, by trying every active set (plain numpy)."""
    m = len(q)
    for active in itertools.product([False, True], repeat=m):
        A = np.array(active)
        p = np.zeros(m)
        if A.any():
            p[A] = np.linalg.solve(W[np.ix_(A, A)], -q[A])
        u = q + W @ p
        if np.all(p >= -1e-12) and np.all(u >= -1e-12):
            return p
    raise AssertionError("no solution found")


@pytest.mark.parametrize("seed", range(5))
def test_sweeps_match_the_enumerated_frictionless_solution(seed):
    rng = np.random.default_rng(seed)
    a, b, nx, ny, ra, rb, inv_mass, inv_inertia, H, minv, W = _random_frictionless_system(rng)
    v_free = rng.normal(scale=0.1, size=(4, 3))
    v_free[3] = 0.0
    bias = np.array([0.0, 0.05, 0.0, 0.0])
    q = H @ v_free.reshape(-1) + bias
    expected = _lcp_by_enumeration(W, q)
    vx, vy, w = v_free[:, 0].copy(), v_free[:, 1].copy(), v_free[:, 2].copy()
    pn, pt = np.zeros(4), np.zeros(4)
    problem = nlgs.ContactProblem(a, b, nx, ny, ra[:, 0].copy(), ra[:, 1].copy(), rb[:, 0].copy(), rb[:, 1].copy(),
                                  bias, np.zeros(4), inv_mass, np.zeros(4), inv_mass.copy(), inv_inertia)
    it, quad, worst = nlgs.solve_problem(problem, pn, pt, vx, vy, w, tolerance=1e-14, max_tolerance=1e-14,
                                         max_iterations=100_000)
    assert quad <= 1e-14 and worst <= 1e-14 and it < 100_000
    np.testing.assert_allclose(pn, expected, rtol=1e-8, atol=1e-10 * np.abs(expected).max())
    assert np.all(pt == 0.0)
    # the end velocities are the free velocities plus M^-1 H^T p
    v_end = v_free.reshape(-1) + minv @ H.T @ pn
    np.testing.assert_allclose(np.stack([vx, vy, w], -1).reshape(-1), v_end, rtol=1e-9, atol=1e-12)


def test_warm_start_at_the_solution_converges_in_one_sweep():
    rng = np.random.default_rng(7)
    a, b, nx, ny, ra, rb, inv_mass, inv_inertia, H, minv, W = _random_frictionless_system(rng)
    v_free = rng.normal(scale=0.1, size=(4, 3))
    v_free[3] = 0.0
    bias = np.zeros(4)
    problem = nlgs.ContactProblem(a, b, nx, ny, ra[:, 0].copy(), ra[:, 1].copy(), rb[:, 0].copy(), rb[:, 1].copy(),
                                  bias, np.zeros(4), inv_mass, np.zeros(4), inv_mass.copy(), inv_inertia)
    pn, pt = np.zeros(4), np.zeros(4)
    v = Velocities(*(v_free[:, k].copy() for k in range(3)))
    nlgs.solve(problem, Impulses(pn, pt), v, Limits(1e-14, 1e-14, 100_000, 0), False, 0)
    assert pn.max() > 0
    # restart from the free velocities with the solution as warm start
    v = Velocities(*(v_free[:, k].copy() for k in range(3)))
    it, quad, worst = nlgs.solve(problem, Impulses(pn.copy(), pt.copy()), v, Limits(1e-10, 1e-10, 100_000, 0), False,
                                 0)
    assert it == 1 and quad < 1e-10 and worst < 1e-10


def test_iteration_limit_reports_the_residual_reached():
    rng = np.random.default_rng(3)
    a, b, nx, ny, ra, rb, inv_mass, inv_inertia, H, minv, W = _random_frictionless_system(rng)
    v_free = np.zeros((4, 3))
    v_free[:3, 1] = 1.0  # all pushed against the fixed body 3 (normal +y from a to b)
    nx[:] = 0.0
    ny[:] = 1.0
    pn, pt = np.zeros(4), np.zeros(4)
    v = Velocities(*(v_free[:, k].copy() for k in range(3)))
    problem = nlgs.ContactProblem(a, b, nx, ny, ra[:, 0].copy(), ra[:, 1].copy(), rb[:, 0].copy(), rb[:, 1].copy(),
                                  np.zeros(4), np.zeros(4), inv_mass, np.zeros(4), inv_mass.copy(), inv_inertia)
    it, quad, worst = nlgs.solve(problem, Impulses(pn, pt), v, Limits(1e-14, 1e-14, 1, 0), False, 0)
    assert it == 1 and quad > 1e-14  # stopped by the limit, residual reported


@pytest.mark.parametrize("seed", range(3))
def test_a_sweep_returns_the_scale_of_its_end_impulses(seed):
    """The sweep accumulates S = sum_k p_k . W_k p_k and the loaded points as it goes; each
    point is swept once, so they are those of the end-of-sweep impulses (numpy, here) and the
    norms equal the ones computed after the sweep from the impulses."""
    rng = np.random.default_rng(seed)
    a, b, nx, ny, ra, rb, inv_mass, inv_inertia, H, minv, W = _random_frictionless_system(rng)
    v_free = rng.normal(scale=0.1, size=(4, 3))
    v_free[3] = 0.0
    problem = nlgs.ContactProblem(a, b, nx, ny, ra[:, 0].copy(), ra[:, 1].copy(), rb[:, 0].copy(), rb[:, 1].copy(),
                                  np.zeros(4), np.full(4, 0.3), inv_mass, np.zeros(4), inv_mass.copy(), inv_inertia)
    blocks = nlgs.delassus(problem)
    wnn, wnt, wtt = blocks
    pn, pt = np.zeros(4), np.zeros(4)
    velocities = Velocities(*(v_free[:, k].copy() for k in range(3)))
    for _ in range(3):
        total, top, scale, active = nlgs.sweep(np.arange(4)[::-1].copy(), problem, Impulses(pn, pt), velocities,
                                               blocks)
        loaded = pn > 0
        expected = np.sum((pn * (wnn * pn + wnt * pt) + pt * (wnt * pn + wtt * pt))[loaded])
        assert active == loaded.sum() and scale == pytest.approx(expected, rel=1e-14)
        assert nlgs.sweep_norms(total, top, scale, active) == pytest.approx(
            nlgs.norms(total, top, Impulses(pn, pt), blocks), rel=1e-14)
    assert active > 0
