"""Anderson acceleration of the NLGS: the sweeps as a fixed-point map, extrapolated.

One NLGS sweep maps the impulses x = (p_n, p_t) of all points to new ones; a solution is a
fixed point. In a dense packing the sweeps converge slowly (long force chains pass a correction
on by about one contact per sweep), and Anderson acceleration (type II, Walker & Ni, SIAM J.
Numer. Anal. 49, 2011) combines the last m iterates instead of keeping the last one only. With
G the map "one sweep",

    f_k = G(x_k) - x_k,   gamma = argmin || f_k - dF gamma ||_2,
    x_{k+1} = G(x_k) - dG gamma,

with dF, dG the differences of successive f and G(x) (memory m). The extrapolated impulses are
projected back onto each point's Coulomb cone (p_n >= 0, |p_t| <= mu p_n). The sweep itself
stays the NLGS's exact point-by-point solver, so the method is NLGS with an extrapolation
between sweeps, and its stopping norms are the NLGS's own (:mod:`solver.nlgs`), measured on the
change a sweep makes.

The map G may be several sweeps (``period`` k: Anderson on G = S^k, S one sweep). The
extrapolation and its history passes cost about as much as a sweep each time they run; taking
them after every k-th sweep only divides that cost by k, and the sweeps in between carry the
extrapolation on. The stopping norms are still checked after every sweep. On the same captured
problems of sheared dense packings k = 2 needs a few more sweeps than k = 1 and less time;
over whole steps, where each run follows its own trajectory, the two are not told apart
(docs/solver.md), and k = 1 stays the default.

Safeguard: the problem is nonsmooth (contacts open, close, stick and slip between sweeps), so
when an iterate's change |f_k| grows above the previous one the history is forgotten and the
plain sweeps' result kept: the method falls back to NLGS until the sweeps contract again.

Cost. The least-squares problem is solved by its m x m normal equations, one new row per
iterate. The body velocities stay v = v_free + M^-1 H p without a pass over the points: they
are linear in the impulses, so the velocity differences dV = M^-1 H dG are kept with dG (one
row per body, not per point) and v - dV gamma is the velocity of the unprojected extrapolation;
only the points whose impulse the cone projection moved add their correction to their bodies.
The history lives in rows of m x P arrays (one contiguous row per iterate).

On several cores (``domains`` > 1) the sweeps are the domain-decomposed ones of
:mod:`solver.parallel_nlgs`, and the history and extrapolation passes run a block of points (and
of bodies) per thread. Every sum is a block's own, added in block order, so the result does not
depend on the number of threads.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from . import scratch
from .cell_coupling import couple_cell
from .nlgs import (NLGSResult, apply_impulse_change, delassus_into, stalled, sweep, sweep_norms,
                   velocities_from_impulses)
from .parallel_nlgs import solve_decomposed, start_domains, sweep_domains
from .residuals import cone_projection
from .solve_records import AndersonScratch, DelassusBlocks, Impulses, Limits, Velocities

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


# The passes below work on contiguous views (``v[lo:hi]``) indexed from 0: an index numba can
# prove non-negative needs no wrap-around check, and the loops vectorise.


# The two sums below run in LANES interleaved partial sums (term k goes to sum k mod LANES), added
# in a fixed order at the end: the order of every addition is written in the code, so the compiler
# may map the lanes onto vector registers of any width but cannot reorder the sums, and the result
# is the same bits on every processor. (Reassociation, which would let it vectorise a single
# running sum, orders the additions by the target's vector width.)
LANES = 4


@njit(cache=True)
def _dot2(a, b, c, d):
    """a . b + c . d, summed in :data:`LANES` interleaved partial sums (a block's share, the same
    for every thread count and processor)."""
    s0 = s1 = s2 = s3 = 0.0
    n = a.size
    whole = n - n % LANES
    for k in range(0, whole, LANES):
        s0 += a[k] * b[k] + c[k] * d[k]
        s1 += a[k + 1] * b[k + 1] + c[k + 1] * d[k + 1]
        s2 += a[k + 2] * b[k + 2] + c[k + 2] * d[k + 2]
        s3 += a[k + 3] * b[k + 3] + c[k + 3] * d[k + 3]
    for k in range(whole, n):
        s0 += a[k] * b[k] + c[k] * d[k]
    return (s0 + s1) + (s2 + s3)


@njit(cache=True)
def _dot2_pair(a, b, c, d, e, f):
    """(a . c + b . d, e . c + f . d), each summed as :func:`_dot2` sums it (the same bits), in one
    pass over c and d: a Gram row's term and the right-hand side's for one history row. The
    passes read c and d once instead of twice, and the two sums' eight partial sums run side by
    side (benchmarks/results/portable-sums.md)."""
    s0 = s1 = s2 = s3 = 0.0
    t0 = t1 = t2 = t3 = 0.0
    n = a.size
    whole = n - n % LANES
    for k in range(0, whole, LANES):
        s0 += a[k] * c[k] + b[k] * d[k]
        t0 += e[k] * c[k] + f[k] * d[k]
        s1 += a[k + 1] * c[k + 1] + b[k + 1] * d[k + 1]
        t1 += e[k + 1] * c[k + 1] + f[k + 1] * d[k + 1]
        s2 += a[k + 2] * c[k + 2] + b[k + 2] * d[k + 2]
        t2 += e[k + 2] * c[k + 2] + f[k + 2] * d[k + 2]
        s3 += a[k + 3] * c[k + 3] + b[k + 3] * d[k + 3]
        t3 += e[k + 3] * c[k + 3] + f[k + 3] * d[k + 3]
    for k in range(whole, n):
        s0 += a[k] * c[k] + b[k] * d[k]
        t0 += e[k] * c[k] + f[k] * d[k]
    return (s0 + s1) + (s2 + s3), (t0 + t1) + (t2 + t3)


@njit(cache=True)
def _subtract_scaled(target, rows, lo, hi, gamma, count):
    """target -= sum_j gamma_j rows[j, lo:hi] over the first ``count`` rows (``target`` is the
    block lo..hi - 1 of its array). Each row is taken as ``rows[j, lo:hi]``, a contiguous view
    the loop vectorises (a 2-D view ``rows[:, lo:hi]`` is not known to be contiguous)."""
    for j in range(count):
        g = gamma[j]
        row = rows[j, lo:hi]
        for k in range(target.size):
            target[k] -= g * row[k]


@njit(cache=True)
def _residual(gn, gt, xn, xt, fn, ft):
    """f = G(x) - x into (fn, ft), then x <- G(x); returns |f|^2 (:func:`_dot2`'s order)."""
    for k in range(gn.size):
        fn[k], ft[k] = gn[k] - xn[k], gt[k] - xt[k]
        xn[k], xt[k] = gn[k], gt[k]
    return _dot2(fn, fn, ft, ft)


@njit(cache=True)
def _point_history(lo, hi, slot, count, impulses, scratch, row, rhs):
    """The history of points lo..hi - 1 after a sweep has mapped the iterate x to G(x) =
    ``impulses``: f = G(x) - x; when ``slot`` >= 0 the differences dF, dG with the previous
    sweep are stored in row ``slot`` of the history (:class:`AndersonScratch`), and the block's
    share of the new Gram row (dF_slot . dF_j) and of the right-hand side (dF_j . f) over the
    ``count`` rows in use is added to ``row`` and ``rhs``; then previous <- current and
    x <- G(x). Returns the block's share of |f|^2."""
    pn, pt = impulses
    dfn, dft, dgn, dgt = scratch.dfn, scratch.dft, scratch.dgn, scratch.dgt
    f_n, f_t = scratch.fn[lo:hi], scratch.ft[lo:hi]
    size = _residual(pn[lo:hi], pt[lo:hi], scratch.xn[lo:hi], scratch.xt[lo:hi], f_n, f_t)
    old_fn, old_ft = scratch.fn_prev[lo:hi], scratch.ft_prev[lo:hi]
    old_gn, old_gt = scratch.gn_prev[lo:hi], scratch.gt_prev[lo:hi]
    g_n, g_t = scratch.xn[lo:hi], scratch.xt[lo:hi]
    if slot >= 0:
        new_fn, new_ft = dfn[slot, lo:hi], dft[slot, lo:hi]
        new_gn, new_gt = dgn[slot, lo:hi], dgt[slot, lo:hi]
        for k in range(f_n.size):  # the differences, and previous <- current in the same pass
            new_fn[k] = f_n[k] - old_fn[k]
            new_ft[k] = f_t[k] - old_ft[k]
            new_gn[k] = g_n[k] - old_gn[k]
            new_gt[k] = g_t[k] - old_gt[k]
            old_fn[k] = f_n[k]
            old_ft[k] = f_t[k]
            old_gn[k] = g_n[k]
            old_gt[k] = g_t[k]
        for j in range(count):  # dF_slot . dF_j and dF_j . f, in _dot2's order
            gram, right = _dot2_pair(new_fn, new_ft, dfn[j, lo:hi], dft[j, lo:hi], f_n, f_t)
            row[j] += gram
            rhs[j] += right
    else:
        old_fn[:] = f_n
        old_ft[:] = f_t
        old_gn[:] = g_n
        old_gt[:] = g_t
    return size


@njit(cache=True)
def _body_history(lo, hi, slot, velocities, scratch):
    """The velocity history of bodies lo..hi - 1: the change of ``velocities`` since the
    previous sweep stored in row ``slot`` (when >= 0) of the history (:class:`AndersonScratch`),
    and previous <- current in the same pass. Velocities are linear in the impulses
    (v = v_free + M^-1 H p), so these are M^-1 H dG."""
    vx, vy, w = velocities
    hvx, hvy, hw = scratch.hvx, scratch.hvy, scratch.hw
    if slot >= 0:
        for new, now, old in ((scratch.dvx[slot, lo:hi], vx[lo:hi], hvx[lo:hi]),
                              (scratch.dvy[slot, lo:hi], vy[lo:hi], hvy[lo:hi]),
                              (scratch.dw[slot, lo:hi], w[lo:hi], hw[lo:hi])):
            for i in range(new.size):
                new[i] = now[i] - old[i]
                old[i] = now[i]
    else:
        hvx[lo:hi] = vx[lo:hi]
        hvy[lo:hi] = vy[lo:hi]
        hw[lo:hi] = w[lo:hi]


@njit(cache=True)
def _extrapolate_bodies(lo, hi, gamma, count, velocities, scratch):
    """The velocities of bodies lo..hi - 1 at the extrapolated impulses: v - dV gamma."""
    vx, vy, w = velocities
    _subtract_scaled(vx[lo:hi], scratch.dvx, lo, hi, gamma, count)
    _subtract_scaled(vy[lo:hi], scratch.dvy, lo, hi, gamma, count)
    _subtract_scaled(w[lo:hi], scratch.dw, lo, hi, gamma, count)


@njit(cache=True)
def _extrapolate_points(lo, hi, gamma, count, problem, impulses, velocities, scratch):
    """The impulses of points lo..hi - 1 at the extrapolation G(x) - dG gamma (computed in the
    scratch's ``fn, ft``), projected onto each point's Coulomb cone; they become the next
    iterate. Where the projection moved an impulse, its change is added to the velocities of
    the point's bodies (which :func:`_extrapolate_bodies` set for the unprojected
    extrapolation)."""
    pn, pt = impulses
    e_n, e_t = scratch.fn[lo:hi], scratch.ft[lo:hi]
    e_n[:] = pn[lo:hi]
    e_t[:] = pt[lo:hi]
    _subtract_scaled(e_n, scratch.dgn, lo, hi, gamma, count)
    _subtract_scaled(e_t, scratch.dgt, lo, hi, gamma, count)
    p_n, p_t, x_n, x_t, friction = pn[lo:hi], pt[lo:hi], scratch.xn[lo:hi], scratch.xt[lo:hi], problem.mu[lo:hi]
    for q in range(e_n.size):
        qn, qt = cone_projection(e_n[q], e_t[q], friction[q])
        if qn != e_n[q] or qt != e_t[q]:
            apply_impulse_change(lo + q, qn - e_n[q], qt - e_t[q], problem, velocities)
        p_n[q], p_t[q] = qn, qt
        x_n[q], x_t[q] = qn, qt


@njit(cache=True, parallel=True)
def _history_blocks(blocks, body_blocks, slot, count, impulses, velocities, scratch):
    """:func:`_point_history` over the domains' blocks of points at once (a thread each), then
    over the interface's, and :func:`_body_history` over the blocks of bodies at once; the
    blocks' sums are added in block order into the scratch's ``row`` and ``rhs``, so the result
    does not depend on the threads."""
    n_blocks = blocks.size - 1
    domains = n_blocks - 1
    row, rhs = scratch.row, scratch.rhs
    memory = row.size
    rows = np.zeros((n_blocks, memory))
    rhss = np.zeros((n_blocks, memory))
    sizes = np.zeros(n_blocks)
    for d in prange(domains):
        sizes[d] = _point_history(blocks[d], blocks[d + 1], slot, count, impulses, scratch, rows[d], rhss[d])
    sizes[domains] = _point_history(blocks[domains], blocks[domains + 1], slot, count, impulses, scratch,
                                    rows[domains], rhss[domains])
    for d in prange(body_blocks.size - 1):
        _body_history(body_blocks[d], body_blocks[d + 1], slot, velocities, scratch)
    size = 0.0
    for d in range(n_blocks):
        size += sizes[d]
        for j in range(memory):
            row[j] += rows[d, j]
            rhs[j] += rhss[d, j]
    return size


@njit(cache=True, parallel=True)
def _extrapolate_blocks(blocks, body_blocks, gamma, count, problem, impulses, velocities, scratch):
    """:func:`_extrapolate_bodies` over the blocks of bodies at once, then
    :func:`_extrapolate_points` over the domains at once (each writes its own bodies only) and
    over the interface (the last block) alone."""
    for d in prange(body_blocks.size - 1):
        _extrapolate_bodies(body_blocks[d], body_blocks[d + 1], gamma, count, velocities, scratch)
    domains = blocks.size - 2
    for d in prange(domains):
        _extrapolate_points(blocks[d], blocks[d + 1], gamma, count, problem, impulses, velocities, scratch)
    _extrapolate_points(blocks[domains], blocks[domains + 1], gamma, count, problem, impulses, velocities, scratch)


@njit(cache=True)
def scratch_size(points, bodies, memory):
    """The floats of working memory :func:`solve_anderson` takes from its ``work`` array for a
    problem of P = ``points`` points and B = ``bodies`` bodies with history m = ``memory``:
    (4 m + 11) P + (3 m + 3) B (the history rows dF, dG of the points and dV of the bodies,
    the Delassus blocks, the iterate and its residuals, the bodies' last velocities)."""
    return (4 * memory + 11) * points + (3 * memory + 3) * bodies


@njit(cache=True)
def scratch_records(work, points, bodies, memory):
    """The :class:`AndersonScratch` and the points' :class:`DelassusBlocks` of
    :func:`solve_anderson`, cut from ``work`` (at least :func:`scratch_size` floats): history
    rows (memory x points, memory x bodies), then single arrays of points and of bodies; the
    small normal equations in new memory."""
    m, n_bodies = points, bodies
    history, rows = memory * m, memory * n_bodies
    dfn = work[0:history].reshape((memory, m))
    dft = work[history:2 * history].reshape((memory, m))
    dgn = work[2 * history:3 * history].reshape((memory, m))
    dgt = work[3 * history:4 * history].reshape((memory, m))
    start = 4 * history
    dvx = work[start:start + rows].reshape((memory, n_bodies))
    dvy = work[start + rows:start + 2 * rows].reshape((memory, n_bodies))
    dw = work[start + 2 * rows:start + 3 * rows].reshape((memory, n_bodies))
    start += 3 * rows
    singles = work[start:start + 11 * m + 3 * n_bodies]
    blocks = DelassusBlocks(singles[0:m], singles[m:2 * m], singles[2 * m:3 * m])
    xn, xt, fn, ft = singles[3 * m:4 * m], singles[4 * m:5 * m], singles[5 * m:6 * m], singles[6 * m:7 * m]
    fn_prev, ft_prev = singles[7 * m:8 * m], singles[8 * m:9 * m]
    gn_prev, gt_prev = singles[9 * m:10 * m], singles[10 * m:11 * m]
    hvx = singles[11 * m:11 * m + n_bodies]
    hvy = singles[11 * m + n_bodies:11 * m + 2 * n_bodies]
    hw = singles[11 * m + 2 * n_bodies:11 * m + 3 * n_bodies]
    scratch = AndersonScratch(xn, xt, fn, ft, fn_prev, ft_prev, gn_prev, gt_prev, dfn, dft, dgn, dgt, hvx, hvy, hw,
                              dvx, dvy, dw, np.zeros((memory, memory)), np.zeros(memory), np.zeros(memory))
    return scratch, blocks


@njit(cache=True)
def solve_anderson(blocks, problem, impulses, velocities, limits, memory, period, work):
    """Anderson-accelerated NLGS (module docstring); ``impulses`` (:class:`Impulses`),
    ``velocities`` (:class:`Velocities`), ``limits`` (:class:`Limits`), in-place updates and
    result as :func:`solver.nlgs.solve` without the ordering options; ``memory`` is m,
    ``period`` the number of sweeps that make the map G (the history is taken and the iterate
    extrapolated after every ``period``-th sweep; the stopping norms are checked after every
    sweep).

    ``blocks`` holds the boundaries of the points' blocks: ``[0, P]`` for the serial sweep over
    all points in their order, or ``[0, p_1, ..., p_D, P]`` for the domain-decomposed sweep of
    :mod:`solver.parallel_nlgs` (domain d holds the points ``p_d .. p_{d+1} - 1``, the last
    block is the interface), the problem being laid out as its :class:`Decomposition` says.

    ``work``: a float array of at least :func:`scratch_size` entries, the working memory (its
    contents on entry do not matter: every entry is written before it is read)."""
    m = problem.a.size
    n_bodies = velocities.vx.size
    if work.size < scratch_size(m, n_bodies, memory):
        raise ValueError("solve_anderson: the work array is shorter than scratch_size(points, bodies, memory)")
    parallel = blocks.size > 2
    domains = blocks.size - 2
    body_blocks = (np.arange(domains + 1) * n_bodies) // max(domains, 1)
    scratch, delassus_blocks = scratch_records(work, m, n_bodies, memory)
    if parallel:
        start_domains(blocks, problem, impulses, velocities, delassus_blocks)
    else:
        delassus_into(problem, delassus_blocks)
        velocities_from_impulses(problem, impulses, velocities)
    couple_cell(problem, impulses)
    order = np.arange(m)
    ptr = blocks[:-1].copy()
    points = order[:blocks[-2]]
    interface = order[blocks[-2]:]
    gram, row, rhs = scratch.gram, scratch.row, scratch.rhs
    scratch.xn[:] = impulses.pn
    scratch.xt[:] = impulses.pt
    tol, max_tol, max_iterations = limits.tolerance, limits.max_tolerance, limits.max_iterations
    have_prev = False
    count = 0
    head = 0
    last = np.inf
    quad = 0.0
    worst = 0.0
    watch = np.full(2, np.inf)
    for it in range(1, max_iterations + 1):
        if parallel:
            quad, worst = sweep_norms(*sweep_domains(ptr, points, interface, problem, impulses, velocities,
                                                     delassus_blocks))
        else:
            quad, worst = sweep_norms(*sweep(order, problem, impulses, velocities, delassus_blocks))
        couple_cell(problem, impulses)
        if (quad <= tol and worst <= max_tol) or stalled(it, quad, tol, watch, limits.stall):
            return it, quad, worst
        if it % period != 0 or it == max_iterations:  # the last sweep's iterate is the one its norms describe
            continue
        # the history, assuming the sweeps still contract; forgotten below if they do not
        slot = head if have_prev else -1
        used = min(count + 1, memory) if have_prev else 0
        row[:] = 0.0
        rhs[:] = 0.0
        if parallel:
            size = _history_blocks(blocks, body_blocks, slot, used, impulses, velocities, scratch)
        else:
            size = _point_history(0, m, slot, used, impulses, scratch, row, rhs)
            _body_history(0, n_bodies, slot, velocities, scratch)
        have_prev = True
        if size > last or slot < 0:  # the sweeps stopped contracting, or no history yet: plain sweep
            count = 0
            head = 0
            last = size
            continue
        last = size
        count = used
        head = (head + 1) % memory
        for j in range(count):
            gram[slot, j] = row[j]
            gram[j, slot] = row[j]
        gamma, ok = _small_solve(gram, rhs, count)
        if not ok:
            count = 0
            head = 0
            continue
        if parallel:
            _extrapolate_blocks(blocks, body_blocks, gamma, count, problem, impulses, velocities, scratch)
        else:
            _extrapolate_bodies(0, n_bodies, gamma, count, velocities, scratch)
            _extrapolate_points(0, m, gamma, count, problem, impulses, velocities, scratch)
        couple_cell(problem, impulses)
    return max_iterations, quad, worst


def solve_problem_anderson(problem, pn, pt, vx, vy, w, *, tolerance, max_tolerance, max_iterations,
                           memory=3, domains=1, x=None, period=1, stall=0, decomposition=None) -> NLGSResult:
    """Solve ``problem`` (:class:`solver.solve_records.ContactProblem`) by Anderson-accelerated NLGS
    sweeps (module docstring); same arguments, in-place updates and result as
    :func:`solver.nlgs.solve_problem`. ``memory`` is m, the number of past sweeps combined.
    With ``domains`` > 1 the sweeps are the domain-decomposed ones of
    :mod:`solver.parallel_nlgs`, the particles (the first ``x.size`` bodies, centres'
    abscissae ``x``, m) cut into that many slabs, and the history passes run a domain per
    thread too. ``period``: the sweeps between two extrapolations (Anderson on the map
    "``period`` sweeps", module docstring); ``stall`` as in :func:`solver.nlgs.solve_problem`;
    ``decomposition`` as in :func:`solver.parallel_nlgs.solve_decomposed` (with ``domains`` > 1
    only)."""
    if int(period) < 1 or int(memory) < 1:
        raise ValueError(f"memory={memory!r}, period={period!r}: expected whole numbers >= 1")
    limits = Limits(float(tolerance), float(max_tolerance), int(max_iterations), int(stall))
    if domains > 1:
        def kernel(dec, renumbered, impulses, velocities):
            work = scratch.buffer("anderson", scratch_size(dec.a.size, dec.source.size, int(memory)))
            return solve_anderson(dec.blocks, renumbered, impulses, velocities, limits, int(memory), int(period), work)

        return solve_decomposed(problem, x, domains, (pn, pt, vx, vy, w), kernel, decomposition)
    work = scratch.buffer("anderson", scratch_size(problem.a.size, problem.minv_xx.size, int(memory)))
    blocks = np.array([0, problem.a.size], dtype=np.int64)
    iterations, residual, worst = solve_anderson(blocks, problem, Impulses(pn, pt), Velocities(vx, vy, w), limits,
                                                 int(memory), int(period), work)
    return NLGSResult(int(iterations), float(residual), float(worst))
