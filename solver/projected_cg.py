"""Projected conjugate gradient after Renouf & Alart, for u = W r + q (:mod:`solver.contact_problem`).

Renouf & Alart (Comput. Methods Appl. Mech. Engrg. 194, 2005; the CPG solver of LMGC90) treat
the contact problem as a minimisation of (1/2) r.W r + q.r over the Coulomb cones, driven by
the negative gradient g = -(W r + q) = -u, with two projections that make its fixed points the
solutions of Signorini's condition and Coulomb's law rather than of an associated law:

* the impulses onto the cone *vertically*: r_n = max(0, y_n), r_t = clip(y_t, -mu r_n, mu r_n);
  each point gets a status, open (r = 0), sticking, or sliding at r_t = +-mu r_n (a point that
  slid and whose tangential search direction is zero stays at its edge);
* a direction x onto the face of that status: open, (max(0, x_n), 0) where the gradient pushes
  the point closed and 0 otherwise; sticking, x itself; sliding at r_t = +mu r_n,
  (x_n, min(0, x_t)) (at -mu r_n: max), so that a sliding point keeps u_n = 0 and may only leave
  its edge into the cone.

Iteration, from r on the cones, w = P(D g) (D = diag(1/W_nn, 1/W_tt), a Jacobi preconditioner)
and p = w:

    alpha = g.p / p.W p                  (the exact step along p of the quadratic)
    r    <- vertical projection of r + alpha p,   g = -(W r + q)
    w    =  P(D g),   z = P(p)           (the new gradient and the old direction on the new faces)
    beta = -(W p).w / p.W p,   p = w + beta z

restarted with p = w whenever p is not a descent direction (g.p <= 0). At a fixed point
(w = 0) open points separate (u_n >= 0), sticking points have u = 0, and sliding points have
u_n = 0 with u_t opposing r_t. The iterations stop when the natural-map residual
(:mod:`solver.contact_solution`) is within the tolerance, computed every iteration, and, unconverged,
when its smallest value has fallen by less than 5% over ``STALL_ITERATIONS`` iterations.
"""

from __future__ import annotations

import numpy as np

from .contact_solution import ContactSolution, contact_solution
from .projected_cg_kernels import iteration, start
from .solve_records import MatrixProblem

__all__ = ["STALL_IMPROVEMENT", "STALL_ITERATIONS", "solve"]

STALL_ITERATIONS = 500
"""The iterations stop when the smallest local-law residual has fallen by less than
``STALL_IMPROVEMENT`` over this many iterations."""

STALL_IMPROVEMENT = 0.05
"""The relative fall of the smallest local-law residual over ``STALL_ITERATIONS`` iterations
below which the iterations stop."""


def solve(W, q, mu, tolerance, max_iterations, initial) -> ContactSolution:
    """Projected conjugate-gradient iterations (module docstring; the passes compiled in
    :mod:`solver.projected_cg_kernels`) from the impulses ``initial`` (n, 2) until the
    local-law residual is within ``tolerance`` or ``max_iterations`` iterations."""
    n = mu.size
    diagonal = W.diagonal()
    jacobi = np.stack([1.0 / diagonal[0::2], 1.0 / np.where(diagonal[1::2] > 0, diagonal[1::2], diagonal[0::2])],
                      -1).reshape(-1)
    q = np.ascontiguousarray(q, dtype=np.float64)
    matrix = MatrixProblem(W.indptr.astype(np.int64), W.indices.astype(np.int64), W.data, q, mu)
    r = np.array(initial, dtype=np.float64).reshape(-1)
    status = np.empty(n, np.int64)
    g, p, Wp = np.empty(2 * n), np.empty(2 * n), np.empty(2 * n)
    violation, size = start(matrix, jacobi, r, status, g, p)
    law = _law(violation, size)
    best, checked = law, law
    iterations = 0
    while law > tolerance and iterations < max_iterations:
        violation, size, moved = iteration(matrix, jacobi, r, status, g, p, Wp)
        if not moved:
            break  # no direction with curvature left: a fixed point of the projections
        iterations += 1
        law = _law(violation, size)
        best = min(best, law)
        if iterations % STALL_ITERATIONS == 0:
            if best > (1.0 - STALL_IMPROVEMENT) * checked:
                break
            checked = best
    return contact_solution(W, q, mu, r.reshape(n, 2), iterations, law <= tolerance)


def _law(violation, size):
    """|F| / |r| from their squares (at r = 0: 0 if F = 0, infinite otherwise;
    :func:`solver.contact_solution.local_law_residual`)."""
    if size > 0:
        return float(np.sqrt(violation / size))
    return 0.0 if violation == 0.0 else float("inf")
