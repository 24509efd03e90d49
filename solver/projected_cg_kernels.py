"""Compiled passes of the projected conjugate gradient (:mod:`solver.projected_cg`).

Arrays are flat, two entries per point (normal, tangential), W in CSR form. One call of
:func:`iteration` is one iteration of the method: two products with W and one pass over the
points for the projections, the natural map and the dot products.
"""

from __future__ import annotations

from numba import njit

from .residuals import natural_map

OPEN, STICK, SLIDE_POSITIVE, SLIDE_NEGATIVE = 0, 1, 2, 3
"""Point statuses: no impulse; inside the cone; at r_t = +mu r_n; at r_t = -mu r_n."""


@njit(cache=True)
def multiply(matrix, x, out):
    """out = W x for the CSR matrix W of ``matrix`` (:class:`solver.solve_records.MatrixProblem`)."""
    indptr, indices, data = matrix.indptr, matrix.indices, matrix.data
    for i in range(out.size):
        total = 0.0
        for e in range(indptr[i], indptr[i + 1]):
            total += data[e] * x[indices[e]]
        out[i] = total


@njit(cache=True)
def project(yn, yt, mu, status, direction_t):
    """(r_n, r_t, status) of the vertical projection of (yn, yt) onto the cone
    (:mod:`solver.projected_cg`): a point that slid and whose tangential direction is zero stays
    at its edge."""
    if yn <= 0.0:
        return 0.0, 0.0, OPEN
    bound = mu * yn
    if yt >= bound:
        return yn, bound, SLIDE_POSITIVE
    if yt <= -bound:
        return yn, -bound, SLIDE_NEGATIVE
    if direction_t == 0.0 and status == SLIDE_POSITIVE:
        return yn, bound, SLIDE_POSITIVE
    if direction_t == 0.0 and status == SLIDE_NEGATIVE:
        return yn, -bound, SLIDE_NEGATIVE
    return yn, yt, STICK


@njit(cache=True)
def face(xn, xt, status):
    """A direction (xn, xt) projected onto the face of ``status`` (:mod:`solver.projected_cg`)."""
    if status == OPEN:
        return max(xn, 0.0), 0.0
    if status == SLIDE_POSITIVE:
        return xn, min(xt, 0.0)
    if status == SLIDE_NEGATIVE:
        return xn, max(xt, 0.0)
    return xn, xt


@njit(cache=True)
def start(matrix, jacobi, r, status, g, p):
    """Project ``r`` onto the cones (statuses into ``status``), g = -(W r + q) and the first
    direction p = P(D g), for the problem u = W r + q of ``matrix``
    (:class:`solver.solve_records.MatrixProblem`) and the Jacobi scaling ``jacobi`` (2n,);
    returns (|F|^2, |r|^2) of the natural map at r."""
    q, mu = matrix.q, matrix.mu
    n = mu.size
    for k in range(n):
        r[2 * k], r[2 * k + 1], status[k] = project(r[2 * k], r[2 * k + 1], mu[k], STICK, 1.0)
    multiply(matrix, r, g)
    violation = 0.0
    size = 0.0
    for k in range(n):
        un, ut = g[2 * k] + q[2 * k], g[2 * k + 1] + q[2 * k + 1]
        g[2 * k], g[2 * k + 1] = -un, -ut
        fn, ft = natural_map(r[2 * k], r[2 * k + 1], un, ut, mu[k], jacobi[2 * k])
        violation += fn * fn + ft * ft
        size += r[2 * k] * r[2 * k] + r[2 * k + 1] * r[2 * k + 1]
        p[2 * k], p[2 * k + 1] = face(jacobi[2 * k] * g[2 * k], jacobi[2 * k + 1] * g[2 * k + 1], status[k])
    return violation, size


@njit(cache=True)
def iteration(matrix, jacobi, r, status, g, p, Wp):
    """One iteration of :mod:`solver.projected_cg` in place on r, status, g = -(W r + q) and the
    direction p (``Wp`` working memory), for the problem of ``matrix``
    (:class:`solver.solve_records.MatrixProblem`) with the Jacobi scaling ``jacobi``: the step
    along p, the projection onto the cones, the new gradient and natural map, then p = w + beta z
    (p = w when that is no descent direction). Returns (|F|^2, |r|^2, moved), moved False when p
    has no curvature (p.W p <= 0) and nothing was changed."""
    q, mu = matrix.q, matrix.mu
    n = mu.size
    multiply(matrix, p, Wp)
    pWp = 0.0
    gp = 0.0
    for i in range(2 * n):
        pWp += p[i] * Wp[i]
        gp += g[i] * p[i]
    if not pWp > 0.0:
        return 0.0, 0.0, False
    alpha = gp / pWp
    for k in range(n):
        r[2 * k], r[2 * k + 1], status[k] = project(r[2 * k] + alpha * p[2 * k], r[2 * k + 1] + alpha * p[2 * k + 1],
                                                    mu[k], status[k], p[2 * k + 1])
    multiply(matrix, r, g)
    violation = 0.0
    size = 0.0
    wWp = 0.0
    for k in range(n):
        un, ut = g[2 * k] + q[2 * k], g[2 * k + 1] + q[2 * k + 1]
        g[2 * k], g[2 * k + 1] = -un, -ut
        fn, ft = natural_map(r[2 * k], r[2 * k + 1], un, ut, mu[k], jacobi[2 * k])
        violation += fn * fn + ft * ft
        size += r[2 * k] * r[2 * k] + r[2 * k + 1] * r[2 * k + 1]
        wn, wt = face(jacobi[2 * k] * g[2 * k], jacobi[2 * k + 1] * g[2 * k + 1], status[k])
        zn, zt = face(p[2 * k], p[2 * k + 1], status[k])
        wWp += Wp[2 * k] * wn + Wp[2 * k + 1] * wt
        # w into p, the old direction on the new faces into Wp (its entries of point k are read
        # no more), following the new gradient's zeros
        p[2 * k], p[2 * k + 1] = wn, wt
        Wp[2 * k] = zn if wn != 0.0 else 0.0
        Wp[2 * k + 1] = zt if wt != 0.0 else 0.0
    beta = -wWp / pWp
    descent = 0.0
    for i in range(2 * n):
        descent += g[i] * (p[i] + beta * Wp[i])
    if descent > 0.0:  # else not a descent direction: restart on the gradient, p = w
        for i in range(2 * n):
            p[i] += beta * Wp[i]
    return violation, size, True
