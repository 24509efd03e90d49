"""How well a step's impulses satisfy the contact laws and the particles' balance.

The NLGS stops on the change of the impulses between two sweeps (:mod:`solver.nlgs`). That
says when the iterations have stalled, not how far the impulses are from *a* solution; and
the distance to one particular solution (the "same-state force error") is no measure either,
since a hyperstatic packing admits many force networks. Two measures are zero for every
admissible solution and for nothing else:

**Local-law residual** (the natural map, as FCLIB defines it for frictional contact). For
point k with impulse r = (r_n, r_t) (N s), relative velocity u = (u_n, u_t) (m s-1) at the end
of the step and Signorini shift b_k (:mod:`solver.nlgs`), De Saxcé's modified velocity
u^ = (u_n + b_k + mu |u_t|, u_t) turns Signorini and Coulomb together into one cone
complementarity, K* ∋ u^ ⊥ r ∈ K, with K = {|r_t| <= mu r_n} the Coulomb cone. It holds if and
only if

    F_k = r - proj_K(r - rho_k u^) = 0,        rho_k = 1 / W_nn,k  (kg),

W_nn,k the normal entry of the point's Delassus block; rho_k makes both terms impulses. The
step's residual is ``|F| / |r|`` summed in squares over the points (0 with no impulse and no
violation). Projection onto the 2D cone: z itself when |z_t| <= mu z_n; 0 when
z_n <= -mu |z_t| (the polar cone); else onto the nearer edge, d (1, mu sign z_t) with
d = (z_n + mu |z_t|) / (1 + mu^2).

**Unbalanced force** (the quasi-static measure of DEM codes). The contact impulses on
particle i plus its external impulse h m_i g give its momentum change over the step; the
largest of their norms over the particles, divided by the mean impulse of a loaded point, is
the step's unbalanced-force ratio (and likewise the torque over the mean impulse times the
particle's circumscribed radius). It is zero in static equilibrium, whatever network carries
the load, and measures how far from equilibrium a packing is, not the solver's error alone.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .nlgs import relative_velocity, delassus_block
from .solve_records import Impulses, Velocities

__all__ = ["cone_projection", "natural_map", "natural_maps", "local_law_residuals", "particle_imbalance",
           "local_law_residual", "unbalanced_ratios"]


@njit(cache=True)
def cone_projection(zn, zt, mu):
    """Euclidean projection of (zn, zt) onto the 2D Coulomb cone {|t| <= mu n}."""
    at = abs(zt)
    if zn >= 0.0 and at <= mu * zn:
        return zn, zt
    if mu * at <= -zn:
        return 0.0, 0.0
    d = (zn + mu * at) / (1.0 + mu * mu)
    return d, (mu * d if zt >= 0.0 else -mu * d)


@njit(cache=True)
def natural_map(pn, pt, un, ut, mu, rho):
    """F = r - proj_K(r - rho u^) of one point (module docstring): r = (pn, pt) N s, u = (un, ut)
    the velocity with its Signorini shift included (m s-1), rho kg."""
    zn = pn - rho * (un + mu * abs(ut))
    zt = pt - rho * ut
    qn, qt = cone_projection(zn, zt, mu)
    return pn - qn, pt - qt


@njit(cache=True)
def natural_maps(pn, pt, un, ut, mu, rho):
    """:func:`natural_map` of every point: arrays (P,) in, (F_n, F_t) (P,) out."""
    fn = np.empty(pn.size)
    ft = np.empty(pn.size)
    for k in range(pn.size):
        fn[k], ft[k] = natural_map(pn[k], pt[k], un[k], ut[k], mu[k], rho[k])
    return fn, ft


@njit(cache=True, inline="always")
def _point_natural_map(k, problem, impulses, velocities, wnn_k):
    """:func:`natural_map` of point k, its velocity from the bodies' (Signorini shift added)
    and rho = 1 / W_nn."""
    un, ut = relative_velocity(k, problem, velocities)
    return natural_map(impulses.pn[k], impulses.pt[k], un + problem.bias[k], ut, problem.mu[k], 1.0 / wnn_k)


@njit(cache=True)
def local_law_residuals(problem, impulses, velocities, wnn):
    """Natural-map residual (F_n, F_t) (N s) of every point (module docstring), from the
    :class:`solver.solve_records.Impulses` and the end-of-step
    :class:`solver.solve_records.Velocities` of the :class:`solver.solve_records.ContactProblem`,
    ``wnn`` (P,) the points' W_nn (s kg-1)."""
    m = problem.a.size
    fn = np.empty(m)
    ft = np.empty(m)
    for k in range(m):
        fn[k], ft[k] = _point_natural_map(k, problem, impulses, velocities, wnn[k])
    return fn, ft


