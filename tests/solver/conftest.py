"""Shared constants and helpers of the solver's tests."""

import warnings

import numpy as np
from scipy import sparse

from grainview.contract.errors import ConvergenceWarning
from solver import residuals

G = 9.81  # m s-2
R = 0.0125  # m, circumscribed radius of the paper's smallest particles
PENTAGON_ON_EDGE = np.radians(-54.0)  # vertices at -54 + 72 k degrees: an edge at the bottom
EXACT = dict(tolerance=1e-12, max_tolerance=1e-12, max_iterations=100_000)
"""NLGS settings for analytic checks: converge to round-off."""


def compacted_problem(seed):
    """The contact problem of the next step of 120 pentagons compacted under 10 kPa (seed
    ``seed``; a stress-driven right wall) with plain NLGS sweeps, so that the problem is fixed
    whatever the solver's default: (sim, problem, warm-start impulses (P, 2), free velocities
    (B, 2), free angular velocities (B,)). A few compaction steps hit the sweep cap: not what
    the tests using it check."""
    from solver import compaction_sample, isotropic_compaction

    sim = compaction_sample(120, "pentagon", seed=seed, acceleration="off")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConvergenceWarning)
        isotropic_compaction(sim)
    posed = sim.contact_problem()
    pn, pt, vx, vy, w = posed.state
    return sim, posed.problem, np.stack([pn, pt], -1), np.stack([vx, vy], -1), w


def random_body_problem(seed, *, bodies, points, friction):
    """(W, q, mu): ``points`` contact points between ``bodies`` random rigid bodies (x, y,
    rotation; each point joins two different bodies at random lever arms, its normal at a random
    angle), W = H M^-1 H^T with random masses and inertias, q = H v0 for random body velocities
    v0, mu = ``friction`` at every point. W is singular where 2 ``points`` > 3 ``bodies``."""
    rng = np.random.default_rng(seed)
    a = rng.integers(0, bodies, points)
    b = (a + rng.integers(1, bodies, points)) % bodies
    angle = rng.uniform(0, 2 * np.pi, points)
    nx, ny = np.cos(angle), np.sin(angle)
    ra, rb = rng.uniform(-0.5, 0.5, (points, 2)), rng.uniform(-0.5, 0.5, (points, 2))
    H = np.zeros((2 * points, 3 * bodies))
    for k in range(points):
        for e, (ex, ey) in enumerate([(nx[k], ny[k]), (-ny[k], nx[k])]):
            for body, lever, sign in ((b[k], rb[k], 1.0), (a[k], ra[k], -1.0)):
                H[2 * k + e, 3 * body:3 * body + 3] += sign * np.array([ex, ey, lever[0] * ey - lever[1] * ex])
    minv = np.repeat(rng.uniform(0.5, 2.0, bodies), 3)
    minv[2::3] = rng.uniform(1.0, 4.0, bodies)
    return H @ np.diag(minv) @ H.T, H @ rng.normal(size=3 * bodies), np.full(points, float(friction))


def independent_residual(W, q, mu, impulse):
    """|F| / |r| of the natural map recomputed from the impulses alone: u = W r + q, rho = 1 / W_nn."""
    W = np.asarray(sparse.csr_matrix(W).toarray())
    n = len(impulse)
    u = (W @ impulse.reshape(-1) + np.asarray(q, float)).reshape(n, 2)
    mu = np.broadcast_to(np.asarray(mu, float), (n,)).copy()
    fn, ft = residuals.natural_maps(impulse[:, 0].copy(), impulse[:, 1].copy(), u[:, 0].copy(), u[:, 1].copy(), mu,
                                    1.0 / np.diag(W)[0::2])
    size = np.linalg.norm(impulse)
    violation = np.hypot(np.linalg.norm(fn), np.linalg.norm(ft))
    return violation / size if size > 0 else violation
