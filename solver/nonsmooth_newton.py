"""Semi-smooth Newton on Alart–Curnier's function, for u = W r + q (:mod:`solver.contact_problem`).

Signorini's condition and Coulomb's law hold at point k exactly when Alart & Curnier's
function (Comput. Methods Appl. Mech. Engrg. 92, 1991; the augmented form) is zero:

    z_n = r_n - rho_n u_n,   z_t = r_t - rho_t u_t,   s = mu max(0, z_n),
    F_n = r_n - max(0, z_n),
    F_t = r_t - clip(z_t, -s, s),

with u = W r + q and rho_n = 1 / W_nn, rho_t = 1 / W_tt (kg) per point. F is piecewise linear
in r; on each piece its Jacobian is J = D_r + D_u W with D_r, D_u 2x2 blocks per point:

    normal row:  z_n >= 0 (closed):  D_u = rho_n e_n          else (open):  D_r = e_n
    tangent row: closed and |z_t| <= s (sticking):  D_u = rho_t e_t
                 closed and sliding, sigma = sign z_t:  D_r = e_t - mu sigma e_n,  D_u = mu sigma rho_n e_n
                 open:  D_r = e_t

Each iteration solves J d = -F by a sparse LU factorisation (scipy.sparse.linalg.splu; J has
W's pattern) and takes the longest step t in 1, 1/2, 1/4, ... for which the merit
phi = |F|^2 / 2 falls by Armijo's rule, phi(r + t d) <= (1 - 2e-4 t) phi(r). A granular
packing has more contact components than degrees of freedom, so W, and J on the closed points,
can be singular: the factorised matrix is D_r + D_u (W + eps diag W), eps = 0 at first and
raised to the next of 1e-10, 1e-8, ... 1e-2 whenever the factorisation fails or no step passes
the line search (beyond 1e-2 the iterations stop unconverged), lowered one level after each step
taken. The iterations stop when the natural-map residual (:mod:`solver.contact_solution`) is
within the tolerance, and, unconverged, when its smallest value has fallen by less than 5% over
``STALL_STEPS`` steps.
"""

from __future__ import annotations

import numpy as np
from scipy import sparse
from scipy.sparse import linalg as splinalg

from .contact_solution import ContactSolution, contact_solution, local_law_residual, natural_map

__all__ = ["STALL_IMPROVEMENT", "STALL_STEPS", "alart_curnier", "jacobian", "solve"]

REGULARISATIONS = (0.0, 1e-10, 1e-8, 1e-6, 1e-4, 1e-2)
"""The regularisations eps of the Newton matrix tried in turn (module docstring)."""
ARMIJO = 1e-4
"""Sufficient-decrease constant of the line search."""
HALVINGS = 30
"""Largest number of step halvings in one line search."""
STALL_STEPS = 10
"""The iterations stop when the smallest local-law residual has fallen by less than
``STALL_IMPROVEMENT`` over this many steps (the merit can creep down by tiny steps for ever on
a packing whose points sit on the kinks of F)."""
STALL_IMPROVEMENT = 0.05
"""The relative fall of the smallest local-law residual over ``STALL_STEPS`` steps below which
the iterations stop."""


def alart_curnier(W, q, mu, impulse, rho_n, rho_t):
    """Alart–Curnier's F (n, 2) of the module docstring for impulses ``impulse`` (n, 2), with
    z_n, z_t (n,) for :func:`jacobian`."""
    u = (W @ impulse.reshape(-1) + q).reshape(-1, 2)
    zn = impulse[:, 0] - rho_n * u[:, 0]
    zt = impulse[:, 1] - rho_t * u[:, 1]
    bound = mu * np.maximum(zn, 0.0)
    F = np.stack([impulse[:, 0] - np.maximum(zn, 0.0), impulse[:, 1] - np.clip(zt, -bound, bound)], -1)
    return F, zn, zt


