"""A frictional contact problem given directly by its matrix: u = W r + q, solved by a method of choice.

This is the form in which FCLIB stores 2D frictional contact problems and in which other
solvers (Siconos, LMGC90's exports) exchange them: n contact points, their impulses
r = (r_n,0, r_t,0, r_n,1, r_t,1, ...) (local frames, normal first), W the 2n x 2n Delassus
matrix (sparse, 2x2 blocks; symmetric positive semi-definite for a mechanical system), q the
free local velocities (any Signorini shift already in q_n) and mu the friction coefficient of
each point. Every point k must satisfy Signorini and Coulomb:

    r_n >= 0,  u_n >= 0,  r_n u_n = 0;   |r_t| <= mu r_n,  and u_t != 0 => r_t = -mu r_n sign(u_t).

:func:`solve_contact_problem` validates the problem and hands it to the method named by
``method`` (a method of the registry :mod:`solver.contact_solvers` with a matrix entry point): by default the same point-by-point exact
local solver and the same two stopping norms as the time stepper's NLGS (:mod:`solver.nlgs`);
``newton`` (semi-smooth Newton, :mod:`solver.nonsmooth_newton`) and ``pcg`` (projected conjugate
gradient, :mod:`solver.projected_cg`) stop on the natural-map residual instead. Every method's
result reports the natural-map residual (:mod:`solver.contact_solution`), zero exactly at a
solution.
"""

from __future__ import annotations

import inspect

import numpy as np

from grainview.contract.errors import ParameterError

from .contact_solution import ContactSolution
from .contact_solvers import solver

__all__ = ["ContactSolution", "solve_contact_problem"]


def check_problem(W, q, mu):
    """The matrix problem u = W r + q checked and normalised, or one ParameterError line naming
    what is wrong: returns ``(W, q, mu, n)`` with W a (2n, 2n) CSR matrix of sorted indices and no
    duplicates, finite, with W_nn > 0 at every point; q (2n,) finite; mu (n,) finite and >= 0
    (a scalar is broadcast); n the number of points. Every entry point that takes (W, q, mu)
    checks them here."""
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


def solve_contact_problem(W, q, mu, *, method="nlgs", tolerance=1e-10, max_iterations=10_000, initial=None,
                          **options) -> ContactSolution:
    """Solve the 2D frictional contact problem u = W r + q (module docstring) by ``method``.

    Parameters
    ----------
    W : (2n, 2n) array or scipy.sparse matrix, the Delassus matrix (rows 2k, 2k+1: normal and
        tangential velocity of point k).
    q : (2n,) free local velocities (m s-1 for impulses in N s).
    mu : scalar or (n,), friction coefficients.
    method : a name of :func:`solver.contact_solvers.matrix_methods`: ``nlgs`` (default), ``newton``,
        ``pcg``.
    tolerance : the method's stopping tolerance: for ``nlgs`` its quadratic norm (its max norm
        ``max_tolerance``, an option, defaults to 60 x ``tolerance``); for the others the
        natural-map residual |F| / |r|.
    max_iterations : the method's iteration cap (sweeps, Newton steps, gradient steps).
    initial : (n, 2) or (2n,) starting impulses (default 0).
    options : further keywords of the method (``max_tolerance`` for ``nlgs``).

    Returns
    -------
    ContactSolution (:mod:`solver.contact_solution`).
    """
    solve = solver(method)
    W, q, mu, n = check_problem(W, q, mu)
    if not (np.isfinite(tolerance) and tolerance > 0):
        raise ParameterError(f"tolerance={tolerance!r}: expected a positive number")
    if int(max_iterations) < 1:
        raise ParameterError(f"max_iterations={max_iterations!r}: expected an integer >= 1")
    r = np.zeros((n, 2)) if initial is None else np.array(initial, dtype=np.float64).reshape(-1)
    if r.size != 2 * n or not np.all(np.isfinite(r)):
        raise ParameterError(f"initial must hold 2 finite impulses per point ({2 * n} values), got {r.size}")
    known = set(inspect.signature(solve).parameters) - {"W", "q", "mu", "tolerance", "max_iterations", "initial"}
    unknown = sorted(set(options) - known)
    if unknown:
        raise ParameterError(f"method={method!r} has no option {', '.join(unknown)}; its options: "
                             f"{', '.join(sorted(known)) or 'none'}")
    return solve(W, q, mu, float(tolerance), int(max_iterations), r.reshape(n, 2), **options)
