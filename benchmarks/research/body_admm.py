"""ADMM in body (velocity) space for the time step's frictional contact problem: an experiment.

The Moreau-Jean step's contact problem, written in the bodies' velocities v (3B: v_x, v_y, w per
body, m s-1 and rad s-1) rather than in the impulses (:mod:`solver.matrix_form` for H, M^-1 and
the conventions): with v_free the free velocities, H (2P x 3B) the points' local map, b_k the
Signorini shift of point k and s_k = mu_k |u_t,k| De Saxcé's shift,

    minimise  1/2 (v - v_free) . M (v - v_free)
    subject to  u^ = H v + (b + s) e_n  in K*,        K*_k = {|u_t| <= u_n / mu_k},

K* the dual of the Coulomb cones K_k = {|r_t| <= mu_k r_n} (for mu_k = 0, the half-plane
u_n >= 0). Its multipliers are the impulses r in K (N s): M (v - v_free) = H^T r,
K* ∋ u^ ⊥ r ∈ K, which at the fixed point s = mu |u_t| are Signorini's condition and Coulomb's
law (De Saxcé & Feng, Math. Comput. Model. 28 (1998) 225-245). The objective is strongly convex
in v whatever the number of points: the self-equilibrated impulse states that make the
Delassus matrix W = H M^-1 H^T singular on a hyperstatic packing are no direction of v.

Bodies that cannot move (their M^-1 zero, walls at an imposed velocity) keep v = v_free: the
unknowns are y, the velocity change on the mobile directions, v = v_free + P y with P the
orthonormal eigenvectors of each body's M^-1 block of positive eigenvalue lambda, and
1/2 (v - v_free) . M (v - v_free) = 1/2 y . D y, D = diag(1 / lambda). With A = H P and
c = H v_free + b e_n (the free local velocities, ``q`` of the matrix form), one iteration of
the alternating direction method of multipliers on the splitting z = A y + c + s e_n, z in K*,
with the scaled multiplier xi = r / rho (Boyd et al., Found. Trends Mach. Learn. 3 (2011) 1-122,
section 3.1.1; body space as Siconos' ``gfc3d_admm``, which factors M + rho H H^T in its own
convention):

1. y = (D + rho A^T A)^-1 rho A^T (z^ + xi^ - c - s e_n)   (one sparse LU, kept while rho is);
2. z = proj_K*(w), w = A y + c + s e_n - xi^, per point (proj_K*(w) = w + proj_K(-w), Moreau);
3. xi = z - w  (= proj_K(-w), so r = rho xi is in the Coulomb cones at every iteration);
4. the shift s = mu |z_t| every ``shift_every`` iterations (z_t is the tangential velocity);
5. with ``acceleration``, Goldstein, O'Donoghue, Setzer & Baraniuk's fast ADMM with restart
   (SIAM J. Imaging Sci. 7 (2014) 1588-1623, algorithm 8, as ``gfc3d_admm``): the combined
   residual e = rho (|A y + c + s e_n - z|^2 + |z - z^|^2); if e < eta e_prev, z^ and xi^ are
   extrapolated by Nesterov's (tau_k - 1) / tau_k+1; otherwise the momentum restarts (tau = 1,
   no extrapolation) from the new iterate, whose e becomes e_prev (Goldstein et al. step back to
   the previous iterate and divide e_prev by eta; with the shift unchanged that repeats the same
   step until e_prev has grown past e, thousands of iterations at eta = 0.999);
6. every ``balance_every`` iterations, residual balancing as OSQP does it (Stellato et al.,
   Math. Prog. Comp. 12 (2020) 637-672, section 5.2): the primal residual
   |A y + c + s e_n - z| over max(|A y|, |z|, |c + s e_n|) and the dual residual
   |rho A^T (z - z_prev)| over max(|D y|, |rho A^T xi|) suggest rho sqrt(primal / dual) (at
   most 100 times larger or smaller); rho takes it, and the LU is made again, only when it
   differs by more than ``refactor_ratio`` from the current rho (xi rescaled so that r is
   unchanged).

Convergence is judged by nothing of the ADMM's own: every ``check_every`` iterations the
impulses r = rho xi give the end velocities v = v_free + M^-1 H^T r and u = H v + b e_n, and the
local-law residual |F| / |r| of the natural map (:mod:`solver.contact_solution`,
:mod:`solver.residuals`; rho_k = 1 / W_nn,k) is computed from them, the same measure as every
other method's. The best impulses seen are returned when ``max_iterations`` runs out.
Not registered in :mod:`solver.contact_solvers`; how it does on the stepper's problems:
benchmarks/results/body-admm.md (``python -m benchmarks.body_admm``).
"""

