"""The two-level method (benchmarks/research/two_level.py) on problems whose answer is known by hand, and on a
random problem against the NLGS."""

import sys

import numpy as np
import pytest
from scipy import sparse

pytest.importorskip("pyamg")

from benchmarks.research import two_level  # noqa: E402
from grainview.contract.errors import ParameterError  # noqa: E402
from solver import residuals  # noqa: E402
from solver.contact_problem import solve_contact_problem  # noqa: E402

W_SLIDE = np.diag([2.0, 2.0])
Q_SLIDE = np.array([-2.0, 1.0])
# mu = 0.2: sticking would need r = (1, -0.5), outside the cone; sliding with u_t > 0:
# r_t = -0.2 r_n and u_n = 2 r_n - 2 = 0, so r = (1, -0.2) and u_t = 1 - 0.4 = 0.6 > 0.

W_STICK = np.array([[2.0, 0.5], [0.5, 1.0]])
Q_STICK = np.array([-2.0, 0.1])
# mu = 1: r = -W^-1 q = (2.05, -1.2) / 1.75, inside the cone.


def _solve(W, q, mu, initial=None, tolerance=1e-12, **options):
    n = np.size(q) // 2
    initial = np.zeros((n, 2)) if initial is None else np.asarray(initial, float).reshape(n, 2)
    return two_level.solve_recorded(sparse.csr_matrix(W), np.asarray(q, float), np.broadcast_to(mu, (n,)).copy(),
                                    tolerance, 200, initial, **options)


@pytest.mark.parametrize("smoother", ["coulomb", "convex"])
@pytest.mark.parametrize("W, q, mu, expected", [
    (np.diag([2.0, 3.0]), [0.5, -1.0], 0.3, [[0.0, 0.0]]),              # open: u_n = q_n > 0
    (W_STICK, Q_STICK, 1.0, [[2.05 / 1.75, -1.2 / 1.75]]),              # sticking
    (W_SLIDE, Q_SLIDE, 0.2, [[1.0, -0.2]]),                              # sliding
])
def test_a_single_contact_gets_its_analytic_impulse(W, q, mu, expected, smoother):
    result = _solve(W, q, mu, smoother=smoother)
    assert result.solution.converged
    np.testing.assert_allclose(result.solution.impulse, expected, atol=1e-9)


@pytest.mark.parametrize("W, q, mu, start, expected", [
    (W_STICK, Q_STICK, 1.0, [1.0, 0.0], [2.05 / 1.75, -1.2 / 1.75]),
    (W_SLIDE, Q_SLIDE, 0.2, [0.5, 0.0], [1.0, -0.2]),
])
def test_the_coarse_step_alone_reaches_the_analytic_impulse(W, q, mu, start, expected):
    """No sweep at all: the truncated Newton step, its projection and line search, and the
    update of De Saxcé's shift between cycles solve the point by themselves (to the accuracy the
    1e-8 regularisation of the Newton matrix leaves)."""
    result = _solve(W, q, mu, start, tolerance=1e-10, pre_sweeps=0, post_sweeps=0)
    assert result.solution.converged
    np.testing.assert_allclose(result.solution.impulse[0], expected, atol=1e-9)
    assert all(0.0 <= c.step <= 1.0 for c in result.cycles)
    assert result.cycles[0].coarse_decrease > 0  # the first step lowers J


def _column():
    """Two disks stacked on a floor (no rotation): point 0 floor-disk 1, point 1 disk 1-disk 2,
    normals vertical. m1 = 1, m2 = 2 kg, free velocities (0, -1) and (1, -1) m/s, mu = 0.3.
    At rest vertically: r_1n = m2 = 2, r_0n = m1 + m2 = 3. Disk 2 slides on disk 1
    (r_1t = -mu r_1n = -0.6, u_1t = 1 - 0.6 / 2 = 0.7 > 0), and disk 1 sticks on the floor with
    r_0t = r_1t = -0.6, |r_0t| < mu r_0n = 0.9."""
    # rows: (u_0n, u_0t, u_1n, u_1t); columns: (v1x, v1y, v2x, v2y)
    H = np.array([[0, 1, 0, 0], [1, 0, 0, 0], [0, -1, 0, 1], [-1, 0, 1, 0]], float)
    minv = np.diag([1.0, 1.0, 0.5, 0.5])
    return H @ minv @ H.T, H @ np.array([0.0, -1.0, 1.0, -1.0]), np.full(2, 0.3)


@pytest.mark.parametrize("smoother", ["coulomb", "convex"])
def test_two_stacked_disks_one_sliding_one_sticking(smoother):
    W, q, mu = _column()
    result = _solve(W, q, mu, smoother=smoother)
    assert result.solution.converged
    np.testing.assert_allclose(result.solution.impulse, [[3.0, -0.6], [2.0, -0.6]], atol=1e-9)
    np.testing.assert_allclose(result.solution.velocity[1], [0.0, 0.7], atol=1e-9)
    assert list(two_level.classify(result.solution.impulse, mu)) == [two_level.STICKING, -two_level.SLIDING]