def jacobian(W, mu, zn, zt, rho_n, rho_t):
    """The Jacobian J = D_r + D_u W (CSC) of :func:`alart_curnier` at the piece given by z_n,
    z_t (module docstring); W may carry the regularisation already."""
    n = mu.size
    closed = zn >= 0.0  # at z_n = 0 the closed piece: r = 0 and u_n = 0 closes it in one step
    bound = mu * np.maximum(zn, 0.0)
    stick = closed & (np.abs(zt) <= bound)
    slide = closed & ~stick
    sigma = np.where(zt >= 0.0, 1.0, -1.0)
    normal, tangent = 2 * np.arange(n), 2 * np.arange(n) + 1
    # D_r: diagonal ones on the open normal rows and the non-sticking tangent rows, -mu sigma (t, n)
    dr = sparse.csr_matrix((np.concatenate([(~closed).astype(float), (~stick).astype(float),
                                            np.where(slide, -mu * sigma, 0.0)]),
                            (np.concatenate([normal, tangent, tangent]), np.concatenate([normal, tangent, normal]))),
                           shape=(2 * n, 2 * n))
    du = sparse.csr_matrix((np.concatenate([np.where(closed, rho_n, 0.0), np.where(stick, rho_t, 0.0),
                                            np.where(slide, mu * sigma * rho_n, 0.0)]),
                            (np.concatenate([normal, tangent, tangent]), np.concatenate([normal, tangent, normal]))),
                           shape=(2 * n, 2 * n))
    return (dr + du @ W).tocsc()


def solve(W, q, mu, tolerance, max_iterations, initial, counts: dict | None = None) -> ContactSolution:
    """Semi-smooth Newton iterations (module docstring) from the impulses ``initial`` (n, 2)
    until the local-law residual is within ``tolerance`` or ``max_iterations`` Newton steps.
    ``counts``: a dict whose ``"factorisations"`` entry is increased by each sparse LU
    factorisation made (one a step, more where the Jacobian had to be regularised)."""
    diagonal = W.diagonal()
    rho_n, rho_t = 1.0 / diagonal[0::2], 1.0 / np.where(diagonal[1::2] > 0, diagonal[1::2], diagonal[0::2])
    r = np.array(initial, dtype=np.float64).reshape(-1, 2)
    F, zn, zt = alart_curnier(W, q, mu, r, rho_n, rho_t)
    phi = 0.5 * float(np.sum(F * F))
    level = 0
    iterations = 0
    law = local_law_residual(natural_map(W, q, mu, r)[0], r)
    best, checked = law, law
    while law > tolerance and iterations < max_iterations:
        step = None
        while step is None and level < len(REGULARISATIONS):
            regularised = W + REGULARISATIONS[level] * sparse.diags(diagonal) if level else W
            if counts is not None:
                counts["factorisations"] = counts.get("factorisations", 0) + 1
            try:
                direction = splinalg.splu(jacobian(regularised, mu, zn, zt, rho_n, rho_t)).solve(-F.reshape(-1))
            except RuntimeError:  # exactly singular: regularise more
                direction = None
            if direction is not None and np.all(np.isfinite(direction)):
                direction = direction.reshape(-1, 2)
                t = 1.0
                for _ in range(HALVINGS):
                    trial = r + t * direction
                    F_trial, zn_trial, zt_trial = alart_curnier(W, q, mu, trial, rho_n, rho_t)
                    phi_trial = 0.5 * float(np.sum(F_trial * F_trial))
                    if phi_trial <= (1.0 - 2.0 * ARMIJO * t) * phi:
                        step = trial, F_trial, zn_trial, zt_trial, phi_trial
                        break
                    t *= 0.5
            if step is None:
                level += 1
        if step is None:
            break
        r, F, zn, zt, phi = step
        iterations += 1
        level = max(level - 1, 0)  # back towards the exact Jacobian once a step has passed
        law = local_law_residual(natural_map(W, q, mu, r)[0], r)
        best = min(best, law)
        if iterations % STALL_STEPS == 0:
            if best > (1.0 - STALL_IMPROVEMENT) * checked:
                break
            checked = best
    return contact_solution(W, q, mu, r, iterations, law <= tolerance)
