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
a zero change (:func:`solver.nlgs._apply`: guarding that write makes the sweep several times
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

from typing import NamedTuple

import numpy as np
from numba import njit, prange

from .nlgs import NLGSResult, delassus, sweep, sweep_norms, velocities_from_impulses

FREE = -1
"""Domain of a body that never moves (zero inverse mass and inertia): shared by every domain."""
SHARED = -2
"""Domain of a moving body that is not a particle (a wall pushed by a stress)."""


def body_domains(x, n_bodies, minv_xx, minv_yy, iinv, domains):
    """Domain of every body: particles (the first ``x.size`` bodies, centres at ``x``, m) in
    ``domains`` slabs of equal counts by x; bodies that never move :data:`FREE`; other moving
    bodies (walls under a stress) :data:`SHARED`."""
    n = x.size
    out = np.full(n_bodies, SHARED, dtype=np.int64)
    rank = np.empty(n, dtype=np.int64)
    rank[np.argsort(x, kind="stable")] = np.arange(n)
    out[:n] = rank * domains // max(n, 1)
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
def sweep_domains(ptr, points, interface, a, b, nx, ny, rax, ray, rbx, rby, bias, mu, pn, pt, vx, vy, w,
                  minv_xx, minv_xy, minv_yy, iinv, wnn, wnt, wtt):
    """One sweep: every domain at once (a thread each), then the interface serially. Returns
    the sum and the largest dV_k^2 of the sweep, the scale and the number of loaded points, as
    :func:`solver.nlgs.sweep`."""
    domains = ptr.size - 1
    partial = np.zeros((domains, 4))
    for d in prange(domains):
        s, top, scale, active = sweep(points[ptr[d]:ptr[d + 1]], a, b, nx, ny, rax, ray, rbx, rby, bias, mu, pn, pt,
                                      vx, vy, w, minv_xx, minv_xy, minv_yy, iinv, wnn, wnt, wtt)
        partial[d, 0] = s
        partial[d, 1] = top
        partial[d, 2] = scale
        partial[d, 3] = active
    sum_dv2, max_dv2, scale, n_active = sweep(interface, a, b, nx, ny, rax, ray, rbx, rby, bias, mu, pn, pt, vx, vy,
                                              w, minv_xx, minv_xy, minv_yy, iinv, wnn, wnt, wtt)
    for d in range(domains):  # in domain order: the same sums whatever the threads did
        sum_dv2 += partial[d, 0]
        max_dv2 = max(max_dv2, partial[d, 1])
        scale += partial[d, 2]
        n_active += np.int64(partial[d, 3])
    return sum_dv2, max_dv2, scale, n_active


@njit(cache=True)
def solve_domains(ptr, points, interface, a, b, nx, ny, rax, ray, rbx, rby, bias, mu, pn, pt, vx, vy, w,
                  minv_xx, minv_xy, minv_yy, iinv, tol, max_tol, max_iterations):
    """:func:`solver.nlgs.solve` with :func:`sweep_domains` as its sweep."""
    wnn, wnt, wtt = delassus(a, b, nx, ny, rax, ray, rbx, rby, minv_xx, minv_xy, minv_yy, iinv)
    velocities_from_impulses(a, b, nx, ny, rax, ray, rbx, rby, pn, pt, vx, vy, w, minv_xx, minv_xy, minv_yy, iinv)
    quad = 0.0
    worst = 0.0
    for it in range(1, max_iterations + 1):
        quad, worst = sweep_norms(*sweep_domains(ptr, points, interface, a, b, nx, ny, rax, ray, rbx, rby, bias, mu,
                                                 pn, pt, vx, vy, w, minv_xx, minv_xy, minv_yy, iinv, wnn, wnt, wtt))
        if quad <= tol and worst <= max_tol:
            return it, quad, worst
    return max_iterations, quad, worst


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

    def gather(self, problem, pn, pt, vx, vy, w):
        """The problem's arrays in the new numbering: (geometry, masses, state) with geometry =
        (a, b, nx, ny, rax, ray, rbx, rby, bias, mu), masses = (minv_xx, minv_xy, minv_yy, iinv)
        and state = (pn, pt, vx, vy, w) (copies)."""
        k, j = self.point_order, self.source
        geometry = (self.a, self.b, *(np.ascontiguousarray(v[k]) for v in (
            problem.nx, problem.ny, problem.rax, problem.ray, problem.rbx, problem.rby, problem.bias, problem.mu)))
        masses = tuple(np.ascontiguousarray(m[j]) for m in (problem.minv_xx, problem.minv_xy, problem.minv_yy,
                                                           problem.iinv))
        return geometry, masses, (pn[k], pt[k], vx[j], vy[j], w[j])

    def scatter(self, state, pn, pt, vx, vy, w):
        """Write a solved ``state`` (new numbering) back into the original arrays, in place:
        every impulse, and the velocities of the bodies that can move (a still wall's
        velocity is imposed and stays as it was)."""
        spn, spt, svx, svy, sw = state
        pn[self.point_order], pt[self.point_order] = spn, spt
        for original, solved in ((vx, svx), (vy, svy), (w, sw)):
            original[self.source[self.moving]] = solved[self.moving]


def decompose(problem, x, domains) -> Decomposition:
    """The :class:`Decomposition` of ``problem`` with the particles (centres' abscissae ``x``,
    m) cut into ``domains`` slabs."""
    n_bodies = problem.minv_xx.size
    domains = int(domains)
    body_domain = body_domains(np.asarray(x, float), n_bodies, problem.minv_xx, problem.minv_yy, problem.iinv,
                               domains)
    ptr, points, interface = partition_points(problem.a, problem.b, body_domain, domains)
    point_order = np.concatenate([points, interface])
    free = np.flatnonzero(body_domain == FREE)
    free_rank = np.full(n_bodies, -1, dtype=np.int64)
    free_rank[free] = np.arange(free.size)
    # body groups in storage order: per domain its moving bodies and its copies of the still
    # walls; then the shared bodies and the interface's still walls
    groups, free_offset, new_of = [], [], np.full(n_bodies, -1, dtype=np.int64)
    size = 0
    for d in range(domains):
        mine = np.flatnonzero(body_domain == d)
        new_of[mine] = size + np.arange(mine.size)
        free_offset.append(size + mine.size)
        groups += [mine, free]
        size += mine.size + free.size
    shared = np.flatnonzero(body_domain == SHARED)
    new_of[shared] = size + np.arange(shared.size)
    free_offset.append(size + shared.size)
    groups += [shared, free]
    source = np.concatenate(groups)
    owner = np.full(problem.a.size, domains, dtype=np.int64)  # the interface: the last "domain"
    owner[points] = np.repeat(np.arange(domains), np.diff(ptr))
    free_offset = np.asarray(free_offset, dtype=np.int64)
    renumbered = []
    for bodies in (problem.a, problem.b):
        bodies = np.asarray(bodies, dtype=np.int64)
        new = new_of[bodies]
        still = free_rank[bodies] >= 0
        new[still] = free_offset[owner[still]] + free_rank[bodies[still]]
        renumbered.append(np.ascontiguousarray(new[point_order]))
    return Decomposition(ptr, point_order, renumbered[0], renumbered[1], source, np.sort(new_of[new_of >= 0]))


def solve_problem_domains(problem, x, pn, pt, vx, vy, w, *, domains, tolerance, max_tolerance,
                          max_iterations) -> NLGSResult:
    """Solve ``problem`` (:class:`solver.nlgs.ContactProblem`) by domain-decomposed sweeps
    (module docstring) with ``domains`` slabs of the particles whose centres have abscissae
    ``x`` (m, the first ``x.size`` bodies); arguments and result otherwise as
    :func:`solver.nlgs.solve_problem`."""
    dec = decompose(problem, x, domains)
    geometry, masses, state = dec.gather(problem, pn, pt, vx, vy, w)
    iterations, residual, worst = solve_domains(dec.ptr, dec.points, dec.interface, *geometry, *state, *masses,
                                                tolerance, max_tolerance, int(max_iterations))
    dec.scatter(state, pn, pt, vx, vy, w)
    return NLGSResult(int(iterations), float(residual), float(worst))
