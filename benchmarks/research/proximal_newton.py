"""Proximal-point iterations around the semi-smooth Newton (Siconos' PROX), for u = W r + q.

Each outer step k solves, by :func:`solver.nonsmooth_newton.solve`, the contact problem of the
same points and friction with the proximal (regularised) matrix and velocity

    W_k = W + alpha_k D,     q_k = q - alpha_k D r_k,      D = diag(W)   (kg-1),

so that u_k = W_k r + q_k = (W r + q) + alpha_k D (r - r_k): the original velocity plus a
restoring term towards the centre r_k, with alpha_k dimensionless. W_k is positive definite
wherever W is positive semi-definite with a positive diagonal, whatever the hyperstaticity of
the contact set, so the Newton matrix on the sticking points is no longer singular; and a
fixed point r_k+1 = r_k of the iteration solves the original problem (Rockafellar's proximal
point algorithm, Siconos' ``fc3d_proximal.c``, strategy "regularization"). The subproblem's
solution is the next centre r_k+1.

The inner tolerance follows the outer error: the subproblem is solved to a local-law residual
of max(tolerance, e_k / 10), e_k the local-law residual of r_k on the *original* problem
(:mod:`solver.contact_solution`). alpha starts at ``alpha`` (1 by default), is multiplied by 5
after an inner solve that did not converge and divided by 10 after one that did (as
``fc3d_proximal.c``). The outer steps stop when e_k is within the tolerance, or after
``max_iterations`` outer steps (or, optionally, once the factorisations reach a cap); the
result is the centre with the smallest e_k met.

Where D has a zero tangential entry (a point whose tangential velocity nothing changes) the
normal entry of the point is used there, as the Newton's rho_t does.

References: Siconos numerics (INRIA), ``numerics/src/FrictionContact/fc3d_proximal.c``
(github.com/siconos/siconos); R. T. Rockafellar, *Monotone operators and the proximal point
algorithm*, SIAM J. Control Optim. 14 (1976) 877-898.
"""

from __future__ import annotations

import time
from typing import NamedTuple

import numpy as np
from scipy import sparse

from grainview.contract.errors import ParameterError

from solver import nonsmooth_newton
from solver.contact_solution import ContactSolution, contact_solution, local_law_residual, natural_map

__all__ = ["ALPHA", "GROW", "INNER_RATIO", "INNER_STEPS", "SHRINK", "ProximalHistory", "solve", "solve_recorded"]

ALPHA = 1.0
"""The first proximal weight alpha (dimensionless: a multiple of diag W)."""
GROW = 5.0
"""alpha is multiplied by this after an inner solve that did not converge."""
SHRINK = 10.0
"""alpha is divided by this after an inner solve that converged."""
INNER_RATIO = 10.0
"""The inner tolerance is the outer error over this ratio (never below the outer tolerance)."""
INNER_STEPS = 50
"""The inner Newton's step cap per outer step (its own stall test usually stops it first)."""


class ProximalHistory(NamedTuple):
    """What the outer steps did, one entry per outer step (``residuals`` and ``seconds`` one more:
    index 0 is the start).

    residuals : the original problem's local-law residual e_k of each centre r_k.
    seconds : wall time since the start at each centre (s).
    alphas : the weight alpha used by each outer step.
    newton_steps : the inner Newton's steps of each outer step.
    factorisations : the sparse LU factorisations each inner solve attempted (its steps, and
        the retries at a larger regularisation of :mod:`solver.nonsmooth_newton`).
    inner_converged : whether each inner solve met its tolerance.
    inner_tolerances : the tolerance each inner solve was given.
    """

    residuals: tuple
    seconds: tuple
    alphas: tuple
    newton_steps: tuple
    factorisations: tuple
    inner_converged: tuple
    inner_tolerances: tuple

    @property
    def outer_steps(self) -> int:
        """The number of outer steps taken."""
        return len(self.alphas)

    @property
    def total_factorisations(self) -> int:
        """The sparse LU factorisations of the whole solve."""
        return int(sum(self.factorisations))


def _check(alpha, grow, shrink, inner_steps, max_factorisations):
    if not (np.isfinite(alpha) and alpha > 0):
        raise ParameterError(f"alpha={alpha!r}: expected a finite number > 0")
    for name, value in (("grow", grow), ("shrink", shrink)):
        if not (np.isfinite(value) and value >= 1):
            raise ParameterError(f"{name}={value!r}: expected a finite number >= 1 (1 keeps alpha)")
    if int(inner_steps) < 1:
        raise ParameterError(f"inner_steps={inner_steps!r}: expected an integer >= 1")
    if max_factorisations is not None and int(max_factorisations) < 1:
        raise ParameterError(f"max_factorisations={max_factorisations!r}: expected an integer >= 1 or None")


