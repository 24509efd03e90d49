"""solver.problem_assembly: the one-pass kernel against the whole-array numpy reference, bit for
bit, and one point's lever arms, shift and friction by hand."""

import numpy as np
import pytest

from solver.narrowphase import ContactPoints
from solver.problem_assembly import assemble, assemble_reference, end_gaps
from solver.solve_records import ContactProblem, StepLaw, StepStart


def Points(point, normal, gap, body_i, body_j):
    """Contact points as the narrow phase returns them (the kernel's cache holds the types it was
    called with: a record type of the tests' own would be looked up by every later run)."""
    m = len(gap)
    return ContactPoints(np.asarray(body_i, np.int32), np.asarray(body_j, np.int32), normal, point, gap,
                         np.ones(m, np.int8), np.arange(m, dtype=np.int32), m)


def _random_points(seed, n=30, walls=4, m=200):
    rng = np.random.default_rng(seed)
    bodies = n + walls
    body_i = rng.integers(0, n, m).astype(np.int32)
    body_j = rng.integers(0, bodies, m).astype(np.int32)
    angle = rng.uniform(0, 2 * np.pi, m)
    normal = np.stack([np.cos(angle), np.sin(angle)], -1)
    return (Points(rng.uniform(0, 1, (m, 2)), normal, rng.normal(0, 1e-4, m), body_i, body_j),
            StepStart(rng.uniform(0, 1, (bodies, 2)), rng.normal(0, 0.01, (bodies, 2)), rng.normal(0, 0.1, bodies), n))


def _problem(a, b, ra, rb, nx, ny, bias, mu):
    """A :class:`ContactProblem` of assembled points (unit masses: end_gaps reads none)."""
    ones = np.ones(int(max(a.max(initial=0), b.max(initial=0))) + 1)
    return ContactProblem(a, b, nx, ny, ra[:, 0].copy(), ra[:, 1].copy(), rb[:, 0].copy(), rb[:, 1].copy(), bias, mu,
                          ones, 0 * ones, ones, ones)


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("theta", [0.5, 1.0])
def test_the_kernel_is_the_reference_bit_for_bit(seed, theta):
    points, start = _random_points(seed)
    args = (points, start, StepLaw(5e-4, theta, 0.4, 0.1))
    got, expected = assemble(*args), assemble_reference(*args)
    for name, x, y in zip(("a", "b", "ra", "rb", "nx", "ny", "bias", "mu"), got, expected):
        np.testing.assert_array_equal(x, y, err_msg=name)
    walls = points.body_j >= start.n_particles
    assert walls.any() and np.all(got[3][walls] == 0.0) and np.all(got[7][walls] == 0.1)
    assert np.any(got[6] == 0.0) and np.any(got[6] > 0.0)  # closed and open points both met


def test_no_points():
    out = assemble(*_random_points(0, m=0), StepLaw(5e-4, 0.5, 0.4, 0.1))
    assert all(x.shape[0] == 0 for x in out)


def test_one_point_by_hand():
    """Particle 0 at (0, 0), rotating at w = 2 rad/s and moving at (0.1, 0); particle 1 at
    (1, 0) at rest; the point at (0.5, 0.1), normal (1, 0), gap 1e-3 m. r_a = (0.5, 0.1),
    r_b = (-0.5, 0.1); u_0 = -(v_a + w (-r_a,y, r_a,x)) = -(0.1 - 0.2, 1.0) = (0.1, -1.0),
    u_n0 = 0.1; g* = 1e-3 + h (1 - theta) 0.1 = 1e-3 + 2.5e-5; bias = g* / (theta h)."""
    h, theta = 5e-4, 0.5
    start = StepStart(np.array([[0.0, 0.0], [1.0, 0.0]]), np.array([[0.1, 0.0], [0.0, 0.0]]), np.array([2.0, 0.0]), 2)
    law = StepLaw(h, theta, 0.4, 0.1)
    a, b, ra, rb, nx, ny, bias, mu = assemble(
        Points(np.array([[0.5, 0.1]]), np.array([[1.0, 0.0]]), np.array([1e-3]), np.array([0], np.int32),
               np.array([1], np.int32)), start, law)
    np.testing.assert_allclose(ra, [[0.5, 0.1]], rtol=1e-15)
    np.testing.assert_allclose(rb, [[-0.5, 0.1]], rtol=1e-15)
    assert bias[0] == pytest.approx((1e-3 + 2.5e-5) / (theta * h), rel=1e-12) and mu[0] == 0.4
    # an overlap that the start velocities do not open: no shift (the IQS law)
    *_, bias, _ = assemble(Points(np.array([[0.5, 0.1]]), np.array([[1.0, 0.0]]), np.array([-1e-3]),
                                  np.array([0], np.int32), np.array([1], np.int32)), start, law)
    assert bias[0] == 0.0


@pytest.mark.parametrize("seed", [0, 1])
def test_end_gaps_are_the_whole_array_expression_bit_for_bit(seed):
    """The first-order end-of-step gaps against the numpy expression they replace in the stepper."""
    points, start = _random_points(seed)
    h = 5e-4
    assembled = assemble(points, start, StepLaw(h, 0.5, 0.4, 0.1))
    a, b, ra, rb, *_ = assembled
    rng = np.random.default_rng(seed + 10)
    velocity, omega = rng.normal(0, 0.01, (34, 2)), rng.normal(0, 0.1, 34)
    normal, gap = points.normal, points.gap
    expected = gap + h * ((velocity[b] - velocity[a]) * normal).sum(1)
    cross_b = rb[:, 0] * normal[:, 1] - rb[:, 1] * normal[:, 0]
    cross_a = ra[:, 0] * normal[:, 1] - ra[:, 1] * normal[:, 0]
    expected = expected + h * (omega[b] * cross_b - omega[a] * cross_a)
    np.testing.assert_array_equal(end_gaps(points, _problem(*assembled), velocity, omega, h), expected)


def test_end_gap_of_one_point_by_hand():
    """Particle 0 at rest, particle 1 moving at (-0.2, 0) m/s and turning at w = 3 rad/s, the
    point at r_b = (-0.5, 0.1) from its centre, normal (1, 0) from 0 to 1, gap 1e-3 m: u_n =
    -0.2 + 3 (r_b x n) = -0.2 + 3 (-0.5 * 0 - 0.1 * 1) = -0.5 m/s; g_end = 1e-3 - h 0.5."""
    h = 1e-3
    points = Points(np.array([[0.0, 0.0]]), np.array([[1.0, 0.0]]), np.array([1e-3]), np.array([0], np.int32),
                    np.array([1], np.int32))
    problem = _problem(np.array([0]), np.array([1]), np.array([[0.5, 0.1]]), np.array([[-0.5, 0.1]]),
                       *np.zeros((4, 1)))
    g = end_gaps(points, problem, np.array([[0.0, 0.0], [-0.2, 0.0]]), np.array([0.0, 3.0]), h)
    assert g[0] == pytest.approx(1e-3 - h * 0.5, rel=1e-13)
