"""NLGS on several cores: a domain-decomposed Gauss–Seidel sweep.

The particles are cut into ``D`` vertical slabs holding equal numbers of particles (by the x
of their centres). A contact point whose bodies all lie in one slab — or in one slab and on a
body that never moves (a fixed or velocity-driven wall: zero inverse mass, so the point's
impulse leaves it unchanged) — belongs to that slab's domain; every other point (across two
slabs, or on a wall pushed by a stress, which is shared by the whole sample) is an interface
point. One sweep is then:

1. the D domains swept at once, one per thread, each in the serial order of its own points
   (no two domains share a moving body, and each works on its own copy of the walls that
   never move, so no two threads ever write the same velocity);
2. the interface points swept serially after them.

The copies exist because the sweep writes every body of a point, a wall that cannot move with
a zero change (:func:`solver.nlgs.apply_impulse_change`: guarding that write makes the sweep several times
slower); a copy's velocity is the wall's imposed one before and after the solve. The problem is
also renumbered so that each domain's points and bodies are contiguous in memory
(:class:`Decomposition`): with the bodies interleaved, the two threads kept writing the same
cache lines and the parallel sweep ran slower than the serial one.

Within a domain the sweep is the serial NLGS (:func:`solver.nlgs.sweep`, the same local solver
and the same stopping norms), so the method is a Gauss–Seidel sweep in another order: it
converges to the same tolerance, to an admissible solution that differs from the serial one's
as two orders' do. For a given ``D`` the result does not depend on the number of threads or on
their timing: each domain's updates are sequential and touch only its own bodies, and the
sweep's sums are added in domain order. ``D = 1`` is not this module: the stepper then runs the
serial :func:`solver.nlgs.solve_problem` unchanged.

The slabs follow the broad phase's idea of locality (LMGC90 and Siconos decompose the same
way for their parallel NLGS); the interface is the points on the D - 1 cuts and on moving
walls, a fraction ~ D / sqrt(N) of the points.
"""

from __future__ import annotations

import os
import warnings
from typing import NamedTuple

import numpy as np
from numba import njit, prange
from numba.extending import overload

from . import scratch
from .nlgs import NLGSResult, delassus_into, stalled, sweep, sweep_norms, velocities_from_impulses
from .solve_records import ContactProblem, DelassusBlocks, Impulses, Limits, PeriodicContactProblem, Velocities

FREE = -1
"""Domain of a body that never moves (zero inverse mass and inertia): shared by every domain."""
SHARED = -2
"""Domain of a moving body that is not a particle (a wall pushed by a stress)."""


def warn_if_threads_sleep(domains, environ=None) -> bool:
    """Warn when domains are asked for while the OpenMP threads are told to sleep.

    With ``OMP_WAIT_POLICY=passive`` numba's OpenMP threads sleep between the parallel regions
    of every sweep and must be woken each time, which made a domain-decomposed sweep slower
    than the serial one (docs/solver.md, "Both cores").

    Parameters
    ----------
    domains : int
        The NLGS domains asked for; one domain never warns.
    environ : mapping, optional
        The environment read (default ``os.environ``; the thread pool reads it when it starts).

    Returns
    -------
    bool
        Whether it warned (a ``RuntimeWarning`` naming the variable and what is expected).
    """
    policy = (os.environ if environ is None else environ).get("OMP_WAIT_POLICY", "")
    if domains > 1 and policy.strip().lower() == "passive":
        warnings.warn(f"domains={domains} with OMP_WAIT_POLICY={policy}: the sweeps' threads sleep between "
                      "parallel regions, and a domain-decomposed sweep measured slower than the serial one; "
                      "expected OMP_WAIT_POLICY unset or 'active' (set before Python starts)", RuntimeWarning,
                      stacklevel=3)
        return True
    return False


