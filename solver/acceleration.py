"""Anderson acceleration of the NLGS: the sweeps as a fixed-point map, extrapolated.

One NLGS sweep maps the impulses x = (p_n, p_t) of all points to new ones, G(x); a solution is
a fixed point x = G(x). In a dense packing the sweeps converge slowly (long force chains pass a
correction on by about one contact per sweep), and Anderson acceleration (type II, Walker & Ni,
SIAM J. Numer. Anal. 49, 2011) combines the last m sweeps instead of keeping the last one only:

    f_k = G(x_k) - x_k,   gamma = argmin || f_k - dF gamma ||_2,
    x_{k+1} = G(x_k) - dG gamma,

with dF, dG the differences of successive f and G(x) (memory m). The extrapolated impulses are
projected back onto each point's Coulomb cone (p_n >= 0, |p_t| <= mu p_n) and the body
velocities rebuilt from them (v = v_free + M^-1 H p). The sweep itself stays the NLGS's exact
point-by-point solver, so the method is NLGS with an extrapolation between sweeps, and its
stopping norms are the NLGS's own (:mod:`solver.nlgs`), measured on the change a sweep makes.

Safeguard: the problem is nonsmooth (contacts open, close, stick and slip between sweeps), so
when a sweep's change |f_k| grows above the previous one the memory is cleared and the plain
sweep's result kept: the method falls back to NLGS until the sweeps contract again. The
least-squares problem is solved by its m x m normal equations, updated by one row per sweep,
so a sweep costs about 2m + 6 passes over the points on top of the NLGS sweep.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .nlgs import NLGSResult, delassus, norms, sweep, velocities_from_impulses
from .residuals import cone_projection

__all__ = ["solve_anderson", "solve_problem_anderson"]


@njit(cache=True)
def _small_solve(matrix, rhs, size):
    """Solution of the leading ``size`` x ``size`` system by Gaussian elimination with partial
    pivoting; (x, ok) with ok False when a pivot vanishes relative to the diagonal."""
    a = matrix[:size, :size].copy()
    x = rhs[:size].copy()
    scale = 0.0
    for i in range(size):
        scale = max(scale, abs(a[i, i]))
    for col in range(size):
        pivot = col
        for row in range(col + 1, size):
            if abs(a[row, col]) > abs(a[pivot, col]):
                pivot = row
        if abs(a[pivot, col]) <= 1e-13 * scale:
            return x, False
        if pivot != col:
            for j in range(size):
                a[col, j], a[pivot, j] = a[pivot, j], a[col, j]
            x[col], x[pivot] = x[pivot], x[col]
        for row in range(col + 1, size):
            factor = a[row, col] / a[col, col]
            for j in range(col, size):
                a[row, j] -= factor * a[col, j]
            x[row] -= factor * x[col]
    for row in range(size - 1, -1, -1):
        acc = x[row]
        for j in range(row + 1, size):
            acc -= a[row, j] * x[j]
        x[row] = acc / a[row, row]
    return x, True


@njit(cache=True)
def solve_anderson(a, b, nx, ny, rax, ray, rbx, rby, bias, mu, pn, pt, vx, vy, w,
                   minv_xx, minv_xy, minv_yy, iinv, tol, max_tol, max_iterations, memory):
    """Anderson-accelerated NLGS (module docstring); arguments, in-place updates and result as
    :func:`solver.nlgs.solve` without the ordering options; ``memory`` is m."""
    m = a.size
    n2 = 2 * m
    wnn, wnt, wtt = delassus(a, b, nx, ny, rax, ray, rbx, rby, minv_xx, minv_xy, minv_yy, iinv)
    free_x, free_y, free_w = vx.copy(), vy.copy(), w.copy()
    velocities_from_impulses(a, b, nx, ny, rax, ray, rbx, rby, pn, pt, vx, vy, w, minv_xx, minv_xy, minv_yy, iinv)
    order = np.arange(m)
    d_f = np.zeros((memory, n2))
    d_g = np.zeros((memory, n2))
    gram = np.zeros((memory, memory))
    rhs = np.zeros(memory)
    x = np.empty(n2)
    f = np.empty(n2)
    f_prev = np.zeros(n2)
    g_prev = np.zeros(n2)
    have_prev = False
    count = 0
    head = 0
    last = np.inf
    quad = 0.0
    worst = 0.0
    for it in range(1, max_iterations + 1):
        x[:m] = pn
        x[m:] = pt
        sum_dv2, max_dv2 = sweep(order, a, b, nx, ny, rax, ray, rbx, rby, bias, mu, pn, pt, vx, vy, w,
                                 minv_xx, minv_xy, minv_yy, iinv, wnn, wnt, wtt)
        quad, worst = norms(sum_dv2, max_dv2, pn, pt, wnn, wnt, wtt)
        if quad <= tol and worst <= max_tol:
            return it, quad, worst
        size = 0.0
        for i in range(m):
            f[i] = pn[i] - x[i]
            f[m + i] = pt[i] - x[m + i]
            size += f[i] * f[i] + f[m + i] * f[m + i]
        if size > last:  # the sweeps stopped contracting: forget the history
            count = 0
            head = 0
            have_prev = False
        last = size
        if have_prev:
            slot = head
            head = (head + 1) % memory
            count = min(count + 1, memory)
            for i in range(m):
                d_f[slot, i] = f[i] - f_prev[i]
                d_f[slot, m + i] = f[m + i] - f_prev[m + i]
                d_g[slot, i] = pn[i] - g_prev[i]
                d_g[slot, m + i] = pt[i] - g_prev[m + i]
            for j in range(count):
                gram[slot, j] = gram[j, slot] = np.dot(d_f[slot], d_f[j])
        for i in range(m):
            f_prev[i] = f[i]
            f_prev[m + i] = f[m + i]
            g_prev[i] = pn[i]
            g_prev[m + i] = pt[i]
        have_prev = True
        if count == 0:
            continue
        for j in range(count):
            rhs[j] = np.dot(d_f[j], f)
        gamma, ok = _small_solve(gram, rhs, count)
        if not ok:
            count = 0
            head = 0
            continue
        for i in range(m):
            en = pn[i]
            et = pt[i]
            for j in range(count):
                en -= d_g[j, i] * gamma[j]
                et -= d_g[j, m + i] * gamma[j]
            pn[i], pt[i] = cone_projection(en, et, mu[i])
        vx[:] = free_x
        vy[:] = free_y
        w[:] = free_w
        velocities_from_impulses(a, b, nx, ny, rax, ray, rbx, rby, pn, pt, vx, vy, w, minv_xx, minv_xy, minv_yy,
                                 iinv)
    return max_iterations, quad, worst


def solve_problem_anderson(problem, pn, pt, vx, vy, w, *, tolerance, max_tolerance, max_iterations,
                           memory=5) -> NLGSResult:
    """Solve ``problem`` (:class:`solver.nlgs.ContactProblem`) by Anderson-accelerated NLGS
    sweeps (module docstring); same arguments, in-place updates and result as
    :func:`solver.nlgs.solve_problem`. ``memory`` is m, the number of past sweeps combined."""
    iterations, residual, worst = solve_anderson(
        problem.a, problem.b, problem.nx, problem.ny, problem.rax, problem.ray, problem.rbx, problem.rby,
        problem.bias, problem.mu, pn, pt, vx, vy, w, problem.minv_xx, problem.minv_xy, problem.minv_yy,
        problem.iinv, float(tolerance), float(max_tolerance), int(max_iterations), int(memory))
    return NLGSResult(int(iterations), float(residual), float(worst))
