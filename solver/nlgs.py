"""Nonlinear Gauss–Seidel (NLGS) on Signorini's condition and Coulomb's law, point by point.

Unknowns are the impulses p = (p_n, p_t) of every contact point over a time step h (force =
p/h) and the end-of-step velocities v+ of the bodies. For point k between bodies a (= i) and
b (= j), the relative velocity of b with respect to a at the point, in the local frame (n, t),
is u = u_free + W p, where W is the 2x2 Delassus block of the point and u_free the velocity
without its own impulse. Each point in turn solves its local problem *exactly* with the other
points frozen, and its impulse change is applied to the bodies' velocities at once.

Local law (inelastic, 2D). With b_k = max(0, g*_k)/(theta h), g*_k = g_k + h (1 - theta) u_n^-
the gap predicted to the middle of the step (LMGC90's IQS law: an open gap may close within
the step, an existing overlap is not pushed out):

    Signorini:  p_n >= 0,  u_n + b_k >= 0,  p_n (u_n + b_k) = 0
    Coulomb:    |p_t| <= mu p_n;  |p_t| < mu p_n => u_t = 0;  u_t != 0 => p_t = -mu p_n sign(u_t)

The exact solution of the local problem is the one of three cases that is consistent: no
contact (p = 0 when u_free_n + b >= 0), sticking (p = -W^-1 (u_free + (b, 0))), or sliding in
direction s = +-1 (p_t = -s mu p_n, u_n + b = 0).

Convergence (checked after every sweep over all points; after LMGC90's "Quad" and "Maxm"
checks). The change dp_k of the impulse of point k over the sweep changes its local velocity
by about W dp_k; it is measured in the metric of the Delassus block, dV_k^2 = dp_k . W_k dp_k
(m2 s-2 x kg), against the scale S = sum_k p_k . W_k p_k of the impulses themselves:

    quadratic norm   e_quad = sqrt( sum_k dV_k^2 / S )                    <= tol
    max norm         e_max  = max_k dV_k / sqrt(S / n_active)             <= max_tol

with n_active the points carrying an impulse (p_n > 0). Both must hold: the quadratic norm is
LMGC90's reference criterion (tolerance 1.666e-4), and the max norm keeps a single newly
loaded contact among thousands (whose change is diluted in the quadratic sum) from stopping
the iterations before its force has built up. With S = 0 (no impulse anywhere) the sweep has
converged when no impulse changed.

Stall (``stall`` sweeps W > 0). In a step where the packing rearranges, the sweeps can creep
for thousands of sweeps with the quadratic norm just above its tolerance, or wander around it.
After every W sweeps the smallest quadratic norm reached so far is compared with the smallest
at the previous check; when it has not fallen by at least ``STALL_IMPROVEMENT`` (5%), the
iterations stop there (:func:`stalled`), unless the quadratic norm already meets its
tolerance (then only the max norm is left, which the quadratic norm need not follow). Such a step has not converged: its norms are returned
as they are, and the stepper warns as it does for a step stopped by the sweep cap. W = 0 turns
the test off. The local-law residual (:mod:`solver.residuals`) of the steps stopped this way is
what the test is judged by (docs/solver.md).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit
from numba.extending import overload

from .cell_coupling import couple_cell
from .solve_records import ContactProblem, DelassusBlocks, Impulses, Limits, Velocities

__all__ = ["ContactProblem", "NLGSResult", "STALL_IMPROVEMENT", "delassus", "delassus_block", "delassus_into",
           "local_solve", "norms", "relative_velocity", "solve", "solve_matrix", "solve_problem", "stalled", "sweep",
           "sweep_norms",
           "velocities_from_impulses"]


from .solve_records import STALL_IMPROVEMENT  # noqa: E402 (defined beside Limits, read here by the kernels)


class NLGSResult(NamedTuple):
    """Sweeps run and the quadratic and max norms of the last sweep (module docstring)."""

    iterations: int
    residual: float
    max_residual: float


@njit(cache=True, inline="always")
def _cross(rx, ry, ex, ey):
    return rx * ey - ry * ex


@njit(cache=True, inline="always")
def delassus_block(k, problem):
    """The local 2x2 Delassus block (W_nn, W_nt, W_tt) of point k of ``problem`` (s kg-1).

    For each body: W += e_a^T M^-1 e_b + I^-1 (r x e_a)(r x e_b), e in {n, t}, t = (-n_y, n_x).
    """
    nx, ny = problem.nx, problem.ny
    minv_xx, minv_xy, minv_yy, iinv = problem.minv_xx, problem.minv_xy, problem.minv_yy, problem.iinv
    tx, ty = -ny[k], nx[k]
    nn = nt = tt = 0.0
    for side in range(2):
        body = problem.a[k] if side == 0 else problem.b[k]
        rx = problem.rax[k] if side == 0 else problem.rbx[k]
        ry = problem.ray[k] if side == 0 else problem.rby[k]
        mxx, mxy, myy = minv_xx[body], minv_xy[body], minv_yy[body]
        rn = _cross(rx, ry, nx[k], ny[k])
        rt = _cross(rx, ry, tx, ty)
        nn += nx[k] * (mxx * nx[k] + mxy * ny[k]) + ny[k] * (mxy * nx[k] + myy * ny[k]) + iinv[body] * rn * rn
        nt += nx[k] * (mxx * tx + mxy * ty) + ny[k] * (mxy * tx + myy * ty) + iinv[body] * rn * rt
        tt += tx * (mxx * tx + mxy * ty) + ty * (mxy * tx + myy * ty) + iinv[body] * rt * rt
    return nn, nt, tt


@njit(cache=True)
def delassus_into(problem, out):
    """:func:`delassus` written into ``out`` (:class:`DelassusBlocks` of (P,) arrays)."""
    for k in range(problem.a.size):
        out.nn[k], out.nt[k], out.tt[k] = delassus_block(k, problem)


@njit(cache=True)
def delassus(problem):
    """Local 2x2 Delassus blocks of every point (:func:`delassus_block`), a new
    :class:`DelassusBlocks`."""
    m = problem.a.size
    out = DelassusBlocks(np.empty(m), np.empty(m), np.empty(m))
    delassus_into(problem, out)
    return out


@njit(cache=True)
def local_solve(ufn, uft, bias, wnn, wnt, wtt, mu):
    """Exact solution (p_n, p_t) of the 2D Signorini–Coulomb problem of one point."""
    if ufn + bias >= 0.0:
        return 0.0, 0.0
    det = wnn * wtt - wnt * wnt
    if det > 0.0:  # sticking
        rn, rt = -(ufn + bias), -uft
        pn = (wtt * rn - wnt * rt) / det
        pt = (wnn * rt - wnt * rn) / det
        if pn >= 0.0 and abs(pt) <= mu * pn:
            return pn, pt
    for s in (1.0, -1.0):  # sliding with u_t of sign s, p_t = -s mu p_n
        denom = wnn - s * mu * wnt
        if denom <= 0.0:
            continue
        pn = -(ufn + bias) / denom
        pt = -s * mu * pn
        ut = uft + wnt * pn + wtt * pt
        if pn >= 0.0 and s * ut >= 0.0:
            return pn, pt
    pn = -(ufn + bias) / wnn  # degenerate W: frictionless fallback
    return pn, 0.0


# Point and body indices are read from arrays as unsigned integers in the sweep's helpers: numba
# then skips the wrap-around test that a possibly negative index costs on every access (the
# indices are never negative, and the arithmetic is unchanged, bit for bit).


def tangential_slip(problem, k):
    """The tangential velocity (m s-1) that ``problem`` adds at point k to the bodies' relative
    velocity: ``problem.slip[k]`` for a :class:`solver.solve_records.PeriodicContactProblem` (a
    pair across a moving boundary: the image moves with the cell), none for a
    :class:`ContactProblem`, whose compiled kernels are those without the term (it adds -0.0,
    which leaves every float as it is and which the compiler drops)."""
    return problem.slip[k] if hasattr(problem, "slip") else -0.0


@overload(tangential_slip, jit_options={"cache": True})
def _tangential_slip(problem, k):
    if "slip" in getattr(problem, "fields", ()):
        return lambda problem, k: problem.slip[k]
    return lambda problem, k: -0.0


@njit(cache=True)
def relative_velocity(k, problem, velocities):
    """Relative velocity (u_n, u_t) of body b with respect to body a at point k (m s-1), with
    the problem's :func:`tangential_slip` (the normal one is in its Signorini shift ``bias``)."""
    vx, vy, w = velocities
    bb, aa = np.uint64(problem.b[k]), np.uint64(problem.a[k])
    ubx = vx[bb] - w[bb] * problem.rby[k]
    uby = vy[bb] + w[bb] * problem.rbx[k]
    uax = vx[aa] - w[aa] * problem.ray[k]
    uay = vy[aa] + w[aa] * problem.rax[k]
    dx, dy = ubx - uax, uby - uay
    nx, ny = problem.nx[k], problem.ny[k]
    return dx * nx + dy * ny, (-dx * ny + dy * nx) + tangential_slip(problem, k)


