"""The step's contact problem in a periodic cell: :mod:`solver.problem_assembly` with each
point's body b taken at its image.

For a point between body a and the image (m, n) of body b (:mod:`solver.periodic_detection`),
the image's centre is c_b + s with s = m a + n b and its velocity v_b + V with V = n db/dt
(:mod:`solver.periodic_cell`; da/dt = 0). Then

    r_b = x_k - (c_b + s),   u_0 = (v_b + V) + w_b x r_b - v_a - w_a x r_a,
    g* = g_k + h (1 - theta) u_0 . n_k,
    bias_k = max(g*, 0) / (theta h) + V . n_k,   slip_k = V . t_k,  t = (-n_y, n_x),

so that the solver's u_n + bias_k >= 0 and its tangential velocity (with ``slip``,
:func:`solver.nlgs.tangential_slip`) are those of the image: the IQS law and Coulomb's law of
the real pair. Inside the cell (s = 0, V = 0) every value is the walled assembly's, operation
for operation, but for the ``+ 0.0`` of the zero shift.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit


class Images(NamedTuple):
    """Where body b of each point stands and moves relative to body b itself (P, 2): ``shift``
    m a + n b (m) and ``velocity`` n db/dt (m s-1)."""

    shift: np.ndarray
    velocity: np.ndarray


@njit(cache=True)
def assemble(points, images, start, law):
    """(a, b, ra, rb, nx, ny, bias, mu, slip) of every point (module doc): ``points`` the
    :class:`solver.narrowphase.ContactPoints`, ``images`` their :class:`Images`, ``start`` the
    :class:`solver.solve_records.StepStart`, ``law`` the :class:`solver.solve_records.StepLaw`."""
    point, normal, gap, body_i, body_j = points.point, points.normal, points.gap, points.body_i, points.body_j
    centre, v_start, omega_start, n_particles = start
    time_step, theta, friction, wall_friction = law
    shift, image_velocity = images
    m = gap.size
    a = body_i.astype(np.int64)
    b = body_j.astype(np.int64)
    ra = np.empty((m, 2))
    rb = np.empty((m, 2))
    nx = np.empty(m)
    ny = np.empty(m)
    bias = np.empty(m)
    mu = np.empty(m)
    slip = np.empty(m)
    advance = time_step * (1 - theta)
    scale = theta * time_step
    for k in range(m):
        i, j = a[k], b[k]
        rax = point[k, 0] - centre[i, 0]
        ray = point[k, 1] - centre[i, 1]
        rbx = point[k, 0] - (centre[j, 0] + shift[k, 0])
        rby = point[k, 1] - (centre[j, 1] + shift[k, 1])
        if j >= n_particles:
            rbx = 0.0
            rby = 0.0
        ra[k, 0], ra[k, 1], rb[k, 0], rb[k, 1] = rax, ray, rbx, rby
        nx[k] = normal[k, 0]
        ny[k] = normal[k, 1]
        vx = image_velocity[k, 0]
        vy = image_velocity[k, 1]
        ux = v_start[j, 0] + vx + omega_start[j] * -rby - v_start[i, 0] - omega_start[i] * -ray
        uy = v_start[j, 1] + vy + omega_start[j] * rbx - v_start[i, 1] - omega_start[i] * rax
        g_star = gap[k] + advance * (ux * nx[k] + uy * ny[k])
        bias[k] = max(g_star, 0.0) / scale + (vx * nx[k] + vy * ny[k])
        slip[k] = -vx * ny[k] + vy * nx[k]
        mu[k] = wall_friction if j >= n_particles else friction
    return a, b, ra, rb, nx, ny, bias, mu, slip


@njit(cache=True)
def stress_sums(problem, pn, pt, time_step):
    """sum_k f_k (x) (r_a - r_b) over the points (N m; (2, 2), [row, column] = [f, branch]):
    the force of a on b at each point, f = (p_n n + p_t t) / h, times the branch c_b + s - c_a =
    r_a - r_b; over the cell's volume, the contact stress (compression positive)."""
    out = np.zeros((2, 2))
    for k in range(problem.a.size):
        fx = (pn[k] * problem.nx[k] - pt[k] * problem.ny[k]) / time_step
        fy = (pn[k] * problem.ny[k] + pt[k] * problem.nx[k]) / time_step
        lx = problem.rax[k] - problem.rbx[k]
        ly = problem.ray[k] - problem.rby[k]
        out[0, 0] += fx * lx
        out[0, 1] += fx * ly
        out[1, 0] += fy * lx
        out[1, 1] += fy * ly
    return out
