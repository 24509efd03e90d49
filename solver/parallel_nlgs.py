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
slower); a copy's velocity is the wall's imposed one before and after the solve.

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

from .nlgs import NLGSResult, delassus, norms, sweep, velocities_from_impulses

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
    the sum and the largest dV_k^2 of the sweep, as :func:`solver.nlgs.sweep`."""
    domains = ptr.size - 1
    partial = np.zeros((domains, 2))
    for d in prange(domains):
        s, top = sweep(points[ptr[d]:ptr[d + 1]], a, b, nx, ny, rax, ray, rbx, rby, bias, mu, pn, pt, vx, vy, w,
                       minv_xx, minv_xy, minv_yy, iinv, wnn, wnt, wtt)
        partial[d, 0] = s
        partial[d, 1] = top
    sum_dv2, max_dv2 = sweep(interface, a, b, nx, ny, rax, ray, rbx, rby, bias, mu, pn, pt, vx, vy, w,
                             minv_xx, minv_xy, minv_yy, iinv, wnn, wnt, wtt)
    for d in range(domains):  # in domain order: the same sum whatever the threads did
        sum_dv2 += partial[d, 0]
        max_dv2 = max(max_dv2, partial[d, 1])
    return sum_dv2, max_dv2


@njit(cache=True)
def solve_domains(ptr, points, interface, a, b, nx, ny, rax, ray, rbx, rby, bias, mu, pn, pt, vx, vy, w,
                  minv_xx, minv_xy, minv_yy, iinv, tol, max_tol, max_iterations):
    """:func:`solver.nlgs.solve` with :func:`sweep_domains` as its sweep."""
    wnn, wnt, wtt = delassus(a, b, nx, ny, rax, ray, rbx, rby, minv_xx, minv_xy, minv_yy, iinv)
    velocities_from_impulses(a, b, nx, ny, rax, ray, rbx, rby, pn, pt, vx, vy, w, minv_xx, minv_xy, minv_yy, iinv)
    quad = 0.0
    worst = 0.0
    for it in range(1, max_iterations + 1):
        sum_dv2, max_dv2 = sweep_domains(ptr, points, interface, a, b, nx, ny, rax, ray, rbx, rby, bias, mu, pn, pt,
                                         vx, vy, w, minv_xx, minv_xy, minv_yy, iinv, wnn, wnt, wtt)
        quad, worst = norms(sum_dv2, max_dv2, pn, pt, wnn, wnt, wtt)
        if quad <= tol and worst <= max_tol:
            return it, quad, worst
    return max_iterations, quad, worst


class Decomposition(NamedTuple):
    """The points of each domain (CSR: ``points[ptr[d]:ptr[d + 1]]``), the interface points,
    and the points' bodies ``a``, ``b`` with the domains' own wall copies
    (:func:`wall_copies`), whose original body is ``source[body]``."""
    ptr: np.ndarray
    points: np.ndarray
    interface: np.ndarray
    a: np.ndarray
    b: np.ndarray
    source: np.ndarray


def decompose(problem, x, domains) -> Decomposition:
    """The :class:`Decomposition` of ``problem`` with the particle centres' x (m) cut into
    ``domains`` slabs."""
    n_bodies = problem.minv_xx.size
    body_domain = body_domains(np.asarray(x, float), n_bodies, problem.minv_xx, problem.minv_yy, problem.iinv,
                               int(domains))
    ptr, points, interface = partition_points(problem.a, problem.b, body_domain, int(domains))
    a, b, source = wall_copies(problem.a, problem.b, body_domain, ptr, points)
    return Decomposition(ptr, points, interface, a, b, source)


def wall_copies(a, b, body_domain, ptr, points):
    """Bodies of every point with the walls that never move (:data:`FREE`) replaced, in each
    domain's points, by that domain's own copy of the wall; interface points keep the walls.

    Returns ``(a, b, source)``: the points' bodies, and for every body of the extended set its
    original body (the first ``body_domain.size`` are themselves; the copy of free body f for
    domain d is body ``n + d * n_free + rank(f)``)."""
    n = body_domain.size
    domains = ptr.size - 1
    free = np.flatnonzero(body_domain == FREE)
    rank = np.full(n, -1, dtype=np.int64)
    rank[free] = np.arange(free.size)
    owner = np.full(a.size, -1, dtype=np.int64)
    owner[points] = np.repeat(np.arange(domains), np.diff(ptr))
    out = []
    for bodies in (a, b):
        bodies = np.array(bodies, dtype=np.int64)
        copy = (owner >= 0) & (rank[bodies] >= 0)
        bodies[copy] = n + owner[copy] * free.size + rank[bodies[copy]]
        out.append(bodies)
    source = np.concatenate([np.arange(n), np.tile(free, domains)])
    return out[0], out[1], source


def solve_problem_domains(problem, x, pn, pt, vx, vy, w, *, domains, tolerance, max_tolerance,
                          max_iterations) -> NLGSResult:
    """Solve ``problem`` (:class:`solver.nlgs.ContactProblem`) by domain-decomposed sweeps
    (module docstring) with ``domains`` slabs of the particles whose centres have abscissae
    ``x`` (m, the first ``x.size`` bodies); arguments and result otherwise as
    :func:`solver.nlgs.solve_problem`."""
    n_bodies = problem.minv_xx.size
    ptr, points, interface, a, b, source = decompose(problem, x, domains)
    vx_all, vy_all, w_all = vx[source], vy[source], w[source]
    iterations, residual, worst = solve_domains(
        ptr, points, interface, a, b, problem.nx, problem.ny, problem.rax, problem.ray,
        problem.rbx, problem.rby, problem.bias, problem.mu, pn, pt, vx_all, vy_all, w_all, problem.minv_xx[source],
        problem.minv_xy[source], problem.minv_yy[source], problem.iinv[source], tolerance, max_tolerance,
        int(max_iterations))
    vx[:], vy[:], w[:] = vx_all[:n_bodies], vy_all[:n_bodies], w_all[:n_bodies]
    return NLGSResult(int(iterations), float(residual), float(worst))