def solve_recorded(W, q, mu, tolerance, max_iterations, initial, *, alpha=ALPHA, grow=GROW, shrink=SHRINK,
                   inner_steps=INNER_STEPS, max_factorisations=None) -> tuple[ContactSolution, ProximalHistory]:
    """Proximal-point outer steps around the semi-smooth Newton (module docstring).

    Parameters
    ----------
    W : (2n, 2n) CSR Delassus matrix (kg-1), sorted indices, W_nn > 0 on every point.
    q : (2n,) free local velocities (m s-1).
    mu : (n,) friction coefficients.
    tolerance : the original problem's local-law residual |F| / |r| to reach.
    max_iterations : the cap on outer steps.
    initial : (n, 2) starting impulses r_0 (N s).
    alpha : the first proximal weight (dimensionless); grow, shrink : its factors after an inner
        solve that failed / converged (1 keeps alpha fixed); inner_steps : the inner Newton's step
        cap; max_factorisations : no further outer step once the sparse LU factorisations of the
        solve reach this many (None: no such cap).

    Returns
    -------
    (ContactSolution, ProximalHistory): the solution (its ``iterations`` the outer steps, its
    ``converged`` whether the tolerance was met) and the record of every outer step.
    """
    _check(alpha, grow, shrink, inner_steps, max_factorisations)
    start = time.perf_counter()
    W = sparse.csr_matrix(W)
    q = np.asarray(q, dtype=np.float64).reshape(-1)
    diagonal = W.diagonal()
    weights = diagonal.copy()
    weights[1::2] = np.where(diagonal[1::2] > 0, diagonal[1::2], diagonal[0::2])
    D = sparse.diags(weights, format="csr")
    if not (np.isfinite(tolerance) and tolerance > 0) or int(max_iterations) < 1:
        raise ParameterError(f"tolerance={tolerance!r}, max_iterations={max_iterations!r}: expected a positive "
                             "tolerance and at least one outer step")
    r = np.array(initial, dtype=np.float64)
    if r.size != q.size or not np.all(np.isfinite(r)):
        raise ParameterError(f"initial must hold 2 finite impulses per point ({q.size} values), got {r.size}")
    r = r.reshape(-1, 2)

    def error(impulse):
        return local_law_residual(natural_map(W, q, mu, impulse)[0], impulse)

    e = error(r)
    best, best_error = r, e
    residuals, seconds = [e], [time.perf_counter() - start]
    alphas, steps, lus, converged, tolerances = [], [], [], [], []
    while e > tolerance and len(alphas) < max_iterations and (max_factorisations is None
                                                              or sum(lus) < max_factorisations):
        inner_tolerance = max(tolerance, e / INNER_RATIO) if np.isfinite(e) else tolerance
        W_k = (W + alpha * D).tocsr()
        W_k.sort_indices()
        q_k = q - alpha * (weights * r.reshape(-1))
        counts = {"factorisations": 0}
        inner = nonsmooth_newton.solve(W_k, q_k, mu, inner_tolerance, int(inner_steps), r, counts=counts)
        alphas.append(alpha)
        steps.append(inner.iterations)
        lus.append(counts["factorisations"])
        converged.append(inner.converged)
        tolerances.append(inner_tolerance)
        r = inner.impulse
        e = error(r)
        residuals.append(e)
        seconds.append(time.perf_counter() - start)
        if e < best_error:
            best, best_error = r, e
        alpha = alpha / shrink if inner.converged else alpha * grow
    history = ProximalHistory(tuple(residuals), tuple(seconds), tuple(alphas), tuple(steps), tuple(lus),
                              tuple(converged), tuple(tolerances))
    return contact_solution(W, q, mu, best, len(alphas), best_error <= tolerance), history


def solve(W, q, mu, tolerance, max_iterations, initial, *, alpha=ALPHA, grow=GROW, shrink=SHRINK,
          inner_steps=INNER_STEPS, max_factorisations=None) -> ContactSolution:
    """The solution of :func:`solve_recorded` alone (the matrix methods' signature,
    :mod:`solver.contact_solvers`)."""
    return solve_recorded(W, q, mu, tolerance, max_iterations, initial, alpha=alpha, grow=grow, shrink=shrink,
                          inner_steps=inner_steps, max_factorisations=max_factorisations)[0]