def test_the_cone_minimiser_is_coulombs_local_solution_at_de_saxces_shift():
    """At s = mu |u_t| of the Coulomb solution, J's local minimiser is that solution; at s = 0 it
    is the W-metric projection of the unconstrained minimiser, on the edge (1, -mu)."""
    at_shift = two_level.cone_minimiser(-2.0 + 0.2 * 0.6, 1.0, 2.0, 0.0, 2.0, 0.2)
    np.testing.assert_allclose(at_shift, [1.0, -0.2], atol=1e-12)
    alpha = 2.2 / 2.08  # -e.b / e.W e for e = (1, -0.2), b = (-2, 1)
    np.testing.assert_allclose(two_level.cone_minimiser(-2.0, 1.0, 2.0, 0.0, 2.0, 0.2), [alpha, -0.2 * alpha],
                               atol=1e-12)
    assert two_level.cone_minimiser(1.0, 0.3, 2.0, 0.0, 2.0, 0.2) == (0.0, 0.0)  # pushed apart: the apex


def _random_problem(n=60, seed=3):
    """u = W r + q with W = H M^-1 H^T for n points on random pairs of 80 bodies (x, y, spin),
    mu 0.3, q pressing about two thirds of the points together. With 60 points W has full rank
    (120; condition number about 850), so that the solution is unique."""
    rng = np.random.default_rng(seed)
    bodies = 80
    H = np.zeros((2 * n, 3 * bodies))
    for k in range(n):
        a, b = rng.choice(bodies, 2, replace=False)
        angle = rng.uniform(0, 2 * np.pi)
        normal, tangent = np.array([np.cos(angle), np.sin(angle)]), np.array([-np.sin(angle), np.cos(angle)])
        arm = rng.uniform(0.5, 1.0)
        for row, e in ((2 * k, normal), (2 * k + 1, tangent)):
            H[row, 3 * b:3 * b + 2], H[row, 3 * a:3 * a + 2] = e, -e
            H[row, 3 * b + 2] = H[row, 3 * a + 2] = arm * (e @ tangent)
    W = H @ np.diag(rng.uniform(0.5, 2.0, 3 * bodies)) @ H.T
    q = rng.normal(size=2 * n)
    q[0::2] -= 0.7
    return sparse.csr_matrix(W), q, np.full(n, 0.3)


def test_a_random_problem_reaches_the_nlgs_solution_and_reports_its_true_residual():
    W, q, mu = _random_problem()
    result = two_level.solve_recorded(W, q, mu, 1e-9, 500, np.zeros((mu.size, 2)))
    solution = result.solution
    assert solution.converged and solution.local_law_residual <= 1e-9
    assert result.builds >= 1 and any(c.step > 0.1 for c in result.cycles)
    reference = solve_contact_problem(W, q, mu, method="nlgs", tolerance=1e-13, max_iterations=100_000)
    assert reference.local_law_residual < 1e-8
    scale = np.abs(reference.impulse).max()
    np.testing.assert_allclose(solution.impulse, reference.impulse, atol=1e-6 * scale)
    # the residual it claims, recomputed from W, q, mu and its impulses with solver.residuals alone
    r = solution.impulse
    u = (W.toarray() @ r.reshape(-1) + q).reshape(-1, 2)
    fn, ft = residuals.natural_maps(r[:, 0].copy(), r[:, 1].copy(), u[:, 0].copy(), u[:, 1].copy(), mu,
                                    1.0 / np.diag(W.toarray())[0::2])
    recomputed = np.sqrt(np.sum(fn ** 2 + ft ** 2) / np.sum(r ** 2))
    assert solution.local_law_residual == pytest.approx(recomputed, rel=1e-9)
    assert result.cycles[-1].residual == pytest.approx(recomputed, rel=1e-9)
    assert solution.iterations == len(result.cycles)


def test_without_the_v_cycle_a_cycle_is_two_plain_sweeps():
    W, q, mu = _random_problem()
    control = two_level.solve_recorded(W, q, mu, 1e-300, 7, np.zeros((mu.size, 2)), coarse=False)
    reference = solve_contact_problem(W, q, mu, method="nlgs", tolerance=1e-300, max_iterations=14)
    np.testing.assert_array_equal(control.solution.impulse, reference.impulse)
    assert all(np.isnan(c.step) for c in control.cycles)


def test_bad_input_and_a_missing_pyamg_are_one_line_errors(monkeypatch):
    W, q, mu = _column()
    with pytest.raises(ParameterError, match="smoother='gauss'"):
        _solve(W, q, mu, smoother="gauss")
    with pytest.raises(ParameterError, match=r"rebuild_fraction=1.5: expected regularisation in \[0, 1\) and "
                       r"rebuild_fraction in \[0, 1\]"):
        _solve(W, q, mu, rebuild_fraction=1.5)
    with pytest.raises(ParameterError, match="initial must hold 2 finite impulses per point"):
        two_level.solve(sparse.csr_matrix(W), q, mu, 1e-8, 10, np.zeros(3))
    monkeypatch.setitem(sys.modules, "pyamg", None)
    with pytest.raises(ParameterError, match="needs pyamg"):
        _solve(W, q, mu)