@njit(cache=True)
def apply_impulse_change(k, dpn, dpt, problem, velocities):
    """Add the impulse change (dpn, dpt) of point k to the velocities of its two bodies. A body
    that cannot move (zero inverse mass and inertia) is written too, with a zero change: a
    branch around it compiles into a several times slower sweep."""
    vx, vy, w = velocities
    minv_xx, minv_xy, minv_yy, iinv = problem.minv_xx, problem.minv_xy, problem.minv_yy, problem.iinv
    nx, ny = problem.nx[k], problem.ny[k]
    px = dpn * nx - dpt * ny
    py = dpn * ny + dpt * nx
    bb, aa = np.uint64(problem.b[k]), np.uint64(problem.a[k])
    vx[bb] += minv_xx[bb] * px + minv_xy[bb] * py
    vy[bb] += minv_xy[bb] * px + minv_yy[bb] * py
    w[bb] += iinv[bb] * _cross(problem.rbx[k], problem.rby[k], px, py)
    vx[aa] -= minv_xx[aa] * px + minv_xy[aa] * py
    vy[aa] -= minv_xy[aa] * px + minv_yy[aa] * py
    w[aa] -= iinv[aa] * _cross(problem.rax[k], problem.ray[k], px, py)


@njit(cache=True)
def _next_random(state):
    """xorshift64* (Vigna 2016): the next state and a 64-bit pseudo-random integer. The NLGS
    keeps its own generator so that shuffling never touches numba's global one."""
    x = state
    x ^= x >> np.uint64(12)
    x ^= x << np.uint64(25)
    x ^= x >> np.uint64(27)
    return x, x * np.uint64(2685821657736338717)