from __future__ import annotations

import time

import numpy as np
from numba import njit

from grainview.contract.errors import ParameterError

from solver.contact_solution import ContactSolution, largest_point_residual, local_law_residual, natural_map_at
from solver.residuals import cone_projection

STALL_WINDOW = 100
"""Iterations over which ``stall_growth`` looks for progress of the best local-law residual."""
STALL_IMPROVEMENT = 0.1
"""The fraction by which the best residual must fall over STALL_WINDOW iterations."""
RHO_RANGE = 1e4
"""``stall_growth`` takes rho to at most this many times its first value."""

__all__ = ["BodyProblem", "body_problem", "delassus_diagonal", "dual_cone_projection", "factorise", "local_velocities",
           "solve"]


@njit(cache=True)
def dual_cone_projection(wn, wt, mu, zn, zt):
    """Euclidean projection of the points' (wn, wt) (P,) onto the dual Coulomb cones
    K*_k = {|t| <= n / mu_k}, into ``zn, zt`` (P,): proj_K*(w) = w + proj_K(-w) (Moreau's
    decomposition, the polar of K* being -K), proj_K of :func:`solver.residuals.cone_projection`."""
    for k in range(wn.size):
        pn, pt = cone_projection(-wn[k], -wt[k], mu[k])
        zn[k] = wn[k] + pn
        zt[k] = wt[k] + pt


class BodyProblem:
    """The problem of the module docstring in the mobile directions: ``A`` = H P (2P x n, CSR),
    ``D`` (n,) the inverse eigenvalues of M^-1 (kg, kg m2), ``P`` (3B x n, CSR), ``c`` (2P,) the
    free local velocities H v_free + b e_n (m s-1), ``mu`` (P,), ``H`` and ``minv`` as given,
    ``v_free`` (3B,), ``bias`` (P,), ``wnn`` (P,) the normal diagonal of W (s kg-1)."""

    def __init__(self, H, minv, v_free, bias, mu, A, D, P, c, wnn):
        self.H, self.minv, self.v_free, self.bias, self.mu = H, minv, v_free, bias, mu
        self.A, self.D, self.P, self.c, self.wnn = A, D, P, c, wnn


def delassus_diagonal(H, minv):
    """The diagonal of W = H M^-1 H^T (2P,) without forming W: the row sums of (H M^-1) * H."""
    return np.asarray((H @ minv).multiply(H).sum(axis=1)).ravel()


def body_problem(H, minv, v_free, bias, mu) -> BodyProblem:
    """Check and convert the step's problem (H (2P x 3B) sparse, M^-1 (3B x 3B) block diagonal with
    3x3 blocks, v_free (3B,), bias (P,), mu (P,) or a scalar) into a :class:`BodyProblem`; one
    ParameterError line naming what is wrong otherwise."""
    from scipy import sparse

    H = sparse.csr_matrix(H, dtype=np.float64)
    minv = sparse.csr_matrix(minv, dtype=np.float64)
    points, dofs = H.shape[0] // 2, H.shape[1]
    if H.shape[0] % 2 or dofs % 3:
        raise ParameterError(f"H has shape {H.shape}: expected (2P, 3B), two rows per point and three columns per body")
    if minv.shape != (dofs, dofs):
        raise ParameterError(f"minv has shape {minv.shape}: expected ({dofs}, {dofs}), the bodies' inverse mass of H's "
                             "columns")
    v_free = np.asarray(v_free, dtype=np.float64).reshape(-1)
    bias = np.asarray(bias, dtype=np.float64).reshape(-1)
    if v_free.size != dofs or bias.size != points:
        raise ParameterError(f"v_free has {v_free.size} values and bias {bias.size}: expected {dofs} (3 per body) and "
                             f"{points} (1 per point)")
    mu = np.broadcast_to(np.asarray(mu, dtype=np.float64), (points,)).copy()
    if not (np.all(np.isfinite(mu)) and np.all(mu >= 0)) or not (np.all(np.isfinite(v_free))
                                                                  and np.all(np.isfinite(bias))):
        raise ParameterError("mu, v_free and bias must be finite and mu >= 0")
    diagonal_blocks = _diagonal_blocks(minv)
    off = minv - sparse.block_diag(list(diagonal_blocks), format="csr")
    if off.count_nonzero() and np.abs(off.data).max() > 1e-12 * max(np.abs(minv.data).max(), 1e-300):
        raise ParameterError("minv must be block diagonal with one 3x3 block per body (expected the bodies' inverse "
                             "masses, solver.matrix_form.inverse_mass)")
    values, vectors = np.linalg.eigh(diagonal_blocks)  # (B, 3), (B, 3, 3)
    if np.any(values < -1e-12 * max(values.max(), 1e-300)):
        raise ParameterError("minv has a negative eigenvalue: expected positive semi-definite inverse masses")
    mobile = values > 1e-12 * max(values.max(), 1e-300)
    body, which = np.nonzero(mobile)
    n = body.size
    rows = (3 * body[:, None] + np.arange(3)[None, :]).ravel()
    cols = np.repeat(np.arange(n), 3)
    P = sparse.csr_matrix((vectors[body, :, which].ravel(), (rows, cols)), shape=(dofs, n))
    D = 1.0 / values[body, which]
    A = (H @ P).tocsr()
    c = H @ v_free
    c[0::2] += bias
    wnn = delassus_diagonal(H, minv)[0::2]
    if np.any(wnn <= 0):
        raise ParameterError("every point needs W_nn > 0 (a point on two bodies that cannot move has no solution to "
                             "measure)")
    return BodyProblem(H, minv, v_free, bias, mu, A, D, P, c, wnn)