def slab_of_particles(x, domains):
    """Slab of each particle (centres' abscissae ``x``, m) among ``domains`` slabs of equal
    counts by x: rank(x) * domains // n, with ties ranked by index (a stable sort's ranks).

    The slab boundaries are order statistics, so they are found by selection (``np.partition``,
    O(n)) instead of a full sort: with distinct abscissae a particle lies in slab d exactly when
    x reaches the boundary values of slabs 1 .. d. Where a boundary value is shared by several
    particles the ranks decide among them, and the stable sort is used."""
    n = x.size
    if n == 0 or domains <= 1:
        return np.zeros(n, dtype=np.int64)
    first = -(-np.arange(1, domains) * n // domains)  # the smallest rank of each slab 1 .. D - 1
    first = first[first < n]
    bounds = np.partition(x, first)[first]
    if all(np.count_nonzero(x == value) == 1 for value in np.unique(bounds)):
        return np.searchsorted(bounds, x, side="right").astype(np.int64)
    rank = np.empty(n, dtype=np.int64)
    rank[np.argsort(x, kind="stable")] = np.arange(n)
    return rank * domains // n


def body_domains(x, n_bodies, minv_xx, minv_yy, iinv, domains):
    """Domain of every body: particles (the first ``x.size`` bodies, centres at ``x``, m) in
    ``domains`` slabs of equal counts by x (:func:`slab_of_particles`); bodies that never move
    :data:`FREE`; other moving bodies (walls under a stress) :data:`SHARED`."""
    out = np.full(n_bodies, SHARED, dtype=np.int64)
    out[:x.size] = slab_of_particles(x, domains)
    still = (minv_xx == 0.0) & (minv_yy == 0.0) & (iinv == 0.0)
    out[still] = FREE
    return out


@njit(cache=True)
def partition_points(a, b, body_domain, domains):
    """Points of each domain (CSR: ``points[ptr[d]:ptr[d + 1]]``) and the interface points,
    each list in the points' own order."""
    m = a.size
    owner = np.empty(m, dtype=np.int64)
    counts = np.zeros(domains + 1, dtype=np.int64)  # the last: the interface
    for k in range(m):
        da, db = body_domain[a[k]], body_domain[b[k]]
        if da == FREE:
            d = db
        elif db == FREE or da == db:
            d = da
        else:
            d = domains
        if d < 0:  # on a shared body, or between two still ones
            d = domains
        owner[k] = d
        counts[d] += 1
    ptr = np.zeros(domains + 1, dtype=np.int64)
    for d in range(domains):
        ptr[d + 1] = ptr[d] + counts[d]
    points = np.empty(ptr[domains], dtype=np.int64)
    interface = np.empty(counts[domains], dtype=np.int64)
    fill = ptr[:domains].copy()
    n_interface = 0
    for k in range(m):
        d = owner[k]
        if d == domains:
            interface[n_interface] = k
            n_interface += 1
        else:
            points[fill[d]] = k
            fill[d] += 1
    return ptr, points, interface


@njit(cache=True, parallel=True)
def sweep_domains(ptr, points, interface, problem, impulses, velocities, blocks):
    """One sweep: every domain at once (a thread each), then the interface serially. Returns
    the sum and the largest dV_k^2 of the sweep, the scale and the number of loaded points, as
    :func:`solver.nlgs.sweep` (the same arguments after the points' lists)."""
    domains = ptr.size - 1
    partial = np.zeros((domains, 4))
    for d in prange(domains):
        s, top, scale, active = sweep(points[ptr[d]:ptr[d + 1]], problem, impulses, velocities, blocks)
        partial[d, 0] = s
        partial[d, 1] = top
        partial[d, 2] = scale
        partial[d, 3] = active
    sum_dv2, max_dv2, scale, n_active = sweep(interface, problem, impulses, velocities, blocks)
    for d in range(domains):  # in domain order: the same sums whatever the threads did
        sum_dv2 += partial[d, 0]
        max_dv2 = max(max_dv2, partial[d, 1])
        scale += partial[d, 2]
        n_active += np.int64(partial[d, 3])
    return sum_dv2, max_dv2, scale, n_active


@njit(cache=True)
def points_slice(problem, lo, hi):
    """The points lo..hi - 1 of ``problem`` as a problem of their own (views; the body arrays
    whole)."""
    p = problem
    return ContactProblem(p.a[lo:hi], p.b[lo:hi], p.nx[lo:hi], p.ny[lo:hi], p.rax[lo:hi], p.ray[lo:hi], p.rbx[lo:hi],
                          p.rby[lo:hi], p.bias[lo:hi], p.mu[lo:hi], p.minv_xx, p.minv_xy, p.minv_yy, p.iinv)


@njit(cache=True)
def _start_block(lo, hi, problem, impulses, velocities, blocks):
    """The Delassus blocks of points lo..hi - 1 (:func:`solver.nlgs.delassus_into`), then their
    impulses added to their bodies' velocities (:func:`solver.nlgs.velocities_from_impulses`)."""
    part = points_slice(problem, lo, hi)
    delassus_into(part, DelassusBlocks(blocks.nn[lo:hi], blocks.nt[lo:hi], blocks.tt[lo:hi]))
    velocities_from_impulses(part, Impulses(impulses.pn[lo:hi], impulses.pt[lo:hi]), velocities)


@njit(cache=True, parallel=True)
def start_domains(blocks, problem, impulses, velocities, delassus_blocks):
    """The start of a domain-decomposed solve, a block of points per thread: each point's
    Delassus block into ``delassus_blocks`` (:func:`solver.nlgs.delassus_into`), then the
    impulses added to the velocities (:func:`solver.nlgs.velocities_from_impulses`), the
    domains at once (each writes its own bodies only) and the interface (the last block) after
    them. ``blocks``: ``[0, p_1, ..., p_D, P]`` of the renumbered problem
    (:attr:`Decomposition.blocks`). Every body receives its points' impulses in the order the
    serial pass over all points would add them, so the velocities are the serial ones bit for
    bit."""
    domains = blocks.size - 2
    for d in prange(domains):  # a loop of D iterations gives each of D threads one domain
        _start_block(blocks[d], blocks[d + 1], problem, impulses, velocities, delassus_blocks)
    _start_block(blocks[domains], blocks[domains + 1], problem, impulses, velocities, delassus_blocks)


@njit(cache=True)
def solve_domains(ptr, points, interface, problem, impulses, velocities, limits):
    """:func:`solver.nlgs.solve` with :func:`sweep_domains` as its sweep (the problem laid out
    as its :class:`Decomposition` says: ``points`` and ``interface`` contiguous, in order)."""
    m = problem.a.size
    delassus_blocks = DelassusBlocks(np.empty(m), np.empty(m), np.empty(m))
    blocks = np.empty(ptr.size + 1, dtype=np.int64)
    blocks[:ptr.size] = ptr
    blocks[ptr.size] = m
    start_domains(blocks, problem, impulses, velocities, delassus_blocks)
    quad = 0.0
    worst = 0.0
    watch = np.full(2, np.inf)
    tol, max_tol = limits.tolerance, limits.max_tolerance
    for it in range(1, limits.max_iterations + 1):
        quad, worst = sweep_norms(*sweep_domains(ptr, points, interface, problem, impulses, velocities,
                                                 delassus_blocks))
        if (quad <= tol and worst <= max_tol) or stalled(it, quad, tol, watch, limits.stall):
            return it, quad, worst
    return limits.max_iterations, quad, worst


class Decomposition(NamedTuple):
    """A contact problem laid out for the domain-decomposed sweep.

    The points are renumbered so that each domain's points are contiguous — domain d holds
    ``ptr[d] .. ptr[d + 1] - 1``, the interface ``ptr[-1] ..`` — and so are the bodies: each
    domain's moving bodies, then its own copies of the walls that never move, domain after
    domain, then the shared bodies (walls pushed by a stress) and the still walls the interface
    uses. Two threads then write the same cache line of the impulses or of the velocities at
    most at the edge of two blocks (interleaved storage made the sweep several times slower
    than the serial one).

    ``point_order[k]``: the original point of point k; ``source[j]``: the original body of body
    j; ``a``, ``b``: the points' bodies in the new numbering; ``moving``: the new numbers of the
    bodies that can move (each appears once), whose velocities the solve returns.
    """
    ptr: np.ndarray
    point_order: np.ndarray
    a: np.ndarray
    b: np.ndarray
    source: np.ndarray
    moving: np.ndarray

    @property
    def points(self):
        """The domains' points in the new numbering (contiguous by domain)."""
        return np.arange(self.ptr[-1])

    @property
    def interface(self):
        """The interface points in the new numbering."""
        return np.arange(self.ptr[-1], self.point_order.size)

    @property
    def gathered_size(self):
        """Floats that :meth:`gather` writes: 11 per point (the last, a periodic problem's
        slip, unused otherwise) and 7 per body, new numbering."""
        return 11 * self.point_order.size + 7 * self.source.size

    @property
    def blocks(self):
        """The boundaries of the points' blocks in the new numbering: ``ptr`` then the number of
        points (the last block is the interface)."""
        return np.append(self.ptr, self.point_order.size)

    def gather(self, problem, pn, pt, vx, vy, w, out=None):
        """The problem and its state in the new numbering: (:class:`ContactProblem`,
        :class:`Impulses`, :class:`Velocities`) (copies; :func:`gather_into`), in ``out`` (a
        float array of at least :attr:`gathered_size` entries) or in new memory."""
        return gather_into(self, problem, Impulses(pn, pt), Velocities(vx, vy, w),
                           np.empty(self.gathered_size) if out is None else out)

    def scatter(self, impulses, velocities, pn, pt, vx, vy, w):
        """Write solved ``impulses`` and ``velocities`` (new numbering) back into the original
        arrays, in place: every impulse, and the velocities of the bodies that can move (a
        still wall's velocity is imposed and stays as it was; :func:`scatter_from`)."""
        scatter_from(self, impulses, velocities, Impulses(pn, pt), Velocities(vx, vy, w))


def point_slip(problem, k):
    """A periodic problem's ``slip[k]`` (:class:`PeriodicContactProblem`); 0.0 for a
    :class:`ContactProblem`, which has none (the row is then not read)."""
    return problem.slip[k] if hasattr(problem, "slip") else 0.0


@overload(point_slip, jit_options={"cache": True})
def _point_slip(problem, k):
    if "slip" in getattr(problem, "fields", ()):
        return lambda problem, k: problem.slip[k]
    return lambda problem, k: 0.0


def renumbered_problem(problem, a, b, points, bodies):
    """The problem of the kind of ``problem`` from the renumbered bodies ``a``, ``b`` and the
    gathered rows ``points`` (nx .. mu, then slip at row 10) and ``bodies`` (minv_xx .. iinv)."""
    fields = (a, b, *points[:8], *bodies[:4])
    return PeriodicContactProblem(*fields, points[10]) if hasattr(problem, "slip") else ContactProblem(*fields)


@overload(renumbered_problem, jit_options={"cache": True})
def _renumbered_problem(problem, a, b, points, bodies):
    if "slip" in getattr(problem, "fields", ()):
        def periodic(problem, a, b, points, bodies):
            return PeriodicContactProblem(a, b, points[0], points[1], points[2], points[3], points[4], points[5],
                                          points[6], points[7], bodies[0], bodies[1], bodies[2], bodies[3], points[10])
        return periodic

    def walled(problem, a, b, points, bodies):
        return ContactProblem(a, b, points[0], points[1], points[2], points[3], points[4], points[5], points[6],
                              points[7], bodies[0], bodies[1], bodies[2], bodies[3])
    return walled


@njit(cache=True, parallel=True)
def gather_into(decomposition, problem, impulses, velocities, out):
    """Copies in the new numbering of ``decomposition`` (:class:`Decomposition`): the eleven
    point arrays (nx .. rby, bias, mu, pn, pt, and a periodic problem's slip) taken at its
    ``point_order``, then the seven body arrays (minv_xx .. iinv, vx, vy, w) at its ``source``,
    written into ``out`` (11 P + 7 B floats or more). Plain copies, shared among the threads.
    Returns the renumbered (problem of ``problem``'s kind, :class:`Impulses`,
    :class:`Velocities`), views of ``out``."""
    point_order, source = decomposition.point_order, decomposition.source
    p = problem
    pn, pt = impulses
    vx, vy, w = velocities
    m = point_order.size
    points = out[:11 * m].reshape((11, m))
    for q in prange(m):
        k = point_order[q]
        points[0, q], points[1, q], points[2, q] = p.nx[k], p.ny[k], p.rax[k]
        points[3, q], points[4, q], points[5, q] = p.ray[k], p.rbx[k], p.rby[k]
        points[6, q], points[7, q], points[8, q], points[9, q] = p.bias[k], p.mu[k], pn[k], pt[k]
        points[10, q] = point_slip(p, k)
    n = source.size
    bodies = out[11 * m:11 * m + 7 * n].reshape((7, n))
    for q in prange(n):
        j = source[q]
        bodies[0, q], bodies[1, q], bodies[2, q], bodies[3, q] = p.minv_xx[j], p.minv_xy[j], p.minv_yy[j], p.iinv[j]
        bodies[4, q], bodies[5, q], bodies[6, q] = vx[j], vy[j], w[j]
    renumbered = renumbered_problem(problem, decomposition.a, decomposition.b, points, bodies)
    return renumbered, Impulses(points[8], points[9]), Velocities(bodies[4], bodies[5], bodies[6])


@njit(cache=True)
def scatter_from(decomposition, solved_impulses, solved_velocities, impulses, velocities):
    """:meth:`Decomposition.scatter`: the solved impulses (new numbering) back to their points,
    the moving bodies' solved velocities back to their bodies, in place."""
    point_order, source, moving = decomposition.point_order, decomposition.source, decomposition.moving
    for q in range(point_order.size):
        k = point_order[q]
        impulses.pn[k] = solved_impulses.pn[q]
        impulses.pt[k] = solved_impulses.pt[q]
    for i in range(moving.size):
        q = moving[i]
        j = source[q]
        velocities.vx[j] = solved_velocities.vx[q]
        velocities.vy[j] = solved_velocities.vy[q]
        velocities.w[j] = solved_velocities.w[q]


@njit(cache=True)
def renumber(a, b, body_domain, ptr, points, interface, domains):
    """The numbering of :class:`Decomposition`: (point_order, a, b, source, moving) for points
    ``a, b`` whose bodies lie in ``body_domain`` and whose domains are ``points[ptr[d]:ptr[d +
    1]]`` and ``interface`` (:func:`partition_points`). Bodies are stored group by group — per
    domain its moving bodies then its copies of the still walls, then the shared bodies and the
    interface's still walls — each group in the bodies' own order."""
    n_bodies = body_domain.size
    count = np.zeros(domains + 1, dtype=np.int64)  # moving bodies per group; the last: the shared ones
    free_rank = np.full(n_bodies, -1, dtype=np.int64)
    n_free = 0
    for j in range(n_bodies):
        d = body_domain[j]
        if d == FREE:
            free_rank[j] = n_free
            n_free += 1
        else:
            count[domains if d == SHARED else d] += 1
    start = np.zeros(domains + 1, dtype=np.int64)
    size = 0
    for g in range(domains + 1):
        start[g] = size
        size += count[g] + n_free
    source = np.empty(size, dtype=np.int64)
    new_of = np.full(n_bodies, -1, dtype=np.int64)
    fill = start.copy()
    for j in range(n_bodies):
        d = body_domain[j]
        if d != FREE:
            g = domains if d == SHARED else d
            new_of[j] = fill[g]
            source[fill[g]] = j
            fill[g] += 1
        else:
            for g in range(domains + 1):
                source[start[g] + count[g] + free_rank[j]] = j
    m = a.size
    point_order = np.empty(m, dtype=np.int64)
    new_a = np.empty(m, dtype=np.int64)
    new_b = np.empty(m, dtype=np.int64)
    n_inner = ptr[domains]
    point_order[:n_inner] = points
    point_order[n_inner:] = interface
    g = 0
    for q in range(m):
        while g < domains and q >= ptr[g + 1]:
            g += 1
        k = point_order[q]
        for body, out in ((a[k], new_a), (b[k], new_b)):
            out[q] = start[g] + count[g] + free_rank[body] if free_rank[body] >= 0 else new_of[body]
    moving = np.empty(size - (domains + 1) * n_free, dtype=np.int64)
    n = 0
    for g in range(domains + 1):
        for i in range(count[g]):
            moving[n] = start[g] + i
            n += 1
    return point_order, new_a, new_b, source, moving


def decompose(problem, x, domains) -> Decomposition:
    """The :class:`Decomposition` of ``problem`` with the particles (centres' abscissae ``x``,
    m) cut into ``domains`` slabs."""
    domains = int(domains)
    body_domain = body_domains(np.asarray(x, float), problem.minv_xx.size, problem.minv_xx, problem.minv_yy,
                               problem.iinv, domains)
    ptr, points, interface = partition_points(problem.a, problem.b, body_domain, domains)
    point_order, a, b, source, moving = renumber(np.asarray(problem.a, dtype=np.int64),
                                                 np.asarray(problem.b, dtype=np.int64), body_domain, ptr, points,
                                                 interface, domains)
    return Decomposition(ptr, point_order, a, b, source, moving)


def solve_problem_domains(problem, x, pn, pt, vx, vy, w, *, domains, tolerance, max_tolerance,
                          max_iterations, stall=0, decomposition=None) -> NLGSResult:
    """Solve ``problem`` (:class:`solver.solve_records.ContactProblem`) by domain-decomposed sweeps
    (module docstring) with ``domains`` slabs of the particles whose centres have abscissae
    ``x`` (m, the first ``x.size`` bodies); arguments and result otherwise as
    :func:`solver.nlgs.solve_problem`. ``decomposition``: the problem's :func:`decompose`, when
    the caller already has it (:func:`solve_decomposed`)."""
    limits = Limits(float(tolerance), float(max_tolerance), int(max_iterations), int(stall))

    def kernel(dec, renumbered, impulses, velocities):
        return solve_domains(dec.ptr, dec.points, dec.interface, renumbered, impulses, velocities, limits)

    return solve_decomposed(problem, x, domains, (pn, pt, vx, vy, w), kernel, decomposition)


def solve_decomposed(problem, x, domains, state, kernel, decomposition=None) -> NLGSResult:
    """Lay ``problem`` out by ``domains`` slabs of the particles (centres' abscissae ``x``, m;
    :func:`decompose`), run ``kernel(decomposition, problem, impulses, velocities)`` on the
    renumbered records (:meth:`Decomposition.gather`; it returns sweeps and the two norms) and
    write the solved impulses and velocities back into ``state`` = (pn, pt, vx, vy, w), in
    place.

    ``decomposition``: the :func:`decompose` of a problem with the same points, bodies and
    masses (another right-hand side or friction, as the overlap recovery's), made from the
    same ``x`` on ``domains`` domains (``x`` is then not read again); made here when None."""
    dec = decompose(problem, x, domains) if decomposition is None else decomposition
    if dec.point_order.size != problem.a.size or dec.ptr.size != int(domains) + 1:
        raise ValueError(f"the decomposition is of {dec.point_order.size} points on {dec.ptr.size - 1} domains, the "
                         f"problem has {problem.a.size} points on {int(domains)} domains: expected the same")
    out = scratch.buffer("renumbered", dec.gathered_size)
    renumbered, impulses, velocities = dec.gather(problem, *state, out=out)
    iterations, residual, worst = kernel(dec, renumbered, impulses, velocities)
    dec.scatter(impulses, velocities, *state)
    return NLGSResult(int(iterations), float(residual), float(worst))