@njit(cache=True)
def _shuffle(order, state):
    """Fisher-Yates shuffle of ``order`` in place; returns the generator's next state."""
    for i in range(order.size - 1, 0, -1):
        state, r = _next_random(state)
        j = np.int64(r % np.uint64(i + 1))
        order[i], order[j] = order[j], order[i]
    return state


@njit(cache=True, inline="always")
def stalled(it, quad, tol, watch, stall):
    """The stall test after sweep ``it`` of quadratic norm ``quad`` (module docstring):
    ``watch`` = [best norm so far, best at the previous check] (float64 (2,), updated in place,
    starting at [inf, inf]); ``stall`` the sweeps between checks (0: never stalled). A sweep
    whose quadratic norm already meets ``tol`` never stalls: only the max norm is left to meet,
    and the quadratic norm need not fall for it."""
    if quad < watch[0]:
        watch[0] = quad
    if stall <= 0 or it % stall != 0 or quad <= tol:
        return False
    if watch[0] > (1.0 - STALL_IMPROVEMENT) * watch[1]:
        return True
    watch[1] = watch[0]
    return False


@njit(cache=True)
def solve(problem, impulses, velocities, limits, shuffle, seed):
    """Run NLGS sweeps until convergence, a stall (``limits.stall`` sweeps, module docstring) or
    ``limits.max_iterations`` sweeps; ``impulses`` (:class:`Impulses`) and ``velocities``
    (:class:`Velocities`) are updated in place. ``shuffle`` visits the points in a random order
    seeded by ``seed``.

    On entry ``impulses`` hold the warm start and ``velocities`` the free velocities; they are
    combined first. A stress-controlled cell's rate is solved after every sweep
    (:func:`solver.cell_coupling.couple_cell`). Returns (iterations, quadratic residual, max
    residual).
    """
    m = problem.a.size
    blocks = delassus(problem)
    # velocities consistent with the warm-start impulses
    velocities_from_impulses(problem, impulses, velocities)
    couple_cell(problem, impulses)
    order = np.arange(m)
    state = np.uint64(seed) * np.uint64(0x9E3779B97F4A7C15) + np.uint64(1)  # never 0
    quad = 0.0
    worst = 0.0
    watch = np.full(2, np.inf)
    tol, max_tol = limits.tolerance, limits.max_tolerance
    for it in range(1, limits.max_iterations + 1):
        if shuffle:
            state = _shuffle(order, state)
        quad, worst = sweep_norms(*sweep(order, problem, impulses, velocities, blocks))
        couple_cell(problem, impulses)
        if (quad <= tol and worst <= max_tol) or stalled(it, quad, tol, watch, limits.stall):
            return it, quad, worst
    return limits.max_iterations, quad, worst