def _diagonal_blocks(minv):
    """The (B, 3, 3) diagonal blocks of a sparse ``minv`` (3B x 3B)."""
    coo = minv.tocoo()
    keep = coo.row // 3 == coo.col // 3
    blocks = np.zeros((minv.shape[0] // 3, 3, 3))
    np.add.at(blocks, (coo.row[keep] // 3, coo.row[keep] % 3, coo.col[keep] % 3), coo.data[keep])
    return blocks


def local_velocities(problem: BodyProblem, impulse):
    """(u (P, 2), v (3B,)): the end velocities v = v_free + M^-1 H^T r of the impulses ``impulse``
    (P, 2) and the points' local velocities u = H v + b e_n (= W r + q)."""
    v = problem.v_free + problem.minv @ (problem.H.T @ impulse.reshape(-1))
    u = problem.H @ v
    u[0::2] += problem.bias
    return u.reshape(-1, 2), v


def _law(problem, impulse):
    """(|F| / |r|, F, u) of ``impulse`` (P, 2) (module docstring)."""
    u, _ = local_velocities(problem, impulse)
    violation = natural_map_at(impulse, u, problem.mu, 1.0 / problem.wnn)
    return local_law_residual(violation, impulse), violation, u


def factorise(D, A, rho):
    """The sparse LU of the v-step's matrix diag(D) + rho A^T A (step 1 of the module docstring;
    D (n,) kg or kg m2, A (2P x n), rho kg): scipy's SuperLU, a fill-reducing order of A + A^T."""
    from scipy import sparse
    from scipy.sparse.linalg import splu

    K = (sparse.diags(D) + rho * (A.T @ A)).tocsc()
    return splu(K, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options=dict(SymmetricMode=True))


def solve(H, minv, v_free, bias, mu, tolerance=1e-6, max_iterations=1000, initial=None, *, rho=None,
          scaling="none", acceleration=True, eta=0.999, shift_every=1, check_every=5, balance_every=10,
          refactor_ratio=10.0, fixed_shift=None, stall_growth=0.0, record=None) -> ContactSolution:
    """Body-space ADMM (module docstring) from the impulses ``initial`` (P, 2) (default 0).

    Parameters
    ----------
    H, minv, v_free, bias, mu : the step's problem (:func:`body_problem`; :mod:`solver.matrix_form`'s
        ``local_map`` and ``inverse_mass``, the free velocities (3B,), the Signorini shifts (P,)).
    tolerance : the local-law residual |F| / |r| to reach.
    max_iterations : the ADMM iterations' cap.
    rho : the penalty (kg); default the median of 1 / W_nn,k over the points.
    scaling : ``"none"``, or ``"wnn"``: each point's two constraint rows multiplied by
        sqrt(omega_k), omega_k = median(W_nn) / W_nn,k, so that its penalty is rho omega_k ~ 1 / W_nn,k
        (the cones are unchanged by a positive factor per point; r = rho sqrt(omega) xi).
    acceleration : Nesterov extrapolation with restart (step 5), ``eta`` its restart factor.
    shift_every, check_every, balance_every : how often (iterations) the shift is updated, the
        local-law residual computed (>= 1: it is the stopping test) and rho balanced (0: never
        updated, never balanced).
    refactor_ratio : rho changes (and D + rho A^T A is factored again) only by more than this factor.
    fixed_shift : (P,) m s-1, a shift s held for the whole solve instead of mu |u_t| (a probe of
        the shift's fixed point: s from a solution makes the problem the convex one it solves).
    stall_growth : when > 0, rho is multiplied by it (and factored again) whenever the best
        local-law residual has fallen by less than STALL_IMPROVEMENT over STALL_WINDOW iterations
        since rho last changed, up to RHO_RANGE times its first value (0: never).
    record : a dict to fill with ``checks`` [(iteration, local-law residual, rho, seconds since
        the call)], ``admm`` [(iteration, |A y + c + s e_n - z| / |c + s e_n|, |z - z_prev| / |z|)]
        at the same iterations, ``factorisations``, ``factor_seconds``, ``rho`` (every value
        used), ``seconds``.

    Returns
    -------
    ContactSolution: the impulses (best residual seen), their local velocities W r + q,
    iterations, residual and local_law_residual both the local-law residual, max_residual
    :func:`solver.contact_solution.largest_point_residual`, converged when within ``tolerance``.
    """
    from scipy import sparse

    start = time.perf_counter()
    problem = body_problem(H, minv, v_free, bias, mu)
    points = problem.mu.size
    if not (np.isfinite(tolerance) and tolerance > 0) or int(max_iterations) < 1:
        raise ParameterError(f"tolerance={tolerance!r}, max_iterations={max_iterations!r}: expected a positive "
                             "tolerance and at least one iteration")
    if rho is not None and not (np.isfinite(rho) and rho > 0):
        raise ParameterError(f"rho={rho!r}: expected a finite penalty > 0 (kg), or None for the default")
    if int(check_every) < 1 or int(shift_every) < 0 or int(balance_every) < 0:
        raise ParameterError(f"check_every={check_every!r}, shift_every={shift_every!r}, "
                             f"balance_every={balance_every!r}: expected check_every >= 1 (the residual is the "
                             "stopping test) and the others >= 0")
    r = np.zeros((points, 2)) if initial is None else np.array(initial, dtype=np.float64)
    if r.size != 2 * points or not np.all(np.isfinite(r)):
        raise ParameterError(f"initial must hold 2 finite impulses per point ({2 * points} values), got {r.size}")
    r = r.reshape(points, 2)
    if fixed_shift is not None:
        fixed_shift = np.asarray(fixed_shift, dtype=np.float64).reshape(-1)
        if fixed_shift.size != points or not np.all(np.isfinite(fixed_shift)):
            raise ParameterError(f"fixed_shift must hold one finite shift per point ({points} values), got "
                                 f"{fixed_shift.size}")
    record = {} if record is None else record
    record.update(checks=[], admm=[], factorisations=0, factor_seconds=0.0, rho=[])
    best, best_r = _law(problem, r)[0], r.copy()
    record["checks"].append((0, best, np.nan, time.perf_counter() - start))
    D, mu = problem.D, problem.mu
    if scaling == "wnn":  # each point's rows times sqrt(omega_k), omega_k = median(W_nn) / W_nn,k
        omega = np.median(problem.wnn) / problem.wnn
    elif scaling == "none":
        omega = np.ones(points)
    else:
        raise ParameterError(f"scaling={scaling!r}: expected 'none' or 'wnn'")
    root = np.repeat(np.sqrt(omega), 2)
    A = (sparse.diags(root) @ problem.A).tocsr()
    c = root * problem.c
    if points == 0 or A.shape[1] == 0 or best <= tolerance:
        return _solution(problem, best_r, 0, best <= tolerance, record, start)
    rho = float(np.median(1.0 / problem.wnn)) if rho is None else float(rho)
    clock = time.perf_counter()
    lu = factorise(D, A, rho)
    record["factor_seconds"] += time.perf_counter() - clock
    record["factorisations"] += 1
    record["rho"].append(rho)

    # the start: r and the velocities it implies
    u, _ = local_velocities(problem, r)
    shift = np.zeros(2 * points)
    shift[0::2] = root[0::2] * (mu * np.abs(u[:, 1]) if fixed_shift is None else fixed_shift)
    xi = r.reshape(-1) / (rho * root)
    z = root * u.reshape(-1) + shift
    zn, zt = np.empty(points), np.empty(points)
    z_hat, xi_hat, z_prev, xi_prev = z.copy(), xi.copy(), z.copy(), xi.copy()
    tau, e_prev = 1.0, np.inf
    iterations, changed, bests = 0, 0, []

    def _new_rho(value):
        """rho = value, D + rho A^T A factored again, xi rescaled (r unchanged), momentum reset."""
        nonlocal xi, xi_hat, xi_prev, tau, e_prev
        factor = rho / value
        xi, xi_hat, xi_prev = xi * factor, xi_hat * factor, xi_prev * factor
        clock = time.perf_counter()
        factored = factorise(D, A, value)
        record["factor_seconds"] += time.perf_counter() - clock
        record["factorisations"] += 1
        record["rho"].append(float(value))
        tau, e_prev = 1.0, np.inf
        return float(value), factored

    for iterations in range(1, int(max_iterations) + 1):
        y = lu.solve(rho * (A.T @ (z_hat + xi_hat - c - shift)))
        Ay = A @ y
        w = Ay + c + shift - xi_hat
        dual_cone_projection(np.ascontiguousarray(w[0::2]), np.ascontiguousarray(w[1::2]), mu, zn, zt)
        z_new = np.empty_like(z)
        z_new[0::2], z_new[1::2] = zn, zt
        xi_new = z_new - w
        primal = Ay + c + shift - z_new
        if acceleration:
            e = rho * (float(primal @ primal) + float((z_new - z_hat) @ (z_new - z_hat)))
            if e < eta * e_prev:
                tau_next = 0.5 * (1.0 + np.sqrt(1.0 + 4.0 * tau * tau))
                alpha = (tau - 1.0) / tau_next
                z_hat = z_new + alpha * (z_new - z)
                xi_hat = xi_new + alpha * (xi_new - xi)
                tau, e_prev = tau_next, e
                z_prev, xi_prev, z, xi = z, xi, z_new, xi_new
            else:  # restart: the momentum dropped, the iterate kept
                tau, e_prev = 1.0, e
                z_prev, xi_prev, z, xi = z, xi, z_new, xi_new
                z_hat, xi_hat = z, xi
        else:
            z_prev, xi_prev, z, xi = z, xi, z_new, xi_new
            z_hat, xi_hat = z, xi
        if fixed_shift is None and shift_every and iterations % shift_every == 0:
            shift[0::2] = mu * np.abs(z[1::2])
        if check_every and iterations % check_every == 0:
            impulse = (rho * root * xi).reshape(points, 2)
            law = _law(problem, impulse)[0]
            record["checks"].append((iterations, law, rho, time.perf_counter() - start))
            record["admm"].append((iterations, float(np.linalg.norm(primal) / max(np.linalg.norm(c + shift), 1e-300)),
                                   float(np.linalg.norm(z_new - z_prev) / max(np.linalg.norm(z_new), 1e-300))))
            if law < best:
                best, best_r = law, impulse
            if best <= tolerance:
                break
            bests.append((iterations, best))
            earlier = [b for it, b in bests if it <= iterations - STALL_WINDOW and it >= changed]
            if (stall_growth and earlier and best > (1.0 - STALL_IMPROVEMENT) * earlier[-1]
                    and rho * stall_growth <= RHO_RANGE * record["rho"][0]):
                rho, lu = _new_rho(rho * stall_growth)
                changed = iterations
        if balance_every and iterations % balance_every == 0:
            scale_primal = max(np.linalg.norm(Ay), np.linalg.norm(z_new), np.linalg.norm(c + shift), 1e-300)
            dual = rho * (A.T @ (z_new - z_prev))
            scale_dual = max(np.linalg.norm(D * y), np.linalg.norm(rho * (A.T @ xi_new)), 1e-300)
            primal_rel, dual_rel = np.linalg.norm(primal) / scale_primal, np.linalg.norm(dual) / scale_dual
            # both near rounding: nothing to balance; one change at most 100x
            ratio = 1.0 if max(primal_rel, dual_rel) < 1e-13 else primal_rel / max(dual_rel, 1e-300)
            suggested = rho * float(np.clip(np.sqrt(ratio), 1e-2, 1e2))
            if suggested > refactor_ratio * rho or suggested < rho / refactor_ratio:
                rho, lu = _new_rho(suggested)
                changed = iterations
    return _solution(problem, best_r, iterations, best <= tolerance, record, start)


def _solution(problem, impulse, iterations, converged, record, start) -> ContactSolution:
    """The :class:`ContactSolution` of ``impulse``, its residual computed afresh."""
    law, violation, u = _law(problem, impulse)
    record["seconds"] = time.perf_counter() - start
    return ContactSolution(impulse, u, int(iterations), law, largest_point_residual(violation, impulse), law,
                           bool(converged))
