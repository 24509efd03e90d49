"""The time step's contact problem in matrix form, u = W r + q, for the methods that solve a
problem given by its matrix (:mod:`solver.contact_problem`, the registry's ``pcg`` in the stepper).

For P points and B bodies (particles then walls), r = (r_n,0, r_t,0, r_n,1, ...) the impulses
(N s) in each point's frame (n, t), t = (-n_y, n_x), and V = (v_x,0, v_y,0, w_0, v_x,1, ...) the
bodies' velocities (m s-1, rad s-1):

* H (2P x 3B) maps V to the points' relative velocities (b minus a): row 2k + e, for e in
  {n, t} of point k, holds e_x, e_y, (r_b x e) on body b and their negatives with r_a on body
  a, where r_a, r_b are the lever arms (m) and x the 2D cross product;
* M^-1 (3B x 3B) is block diagonal: each body's inverse mass matrix (kg-1) and inverse moment
  of inertia (kg-1 m-2), zero for a body that cannot move;
* W = H M^-1 H^T (s kg-1), q = H V_free + (bias_k, 0) per point (the Signorini shift in the
  normal row), and the end-of-step velocities V = V_free + M^-1 H^T r.

These are the same relations the NLGS sweeps apply point by point (:mod:`solver.nlgs`), built
once as sparse matrices (scipy.sparse).
"""

from __future__ import annotations

import numpy as np

__all__ = ["body_velocities", "inverse_mass", "local_map", "matrix_problem"]


def local_map(problem):
    """H (2P x 3B, CSR) of ``problem`` (:class:`solver.nlgs.ContactProblem`; module docstring)."""
    from scipy import sparse

    m, bodies = problem.a.size, problem.minv_xx.size
    rows, cols, vals = [], [], []
    for e, (ex, ey) in enumerate([(problem.nx, problem.ny), (-problem.ny, problem.nx)]):
        for body, rx, ry, sign in ((problem.b, problem.rbx, problem.rby, 1.0),
                                   (problem.a, problem.rax, problem.ray, -1.0)):
            for dof, value in enumerate([ex, ey, rx * ey - ry * ex]):
                rows.append(2 * np.arange(m) + e)
                cols.append(3 * body + dof)
                vals.append(sign * value)
    return sparse.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                             shape=(2 * m, 3 * bodies))


def inverse_mass(problem):
    """M^-1 (3B x 3B, CSR): the bodies' inverse mass matrices and inverse moments of inertia."""
    from scipy import sparse

    bodies = problem.minv_xx.size
    blocks = np.zeros((bodies, 3, 3))
    blocks[:, 0, 0], blocks[:, 0, 1], blocks[:, 1, 0] = problem.minv_xx, problem.minv_xy, problem.minv_xy
    blocks[:, 1, 1], blocks[:, 2, 2] = problem.minv_yy, problem.iinv
    return sparse.block_diag(list(blocks), format="csr")


def matrix_problem(problem, vx, vy, w, H=None, minv=None):
    """(W CSR with sorted indices, q (2P,), mu (P,)) of ``problem`` with the free body
    velocities ``vx, vy, w`` (B,) (module docstring); ``H`` and ``minv``: its
    :func:`local_map` and :func:`inverse_mass` when the caller has them."""
    H = local_map(problem) if H is None else H
    minv = inverse_mass(problem) if minv is None else minv
    W = (H @ minv @ H.T).tocsr()
    W.eliminate_zeros()
    W.sort_indices()
    q = H @ np.stack([vx, vy, w], -1).reshape(-1)
    q[0::2] += problem.bias
    if hasattr(problem, "slip"):  # a periodic cell's moving images (solver.solve_records.PeriodicContactProblem)
        q[1::2] += problem.slip
    return W, q, problem.mu.copy()


def body_velocities(H, minv, impulse, vx, vy, w):
    """Add the velocity change M^-1 H^T r of the impulses ``impulse`` (P, 2) N s to the bodies'
    velocities ``vx, vy, w`` (B,), in place (``H``, ``minv``: :func:`local_map`,
    :func:`inverse_mass`)."""
    change = (minv @ (H.T @ np.asarray(impulse, dtype=float).reshape(-1))).reshape(-1, 3)
    vx += change[:, 0]
    vy += change[:, 1]
    w += change[:, 2]