@njit(cache=True)
def sweep(order, problem, impulses, velocities, blocks):
    """One Gauss–Seidel sweep over the points in ``order``: each solves its local problem with
    the others frozen and applies its impulse change to the bodies at once. ``blocks``: the
    points' :class:`DelassusBlocks`. Returns the sum and the largest of dV_k^2 = dp_k . W_k dp_k
    over the sweep, and the scale S = sum_k p_k . W_k p_k and number of loaded points of the
    points swept, at their new impulses (module docstring; each point is swept once, so these
    are the end-of-sweep values)."""
    pn, pt = impulses
    wnn, wnt, wtt = blocks
    bias, mu = problem.bias, problem.mu
    sum_dv2 = 0.0
    max_dv2 = 0.0
    scale = 0.0
    n_active = 0
    for q in range(order.size):
        k = np.uint64(order[q])
        un, ut = relative_velocity(k, problem, velocities)
        ufn = un - wnn[k] * pn[k] - wnt[k] * pt[k]
        uft = ut - wnt[k] * pn[k] - wtt[k] * pt[k]
        new_n, new_t = local_solve(ufn, uft, bias[k], wnn[k], wnt[k], wtt[k], mu[k])
        dpn, dpt = new_n - pn[k], new_t - pt[k]
        if dpn != 0.0 or dpt != 0.0:
            apply_impulse_change(k, dpn, dpt, problem, velocities)
            dv2 = dpn * (wnn[k] * dpn + wnt[k] * dpt) + dpt * (wnt[k] * dpn + wtt[k] * dpt)
            sum_dv2 += dv2
            if dv2 > max_dv2:
                max_dv2 = dv2
        pn[k], pt[k] = new_n, new_t
        if new_n > 0.0:
            n_active += 1
            scale += new_n * (wnn[k] * new_n + wnt[k] * new_t) + new_t * (wnt[k] * new_n + wtt[k] * new_t)
    return sum_dv2, max_dv2, scale, n_active


@njit(cache=True)
def norms(sum_dv2, max_dv2, impulses, blocks):
    """The quadratic and max norms of a sweep (module docstring) from its sum and largest dV^2,
    the scale computed from the :class:`Impulses` and the points' :class:`DelassusBlocks`."""
    pn, pt = impulses
    wnn, wnt, wtt = blocks
    scale = 0.0
    n_active = 0
    for k in range(pn.size):
        if pn[k] > 0.0:
            n_active += 1
            scale += pn[k] * (wnn[k] * pn[k] + wnt[k] * pt[k]) + pt[k] * (wnt[k] * pn[k] + wtt[k] * pt[k])
    return sweep_norms(sum_dv2, max_dv2, scale, n_active)


@njit(cache=True)
def sweep_norms(sum_dv2, max_dv2, scale, n_active):
    """The quadratic and max norms of a sweep (module docstring) from its sum and largest dV^2,
    the scale S and the number of loaded points, as :func:`sweep` returns them."""
    if scale > 0.0:
        return np.sqrt(sum_dv2 / scale), np.sqrt(max_dv2 / (scale / n_active))
    quad = 0.0 if sum_dv2 == 0.0 else np.inf
    return quad, quad


