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

from .contact_solution import ContactSolution, contact_solution, local_law_residual, natural_map_at

__all__ = ["OPEN", "STICK", "SLIDE_POSITIVE", "SLIDE_NEGATIVE", "cone_projection", "face_projection", "solve"]

STALL_ITERATIONS = 500
"""The iterations stop when the smallest local-law residual has fallen by less than 5% over
this many iterations."""

OPEN, STICK, SLIDE_POSITIVE, SLIDE_NEGATIVE = 0, 1, 2, 3
"""Point statuses: no impulse; inside the cone; at r_t = +mu r_n; at r_t = -mu r_n."""


def cone_projection(y, mu, status, direction_t):
    """Vertical projection of y (n, 2) onto the cones and the new statuses (module docstring);
    ``status`` the previous statuses and ``direction_t`` (n,) the tangential search direction
    (a sliding point with a zero one stays at its edge)."""
    rn = np.maximum(y[:, 0], 0.0)
    bound = mu * rn
    rt = np.clip(y[:, 1], -bound, bound)
    new = np.where(y[:, 1] >= bound, SLIDE_POSITIVE, np.where(y[:, 1] <= -bound, SLIDE_NEGATIVE, STICK))
    keep = (new == STICK) & (direction_t == 0.0) & ((status == SLIDE_POSITIVE) | (status == SLIDE_NEGATIVE))
    new = np.where(keep, status, new)
    rt = np.where(new == SLIDE_POSITIVE, bound, np.where(new == SLIDE_NEGATIVE, -bound, rt))
    new = np.where(y[:, 0] > 0.0, new, OPEN)
    return np.stack([rn, np.where(new == OPEN, 0.0, rt)], -1), new


def face_projection(x, status, mask=None):
    """A direction x (n, 2) projected onto the faces of ``status`` (module docstring). With
    ``mask`` (n, 2) of booleans, the components where it is False are zeroed as well (the old
    direction follows the new gradient's zeros)."""
    xn, xt = x[:, 0], x[:, 1]
    opening = status == OPEN
    out_n = np.where(opening, np.maximum(xn, 0.0), xn)
    out_t = np.where(opening, 0.0, np.where(status == SLIDE_POSITIVE, np.minimum(xt, 0.0),
                                            np.where(status == SLIDE_NEGATIVE, np.maximum(xt, 0.0), xt)))
    out = np.stack([out_n, out_t], -1)
    if mask is not None:
        out = np.where(mask, out, 0.0)
    return out


def solve(W, q, mu, tolerance, max_iterations, initial) -> ContactSolution:
    """Projected conjugate-gradient iterations (module docstring) from the impulses
    ``initial`` (n, 2) until the local-law residual is within ``tolerance`` or
    ``max_iterations`` iterations."""
    n = mu.size
    diagonal = W.diagonal()
    jacobi = np.stack([1.0 / diagonal[0::2], 1.0 / np.where(diagonal[1::2] > 0, diagonal[1::2], diagonal[0::2])], -1)
    start = np.array(initial, dtype=np.float64).reshape(-1, 2)
    rho = jacobi[:, 0]
    r, status = cone_projection(start, mu, np.full(n, STICK), np.ones(n))
    g = -(W @ r.reshape(-1) + q).reshape(-1, 2)
    w = face_projection(jacobi * g, status)
    p = w
    iterations = 0
    law = local_law_residual(natural_map_at(r, -g, mu, rho), r)
    best, checked = law, law
    while law > tolerance and iterations < max_iterations:
        if not np.any(p):
            break  # no direction left: a fixed point of the projections short of the tolerance
        Wp = (W @ p.reshape(-1)).reshape(-1, 2)
        pWp = float(np.sum(p * Wp))
        if not pWp > 0.0:
            break
        alpha = float(np.sum(g * p)) / pWp
        r, status = cone_projection(r + alpha * p, mu, status, p[:, 1])
        g = -(W @ r.reshape(-1) + q).reshape(-1, 2)
        iterations += 1
        law = local_law_residual(natural_map_at(r, -g, mu, rho), r)
        best = min(best, law)
        if iterations % STALL_ITERATIONS == 0:
            if best > 0.95 * checked:
                break
            checked = best
        w = face_projection(jacobi * g, status)
        z = face_projection(p, status, w != 0.0)
        beta = -float(np.sum(Wp * w)) / pWp
        p = w + beta * z
        if float(np.sum(g * p)) <= 0.0:  # not a descent direction: restart on the gradient
            p = w
    return contact_solution(W, q, mu, r, iterations, law <= tolerance)