@njit(cache=True)
def particle_imbalance(problem, impulses, n_particles):
    """Sum of the contact impulses (x, y; N s) and of their moments (N m s) on each of the
    first ``n_particles`` bodies, from the :class:`solver.solve_records.Impulses` of
    ``problem``'s points."""
    a, b, nx, ny = problem.a, problem.b, problem.nx, problem.ny
    pn, pt = impulses
    fx = np.zeros(n_particles)
    fy = np.zeros(n_particles)
    torque = np.zeros(n_particles)
    for k in range(a.size):
        px = pn[k] * nx[k] - pt[k] * ny[k]
        py = pn[k] * ny[k] + pt[k] * nx[k]
        if b[k] < n_particles:
            fx[b[k]] += px
            fy[b[k]] += py
            torque[b[k]] += problem.rbx[k] * py - problem.rby[k] * px
        if a[k] < n_particles:
            fx[a[k]] -= px
            fy[a[k]] -= py
            torque[a[k]] -= problem.rax[k] * py - problem.ray[k] * px
    return fx, fy, torque


@njit(cache=True)
def _law_sums(problem, impulses, velocities):
    """(sum of |F_k|^2, sum of |r_k|^2) over the points: :func:`local_law_residuals` and the
    impulses' squared norm in one pass, each point's W_nn from :func:`solver.nlgs.delassus_block`."""
    pn, pt = impulses
    violation = 0.0
    scale = 0.0
    for k in range(problem.a.size):
        wnn = delassus_block(k, problem)[0]
        fn, ft = _point_natural_map(k, problem, impulses, velocities, wnn)
        violation += fn * fn + ft * ft
        scale += pn[k] * pn[k] + pt[k] * pt[k]
    return violation, scale


def local_law_residual(problem, pn, pt, vx, vy, w) -> float:
    """The step's local-law residual |F| / |r| (module docstring) for a
    :class:`solver.solve_records.ContactProblem` and its impulses and end velocities; 0 for no points."""
    if problem.a.size == 0:
        return 0.0
    violation, scale = _law_sums(problem, Impulses(pn, pt), Velocities(vx, vy, w))
    if scale > 0.0:
        return float(np.sqrt(violation) / np.sqrt(scale))
    return 0.0 if violation == 0.0 else float("inf")


@njit(cache=True)
def _unbalanced(problem, impulses, external_impulse, radius):
    """(largest |sum of impulses|, largest |sum of moments| / R, mean |r| of the loaded
    points, loaded points) of :func:`unbalanced_ratios`, in one pass over the points and one
    over the particles."""
    pn, pt = impulses
    fx, fy, torque = particle_imbalance(problem, impulses, radius.size)
    total = 0.0
    loaded = 0
    for k in range(pn.size):
        if pn[k] > 0.0:
            total += np.hypot(pn[k], pt[k])
            loaded += 1
    force = 0.0
    moment = 0.0
    for i in range(radius.size):  # a NaN is kept, as numpy's max keeps it
        f = np.hypot(fx[i] + external_impulse[i, 0], fy[i] + external_impulse[i, 1])
        if not f <= force:
            force = f
        t = abs(torque[i]) / radius[i]
        if not t <= moment:
            moment = t
    return force, moment, total / max(loaded, 1), loaded


def unbalanced_ratios(problem, pn, pt, external_impulse, radius) -> tuple[float, float]:
    """(force ratio, torque ratio) of the module docstring: the largest |sum of contact impulses
    + external impulse| over the particles (``external_impulse`` (N, 2) N s, e.g. h m g) and the
    largest |sum of contact moments| / R_i, both over the mean |r| of the loaded points. (0, 0)
    when no point is loaded."""
    external_impulse = np.ascontiguousarray(external_impulse, dtype=float)
    if external_impulse.shape != (len(radius), 2):
        raise ValueError(f"external_impulse has shape {external_impulse.shape}: expected ({len(radius)}, 2), one row "
                         "per particle")
    impulses = Impulses(np.asarray(pn, float), np.asarray(pt, float))
    force, moment, mean, loaded = _unbalanced(problem, impulses, external_impulse, np.asarray(radius, float))
    if loaded == 0:
        return 0.0, 0.0
    return float(force / mean), float(moment / mean)
