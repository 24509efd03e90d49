"""What every solver of a contact problem given by its matrix returns, and how good it is.

For u = W r + q (:mod:`solver.contact_problem`) with impulses r = (r_n, r_t) per point, the
quality of a result is the natural-map residual of :mod:`solver.residuals` (FCLIB's measure
for frictional contact): per point F_k = r_k - proj_K(r_k - rho_k u^_k), rho_k = 1 / W_nn,k
(kg), u^ = (u_n + mu |u_t|, u_t) De Saxcé's modified velocity, and over the problem

    local-law residual = |F| / |r|      (infinite when r = 0 and F != 0; 0 when both are 0),

zero exactly at a solution of Signorini's condition and Coulomb's law, whatever method found it
(at r = 0, F = 0 only at a solution, every point open and separating), and the same measure as
the time stepper's (:func:`solver.residuals.local_law_residual`).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from . import residuals

__all__ = ["ContactSolution", "natural_map", "natural_map_at", "local_law_residual", "largest_point_residual",
           "contact_solution"]


class ContactSolution(NamedTuple):
    """Result of a solver of u = W r + q (:func:`solver.contact_problem.solve_contact_problem`).

    impulse : (n, 2) r per point (normal, tangential); velocity : (n, 2) u = W r + q;
    iterations : the method's iterations (NLGS sweeps, Newton steps, conjugate-gradient steps);
    residual, max_residual : the method's own stopping norms at the end (the NLGS: its quadratic
    and max norms; the other methods: the local-law residual and the largest |F_k| over the mean
    |r_k| of the loaded points);
    local_law_residual : |F| / |r| of the natural map (module docstring; 0 at a solution);
    converged : the method's stopping test was met within its iteration cap.
    """

    impulse: np.ndarray
    velocity: np.ndarray
    iterations: int
    residual: float
    max_residual: float
    local_law_residual: float
    converged: bool


def natural_map(W, q, mu, impulse):
    """(F, u): the natural map F (n, 2) N s of every point (module docstring) and the velocity
    u = W r + q (n, 2) m s-1, for impulses ``impulse`` (n, 2) and W in CSR form."""
    velocity = (W @ impulse.reshape(-1) + q).reshape(mu.size, 2)
    return natural_map_at(impulse, velocity, mu, 1.0 / W.diagonal()[0::2]), velocity


def natural_map_at(impulse, velocity, mu, rho):
    """The natural map F (n, 2) of impulses and velocities (n, 2) given, rho = 1 / W_nn (n,)."""
    fn, ft = residuals.natural_maps(np.ascontiguousarray(impulse[:, 0]), np.ascontiguousarray(impulse[:, 1]),
                                    np.ascontiguousarray(velocity[:, 0]), np.ascontiguousarray(velocity[:, 1]),
                                    mu, rho)
    return np.stack([fn, ft], -1)


def local_law_residual(violation, impulse) -> float:
    """|F| / |r| over all points; at r = 0, 0 if F = 0 and infinite otherwise (module
    docstring). (Sums of squares rather
    than np.linalg.norm: its BLAS dot can take milliseconds on a loaded machine whose threads
    wait for cores.)"""
    size = float(np.sqrt(np.sum(impulse * impulse)))
    law = float(np.sqrt(np.sum(violation * violation)))
    if size > 0:
        return law / size
    return 0.0 if law == 0.0 else float("inf")


def largest_point_residual(violation, impulse) -> float:
    """max_k |F_k| over the root mean square |r_k| of the loaded points (r_n > 0); the largest
    |F_k| itself with no point loaded."""
    worst = float(np.max(np.hypot(violation[:, 0], violation[:, 1]))) if len(violation) else 0.0
    loaded = impulse[:, 0] > 0
    if not np.any(loaded):
        return worst
    return worst / float(np.sqrt(np.mean(np.sum(impulse[loaded] ** 2, axis=1))))


def contact_solution(W, q, mu, impulse, iterations, converged, residual=None, max_residual=None) -> ContactSolution:
    """A :class:`ContactSolution` for ``impulse`` (n, 2): its velocity and local-law residual
    computed here from (W, q, mu); ``residual`` and ``max_residual`` default to the local-law
    residual and :func:`largest_point_residual` (the stopping norms of the methods that stop on
    the natural map)."""
    impulse = np.ascontiguousarray(impulse, dtype=np.float64).reshape(-1, 2)
    violation, velocity = natural_map(W, q, mu, impulse)
    law = local_law_residual(violation, impulse)
    if residual is None:
        residual = law
    if max_residual is None:
        max_residual = largest_point_residual(violation, impulse)
    return ContactSolution(impulse, velocity, int(iterations), float(residual), float(max_residual), law,
                           bool(converged))
