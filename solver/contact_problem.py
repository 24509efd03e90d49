"""A frictional contact problem given directly by its matrix: u = W r + q, solved by the NLGS.

This is the form in which FCLIB stores 2D frictional contact problems and in which other
solvers (Siconos, LMGC90's exports) exchange them: n contact points, their impulses
r = (r_n,0, r_t,0, r_n,1, r_t,1, ...) (local frames, normal first), W the 2n x 2n Delassus
matrix (sparse, 2x2 blocks; symmetric positive semi-definite for a mechanical system), q the
free local velocities (any Signorini shift already in q_n) and mu the friction coefficient of
each point. Every point k must satisfy Signorini and Coulomb:

    r_n >= 0,  u_n >= 0,  r_n u_n = 0;   |r_t| <= mu r_n,  and u_t != 0 => r_t = -mu r_n sign(u_t).

:func:`solve_contact_problem` runs the same point-by-point exact local solver and the same two
stopping norms as the time stepper's NLGS (:mod:`solver.nlgs`), and reports the natural-map
residual of the result (:mod:`solver.residuals`), which is zero exactly at a solution.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from grainview.contract.errors import ParameterError

from . import nlgs, residuals

__all__ = ["ContactSolution", "solve_contact_problem"]


class ContactSolution(NamedTuple):
    """Result of :func:`solve_contact_problem`.

    impulse : (n, 2) r per point (normal, tangential); velocity : (n, 2) u = W r + q;
    iterations : sweeps run; residual, max_residual : the NLGS stopping norms of the last sweep;
    local_law_residual : |F| / |r| of the natural map (0 at a solution; with r = 0, |F| itself);
    converged : both stopping norms met within ``max_iterations``.
    """

    impulse: np.ndarray
    velocity: np.ndarray
    iterations: int
    residual: float
    max_residual: float
    local_law_residual: float
    converged: bool


def _validate(W, q, mu):
    from scipy import sparse

    q = np.asarray(q, dtype=np.float64).reshape(-1)
    if q.size % 2 or not np.all(np.isfinite(q)):
        raise ParameterError(f"q must hold 2 finite local velocities per point (normal first), got {q.size} values")
    n = q.size // 2
    try:
        W = sparse.csr_matrix(W, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ParameterError(f"W must be a (2n, 2n) matrix, dense or scipy.sparse: {exc}") from None
    if W.shape != (2 * n, 2 * n):
        raise ParameterError(f"W has shape {W.shape}; q of {2 * n} values needs W of shape ({2 * n}, {2 * n})")
    if not np.all(np.isfinite(W.data)):
        raise ParameterError("W must be finite")
    W.sum_duplicates()
    W.sort_indices()
    diagonal = W.diagonal()
    if np.any(diagonal[0::2] <= 0):
        raise ParameterError("W must have W_nn > 0 on the diagonal of every point (a point no body can move)")
    mu = np.broadcast_to(np.asarray(mu, dtype=np.float64), (n,)).copy()
    if not np.all(np.isfinite(mu)) or np.any(mu < 0):
        raise ParameterError("mu must hold finite friction coefficients >= 0, one per point or one for all")
    return W, q, mu, n


def solve_contact_problem(W, q, mu, *, tolerance=1e-10, max_tolerance=None, max_iterations=10_000,
                          initial=None) -> ContactSolution:
    """Solve the 2D frictional contact problem u = W r + q (module docstring) by NLGS.

    Parameters
    ----------
    W : (2n, 2n) array or scipy.sparse matrix, the Delassus matrix (rows 2k, 2k+1: normal and
        tangential velocity of point k).
    q : (2n,) free local velocities (m s-1 for impulses in N s).
    mu : scalar or (n,), friction coefficients.
    tolerance, max_tolerance : the NLGS's quadratic and max norms (:mod:`solver.nlgs`);
        ``max_tolerance`` defaults to 60 x ``tolerance`` (about the time stepper's ratio).
    max_iterations : sweep cap.
    initial : (n, 2) or (2n,) starting impulses (default 0).

    Returns
    -------
    ContactSolution.
    """
    W, q, mu, n = _validate(W, q, mu)
    if max_tolerance is None:
        max_tolerance = 60.0 * tolerance
    for name, value in (("tolerance", tolerance), ("max_tolerance", max_tolerance)):
        if not (np.isfinite(value) and value > 0):
            raise ParameterError(f"{name}={value!r}: expected a positive number")
    if int(max_iterations) < 1:
        raise ParameterError(f"max_iterations={max_iterations!r}: expected an integer >= 1")
    r = np.zeros((n, 2)) if initial is None else np.array(initial, dtype=np.float64).reshape(-1)
    if r.size != 2 * n or not np.all(np.isfinite(r)):
        raise ParameterError(f"initial must hold 2 finite impulses per point ({2 * n} values), got {r.size}")
    r = r.reshape(n, 2)
    rn, rt = r[:, 0].copy(), r[:, 1].copy()
    iterations, quad, worst = nlgs.solve_matrix(W.indptr.astype(np.int64), W.indices.astype(np.int64), W.data, q,
                                                mu, rn, rt, float(tolerance), float(max_tolerance),
                                                int(max_iterations))
    impulse = np.stack([rn, rt], -1)
    velocity = (W @ impulse.reshape(-1) + q).reshape(n, 2)
    diagonal = W.diagonal()[0::2]
    violation = np.stack(residuals.natural_maps(rn, rt, velocity[:, 0].copy(), velocity[:, 1].copy(), mu,
                                                1.0 / diagonal), -1)
    size = float(np.linalg.norm(impulse))
    law = float(np.linalg.norm(violation)) / size if size > 0 else float(np.linalg.norm(violation))
    converged = bool(quad <= tolerance and worst <= max_tolerance)
    return ContactSolution(impulse, velocity, int(iterations), float(quad), float(worst), law, converged)
