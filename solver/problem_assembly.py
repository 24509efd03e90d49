"""The step's contact problem assembled from the detected points, in one pass over the points.

For each point k between bodies a (a particle) and b (a particle or a wall), at the contact
point x_k with unit normal n_k from a to b:

    r_a = x_k - c_a,   r_b = x_k - c_b (0 for a wall: walls do not rotate),
    u_0 = v_b + w_b (-r_b,y, r_b,x) - v_a - w_a (-r_a,y, r_a,x),    u_n0 = u_0 . n_k,
    g* = g_k + h (1 - theta) u_n0,
    bias_k = max(g*, 0) / (theta h),
    mu_k = the wall friction for a wall, the particle friction otherwise,

with c the centres (walls: their reference point), v, w the start-of-step velocities, g_k the
gap, h the time step and theta the Moreau–Jean parameter. g* is the gap predicted to mid-step
with the start velocities; bias is the Signorini shift of the IQS law (u_n + bias >= 0: an open
gap may close within the step, an existing overlap is not pushed out; docs/solver.md). The
kernel does in one loop what :func:`assemble_reference` does with whole-array numpy
operations, in the same floating-point order, so the two agree bit for bit.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def assemble(points, start, law):
    """Lever arms ra, rb (P, 2) m, normal components nx, ny (P,), Signorini shifts bias (P,)
    m s-1 and friction coefficients mu (P,) of every point (module docstring), returned with the
    points' bodies a, b (int64) as (a, b, ra, rb, nx, ny, bias, mu).

    ``points``: the detected points (:class:`solver.narrowphase.ContactPoints`: ``point``,
    ``normal``, ``gap``, ``body_i``, ``body_j`` are read); ``start``: the bodies at the start of
    the step (:class:`solver.solve_records.StepStart`, particles then walls); ``law``: time
    step, theta and friction (:class:`solver.solve_records.StepLaw`)."""
    point, normal, gap, body_i, body_j = points.point, points.normal, points.gap, points.body_i, points.body_j
    centre, v_start, omega_start, n_particles = start
    time_step, theta, friction, wall_friction = law
    m = gap.size
    a = body_i.astype(np.int64)
    b = body_j.astype(np.int64)
    ra = np.empty((m, 2))
    rb = np.empty((m, 2))
    nx = np.empty(m)
    ny = np.empty(m)
    bias = np.empty(m)
    mu = np.empty(m)
    advance = time_step * (1 - theta)
    scale = theta * time_step
    for k in range(m):
        i, j = a[k], b[k]
        rax = point[k, 0] - centre[i, 0]
        ray = point[k, 1] - centre[i, 1]
        rbx = point[k, 0] - centre[j, 0]
        rby = point[k, 1] - centre[j, 1]
        if j >= n_particles:
            rbx = 0.0
            rby = 0.0
        ra[k, 0], ra[k, 1], rb[k, 0], rb[k, 1] = rax, ray, rbx, rby
        nx[k] = normal[k, 0]
        ny[k] = normal[k, 1]
        ux = v_start[j, 0] + omega_start[j] * -rby - v_start[i, 0] - omega_start[i] * -ray
        uy = v_start[j, 1] + omega_start[j] * rbx - v_start[i, 1] - omega_start[i] * rax
        g_star = gap[k] + advance * (ux * nx[k] + uy * ny[k])
        bias[k] = max(g_star, 0.0) / scale
        mu[k] = wall_friction if j >= n_particles else friction
    return a, b, ra, rb, nx, ny, bias, mu


def assemble_reference(points, start, law):
    """:func:`assemble` with whole-array numpy operations: the slow, plain reference."""
    point, normal, gap, body_i, body_j = points.point, points.normal, points.gap, points.body_i, points.body_j
    centre, v_start, omega_start, n_particles = start
    h, theta, friction, wall_friction = law
    a, b = body_i.astype(np.int64), body_j.astype(np.int64)
    ra = point - centre[a]
    rb = point - centre[b]
    rb[b >= n_particles] = 0.0
    nx, ny = normal[:, 0].copy(), normal[:, 1].copy()
    u0 = (v_start[b] + omega_start[b, None] * np.stack([-rb[:, 1], rb[:, 0]], -1)
          - v_start[a] - omega_start[a, None] * np.stack([-ra[:, 1], ra[:, 0]], -1))
    un0 = u0[:, 0] * nx + u0[:, 1] * ny
    g_star = gap + h * (1 - theta) * un0
    bias = np.maximum(g_star, 0.0) / (theta * h)
    mu = np.where(b >= n_particles, wall_friction, friction)
    return a, b, ra, rb, nx, ny, bias, mu


@njit(cache=True)
def end_gaps(points, problem, velocity, omega, time_step):
    """The gaps (P,) m at the end of the step, to first order: g_k + h u_k . n_k, with u_k the
    relative velocity (b minus a, m s-1) at the point from the bodies' step velocities
    ``velocity`` (bodies, 2) and ``omega`` (bodies,), h the ``time_step``, the gaps g_k and
    normals of the detected ``points`` (:class:`solver.narrowphase.ContactPoints`) and the bodies
    and lever arms of their :class:`solver.solve_records.ContactProblem`; what the overlap
    recovery removes where it is negative. Computed as ``(g + h (v_b - v_a) . n) + h (w_b (r_b x
    n) - w_a (r_a x n))`` with r x n = r_x n_y - r_y n_x, the floating-point order of the
    stepper's numpy expression it replaces."""
    gap, normal = points.gap, points.normal
    a, b = problem.a, problem.b
    m = gap.size
    out = np.empty(m)
    for k in range(m):
        i, j = a[k], b[k]
        n_x, n_y = normal[k, 0], normal[k, 1]
        translation = gap[k] + time_step * ((velocity[j, 0] - velocity[i, 0]) * n_x
                                            + (velocity[j, 1] - velocity[i, 1]) * n_y)
        cross_b = problem.rbx[k] * n_y - problem.rby[k] * n_x
        cross_a = problem.rax[k] * n_y - problem.ray[k] * n_x
        out[k] = translation + time_step * (omega[j] * cross_b - omega[i] * cross_a)
    return out