@njit(cache=True)
def velocities_from_impulses(problem, impulses, velocities):
    """Add the :class:`Impulses` of every point to the bodies' :class:`Velocities` in place:
    v = v_free + M^-1 H p when called on the free velocities."""
    pn, pt = impulses
    for k in range(problem.a.size):
        apply_impulse_change(k, pn[k], pt[k], problem, velocities)


def solve_problem(problem: ContactProblem, pn, pt, vx, vy, w, *, tolerance, max_tolerance, max_iterations,
                  shuffle=False, seed=0, stall=0) -> NLGSResult:
    """Solve ``problem`` by NLGS sweeps until both norms are within their tolerances, the
    sweeps stall (``stall`` sweeps without a 5% fall of the quadratic norm, module docstring;
    0: never) or ``max_iterations`` sweeps have run. ``pn, pt`` (P,) hold the warm-start
    impulses (N s) and ``vx, vy, w`` (B,) the free velocities on entry; all five are updated in
    place to the solution. ``shuffle`` visits the points in a random order seeded by ``seed``."""
    iterations, residual, worst = solve(problem, Impulses(pn, pt), Velocities(vx, vy, w),
                                        Limits(float(tolerance), float(max_tolerance), int(max_iterations),
                                               int(stall)), bool(shuffle), int(seed))
    return NLGSResult(int(iterations), float(residual), float(worst))


@njit(cache=True)
def solve_matrix(matrix, impulses, limits):
    """NLGS on a frictional contact problem given by its matrix (:class:`MatrixProblem`:
    u = W r + q with W (2n x 2n, CSR), rows 2k and 2k+1 the normal and tangential velocity of
    point k). Each point solves :func:`local_solve` (no Signorini shift: it is in q) with the
    others frozen, reading its velocity from its two rows; the stopping norms are those of
    :func:`solve` with W_k the diagonal 2x2 block (``limits.stall`` is not used). ``impulses``
    (:class:`Impulses` (n,)) hold the initial impulses and are updated in place. Returns
    (iterations, quadratic norm, max norm)."""
    indptr, indices, data, q, mu = matrix
    rn, rt = impulses
    tol, max_tol, max_iterations = limits.tolerance, limits.max_tolerance, limits.max_iterations
    n = mu.size
    wnn = np.zeros(n)
    wnt = np.zeros(n)
    wtt = np.zeros(n)
    for k in range(n):
        for e in range(indptr[2 * k], indptr[2 * k + 1]):
            if indices[e] == 2 * k:
                wnn[k] += data[e]
            elif indices[e] == 2 * k + 1:
                wnt[k] += data[e]
        for e in range(indptr[2 * k + 1], indptr[2 * k + 2]):
            if indices[e] == 2 * k + 1:
                wtt[k] += data[e]
    quad = 0.0
    worst = 0.0
    for it in range(1, max_iterations + 1):
        sum_dv2 = 0.0
        max_dv2 = 0.0
        for k in range(n):
            un = q[2 * k]
            for e in range(indptr[2 * k], indptr[2 * k + 1]):
                c = indices[e]
                un += data[e] * (rn[c // 2] if c % 2 == 0 else rt[c // 2])
            ut = q[2 * k + 1]
            for e in range(indptr[2 * k + 1], indptr[2 * k + 2]):
                c = indices[e]
                ut += data[e] * (rn[c // 2] if c % 2 == 0 else rt[c // 2])
            ufn = un - wnn[k] * rn[k] - wnt[k] * rt[k]
            uft = ut - wnt[k] * rn[k] - wtt[k] * rt[k]
            new_n, new_t = local_solve(ufn, uft, 0.0, wnn[k], wnt[k], wtt[k], mu[k])
            dpn, dpt = new_n - rn[k], new_t - rt[k]
            dv2 = dpn * (wnn[k] * dpn + wnt[k] * dpt) + dpt * (wnt[k] * dpn + wtt[k] * dpt)
            sum_dv2 += dv2
            if dv2 > max_dv2:
                max_dv2 = dv2
            rn[k], rt[k] = new_n, new_t
        quad, worst = norms(sum_dv2, max_dv2, impulses, DelassusBlocks(wnn, wnt, wtt))
        if quad <= tol and worst <= max_tol:
            return it, quad, worst
    return max_iterations, quad, worst
