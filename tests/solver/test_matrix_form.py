"""solver.matrix_form: the step's problem as u = W r + q agrees with the bodies' velocities
computed from the impulses (V = V_free + M^-1 H^T r) and the points' relative velocities taken
from them point by point, and W's diagonal blocks are the NLGS's Delassus blocks."""

import warnings

import numpy as np

from grainview.contract.errors import ConvergenceWarning
from solver import compaction_sample, isotropic_compaction, matrix_form, nlgs


def _relative_velocity(problem, vx, vy, w):
    """(u_n, u_t) of b relative to a at every point, from the bodies' velocities (numpy)."""
    P = problem
    ua_x, ua_y = vx[P.a] - w[P.a] * P.ray, vy[P.a] + w[P.a] * P.rax
    ub_x, ub_y = vx[P.b] - w[P.b] * P.rby, vy[P.b] + w[P.b] * P.rbx
    dx, dy = ub_x - ua_x, ub_y - ua_y
    return dx * P.nx + dy * P.ny, -dx * P.ny + dy * P.nx


def test_w_r_plus_q_is_the_relative_velocity_of_the_bodies_the_impulses_move():
    sim = compaction_sample(30, "pentagon", seed=3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConvergenceWarning)
        isotropic_compaction(sim, max_steps=800, progress=False)
    posed = sim.contact_problem()
    P, (pn, pt, vx, vy, w) = posed.problem, posed.state
    assert P.a.size > 40 and np.any(P.b >= sim.n_particles)  # walls among the bodies
    W, q, mu = matrix_form.matrix_problem(P, vx, vy, w)
    impulse = np.random.default_rng(0).uniform(0.0, 1.0, (P.a.size, 2)) * np.abs(pn).max()
    vx, vy, w = vx.copy(), vy.copy(), w.copy()
    matrix_form.body_velocities(matrix_form.local_map(P), matrix_form.inverse_mass(P), impulse, vx, vy, w)
    un, ut = _relative_velocity(P, vx, vy, w)
    u = (W @ impulse.reshape(-1) + q).reshape(-1, 2)
    scale = np.abs(u).max()
    np.testing.assert_allclose(u[:, 0], un + P.bias, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(u[:, 1], ut, rtol=0, atol=1e-12 * scale)
    np.testing.assert_array_equal(mu, P.mu)
    blocks = nlgs.delassus(P)
    diagonal = W.diagonal()
    np.testing.assert_allclose(diagonal[0::2], blocks.nn, rtol=1e-12)
    np.testing.assert_allclose(diagonal[1::2], blocks.tt, rtol=1e-12)
    assert abs(W - W.T).max() <= 1e-12 * abs(W).max()
