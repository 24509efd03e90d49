"""The methods that solve a contact problem given by its matrix, by name.

Every method is a callable ``solve(W, q, mu, tolerance, max_iterations, initial, **options)
-> ContactSolution`` on a validated problem (:func:`solver.contact_problem.solve_contact_problem`
validates and dispatches through :data:`SOLVERS`): W (2n, 2n) CSR with sorted indices, q (2n,),
mu (n,), ``initial`` (n, 2) starting impulses. Each stops on its own test:

``nlgs``
    Point-by-point nonlinear Gauss–Seidel (:func:`solver.nlgs.solve_matrix`): ``tolerance``
    is its quadratic norm of the impulses' change over a sweep, ``max_tolerance`` (an option,
    default 60 x ``tolerance``) its max norm; ``max_iterations`` caps the sweeps.
``newton``
    Semi-smooth Newton on Alart–Curnier's function with a line search
    (:mod:`solver.nonsmooth_newton`); ``tolerance`` is the local-law residual
    (:mod:`solver.contact_solution`).
``pcg``
    Projected conjugate gradient after Renouf & Alart (:mod:`solver.projected_cg`);
    ``tolerance`` is the local-law residual.
"""

from __future__ import annotations

import numpy as np

from grainview.contract.errors import ParameterError

from . import nlgs, nonsmooth_newton, projected_cg
from .contact_solution import ContactSolution, contact_solution

__all__ = ["SOLVERS", "solver", "solve_nlgs"]


def solve_nlgs(W, q, mu, tolerance, max_iterations, initial, *, max_tolerance=None) -> ContactSolution:
    """NLGS sweeps (:func:`solver.nlgs.solve_matrix`) until the quadratic norm is within
    ``tolerance`` and the max norm within ``max_tolerance`` (default 60 x ``tolerance``, about
    the time stepper's ratio), or ``max_iterations`` sweeps."""
    if max_tolerance is None:
        max_tolerance = 60.0 * tolerance
    if not (np.isfinite(max_tolerance) and max_tolerance > 0):
        raise ParameterError(f"max_tolerance={max_tolerance!r}: expected a positive number")
    rn, rt = initial[:, 0].copy(), initial[:, 1].copy()
    iterations, quad, worst = nlgs.solve_matrix(W.indptr.astype(np.int64), W.indices.astype(np.int64), W.data, q,
                                                mu, rn, rt, float(tolerance), float(max_tolerance),
                                                int(max_iterations))
    converged = bool(quad <= tolerance and worst <= max_tolerance)
    return contact_solution(W, q, mu, np.stack([rn, rt], -1), iterations, converged, quad, worst)


SOLVERS = {
    "nlgs": solve_nlgs,
    "newton": nonsmooth_newton.solve,
    "pcg": projected_cg.solve,
}
"""Name -> method (module docstring)."""


def solver(name: str):
    """The method registered as ``name``; a ParameterError naming the known ones otherwise."""
    try:
        return SOLVERS[name]
    except (KeyError, TypeError):
        raise ParameterError(f"method={name!r}: expected one of {', '.join(sorted(SOLVERS))}") from None
