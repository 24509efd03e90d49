"""A two-level method for u = W r + q: NLGS sweeps and one multigrid step on the current face.

A truncated nonsmooth Newton multigrid cycle (TNNMG: Gräser & Kornhuber, *Truncated nonsmooth
Newton multigrid methods for convex minimization problems*, Domain Decomposition Methods in
Science and Engineering XVIII, 2009; Gräser & Sander, arXiv:1709.04992, for block-separable
problems) inside De Saxcé's fixed point on the shift s, for the 2D frictional contact
problem of :mod:`solver.contact_problem` (n points, impulses r_k = (r_n, r_t) in N s, W the
2n x 2n Delassus matrix in s kg-1, q the free velocities in m s-1, Coulomb cones
K_k = {|r_t| <= mu_k r_n}).

For a fixed shift s_k = mu_k |u_t,k| (m s-1), the impulses that satisfy Signorini and Coulomb
minimise the convex

    J(r) = 1/2 r . W r + (q + s e_n) . r   over r in K = K_1 x ... x K_n,

e_n the normal rows (De Saxcé's bipotential: u^ = u + s e_n, K* ∋ u^ ⊥ r ∈ K). One cycle, with
s from the end of the previous cycle (from the starting impulses for the first):

1. ``pre_sweeps`` NLGS sweeps (:func:`solver.nlgs.solve_matrix`, the exact Coulomb local solve;
   with ``smoother="convex"``, :func:`convex_sweeps`, J's exact local minimiser);
2. every point classified on the face of K it sits on: *open* (r_n = 0: no free direction),
   *sticking* (|r_t| < mu r_n: both components free), *sliding* (|r_t| = mu r_n: one free
   direction, the cone's edge e = (1, sigma mu), sigma = sign r_t). The free directions are the
   columns of a block-diagonal T (2x2 blocks, a zero column for each frozen direction);
3. the truncated Newton system (T^T W T + D_0 + eps diag) d = -T^T (W r + q + s e_n), D_0 the
   diagonal of W on the frozen directions (it keeps their rows decoupled, and their d is
   dropped), eps = ``regularisation`` times the diagonal of the truncated matrix, solved
   approximately by ONE smoothed-aggregation V-cycle of pyamg (Vaněk, Mandel & Brezina,
   Computing 56 (1996) 179-196), from d = 0. The hierarchy is built on the first cycle and
   again when more than ``rebuild_fraction`` of the points have changed class since it was
   built; in between only its finest matrix (and smoother) follows the current face (a
   hierarchy of one level, a problem small enough to be solved directly, is built every cycle);
4. the correction projected point by point on the cones, r' = P_K(r + T d)
   (:func:`solver.residuals.cone_projection`), and the exact minimiser of the quadratic J on
   the segment r + t (r' - r), t in [0, 1] (r + t (r' - r) stays in K, K being convex):
   t = -g . delta / (delta . W delta), clipped to [0, 1];
5. ``post_sweeps`` NLGS sweeps; then the local-law residual |F| / |r| of
   :mod:`solver.contact_solution` and the shift s = mu |u_t| for the next cycle.

The cycles stop when the local-law residual is within ``tolerance`` or after
``max_iterations`` cycles. With ``coarse=False`` steps 2-4 are skipped: a cycle is then
``pre_sweeps + post_sweeps`` plain sweeps (the control of the experiment). How it does on the
stepper's problems, and why: benchmarks/results/two-level.md (``python -m benchmarks.two_level``).
"""

from __future__ import annotations

import time
from typing import NamedTuple

import numpy as np
from numba import njit

from grainview.contract.errors import ParameterError

from solver.contact_solution import ContactSolution, contact_solution, local_law_residual, natural_map_at
from solver.residuals import cone_projection
from solver.solve_records import Impulses, Limits, MatrixProblem

__all__ = ["OPEN", "STICKING", "SLIDING", "CycleRecord", "Face", "TwoLevelResult", "classify", "face_basis",
           "project_on_cones", "cone_minimiser", "convex_sweeps", "solve", "solve_recorded"]

OPEN, STICKING, SLIDING = 0, 1, 2
"""The classes of a point (module docstring); a sliding point's class is SLIDING times the sign of
r_t (2 or -2), so that a reversal of the sliding direction counts as a change of class."""
EDGE_TOLERANCE = 1e-9
"""A loaded point is on the cone's edge when |r_t| >= (1 - EDGE_TOLERANCE) mu r_n."""


class CycleRecord(NamedTuple):
    """What one cycle did (module docstring).

    residual : the local-law residual |F| / |r| at the end of the cycle;
    step : the accepted line-search length t in [0, 1] of the coarse step (NaN without one);
    coarse_decrease : J's decrease by the coarse step (N s m s-1 = J); J at the cycle's shift;
    decrease : J's decrease over the whole cycle (sweeps and coarse step), same J;
    coarse_share : coarse_decrease / decrease (NaN when J did not decrease over the cycle);
    rebuilt : the multigrid hierarchy was built in this cycle;
    changed : the share of points whose class differs from the one the hierarchy was built on;
    free : the free directions of the truncated system (its size less the frozen rows);
    setup_seconds : seconds spent building the hierarchy (0 when reused) and the truncated matrix;
    seconds : the whole cycle's seconds, setup and residual included.
    """

    residual: float
    step: float
    coarse_decrease: float
    decrease: float
    coarse_share: float
    rebuilt: bool
    changed: float
    free: int
    setup_seconds: float
    seconds: float


class TwoLevelResult(NamedTuple):
    """:func:`solve_recorded`'s result: the solution, the starting residual, one
    :class:`CycleRecord` per cycle, and the number of hierarchies built."""

    solution: ContactSolution
    initial_residual: float
    cycles: list
    builds: int


def classify(impulse, mu):
    """The class of every point (n,) int: OPEN (r_n <= 0), STICKING (|r_t| < mu r_n) or
    +-SLIDING (on the edge of its cone, the sign of r_t), for impulses ``impulse`` (n, 2)."""
    rn, rt = impulse[:, 0], impulse[:, 1]
    loaded = rn > 0.0
    edge = loaded & (np.abs(rt) >= (1.0 - EDGE_TOLERANCE) * mu * rn)
    out = np.where(loaded, STICKING, OPEN)
    return np.where(edge, np.where(rt >= 0.0, SLIDING, -SLIDING), out)


def face_basis(classes, mu):
    """The 2x2 blocks of T (n, 2, 2) for ``classes``: the free directions of each point as
    columns (module docstring): open, zero; sticking, the identity; sliding with r_t of sign
    sigma, the edge (1, sigma mu) as first column and a zero second column."""
    n = classes.size
    basis = np.zeros((n, 2, 2))
    stick = classes == STICKING
    basis[stick, 0, 0] = basis[stick, 1, 1] = 1.0
    slide = np.abs(classes) == SLIDING
    basis[slide, 0, 0] = 1.0
    basis[slide, 1, 0] = np.sign(classes[slide]) * mu[slide]
    return basis


@njit(cache=True)
def _project(zn, zt, mu):
    """:func:`solver.residuals.cone_projection` of every point, in place on ``zn, zt`` (n,)."""
    for k in range(mu.size):
        zn[k], zt[k] = cone_projection(zn[k], zt[k], mu[k])


def project_on_cones(z, mu):
    """The Euclidean projection of every point's (z_n, z_t) of ``z`` (n, 2) on its Coulomb cone
    {|r_t| <= mu r_n} (:func:`solver.residuals.cone_projection`), a new (n, 2) array."""
    zn, zt = np.ascontiguousarray(z[:, 0], dtype=np.float64), np.ascontiguousarray(z[:, 1], dtype=np.float64)
    _project(zn, zt, np.ascontiguousarray(mu, dtype=np.float64))
    return np.stack([zn, zt], -1)


class Face:
    """W as 2x2 blocks and the truncated matrix T^T W T + D_0 + eps diag of a face (module
    docstring, step 3; s kg-1), built block by block from W's blocks; eps = ``regularisation``."""

    def __init__(self, W, regularisation):
        from scipy import sparse

        self.blocks = sparse.bsr_matrix(W, blocksize=(2, 2))
        self.blocks.sort_indices()
        indptr = self.blocks.indptr
        self.rows = np.repeat(np.arange(indptr.size - 1), np.diff(indptr))
        self.cols = self.blocks.indices
        self.diagonal_block = np.flatnonzero(self.rows == self.cols)
        if self.diagonal_block.size != indptr.size - 1:
            raise ParameterError("W must store the diagonal 2x2 block of every point")
        self.diagonal = W.diagonal().reshape(-1, 2)
        self.regularisation = regularisation

    def matrix(self, basis):
        """The truncated matrix (BSR, 2x2 blocks) for the blocks ``basis`` (n, 2, 2) of T."""
        from scipy import sparse

        data = np.matmul(np.swapaxes(basis[self.rows], 1, 2), np.matmul(self.blocks.data, basis[self.cols]))
        frozen = ~np.any(basis != 0.0, axis=1)  # (n, 2): the zero columns of T
        diagonal = data[self.diagonal_block]
        for j in range(2):
            diagonal[:, j, j] = np.where(frozen[:, j], self.diagonal[:, j], diagonal[:, j, j])
            diagonal[:, j, j] *= 1.0 + self.regularisation
        data[self.diagonal_block] = diagonal
        return sparse.bsr_matrix((data, self.cols, self.blocks.indptr), shape=self.blocks.shape), frozen


def _hierarchy(A, near_null):
    """pyamg's smoothed-aggregation hierarchy of ``A`` (BSR, 2x2 blocks: points are aggregated
    whole), with the near-null-space candidates ``near_null`` (2n, k)."""
    try:
        import pyamg
    except ImportError:
        raise ParameterError("the two-level method needs pyamg (pip install pyamg)") from None
    return pyamg.smoothed_aggregation_solver(A, B=near_null, max_coarse=50)


@njit(cache=True)
def cone_minimiser(bn, bt, wnn, wnt, wtt, mu):
    """The minimiser (r_n, r_t) of 1/2 r . W_k r + b . r over the cone {|r_t| <= mu r_n}, W_k the
    2x2 block (wnn, wnt, wtt) (s kg-1), b (m s-1): the unconstrained minimiser -W_k^-1 b when
    it lies in the cone, else the better of the minimisers along the cone's two edges
    e = (1, +-mu), alpha e with alpha = max(0, -e . b / e . W_k e) (the apex when both are 0).
    This is the projection of -W_k^-1 b on the cone in the metric of W_k."""
    det = wnn * wtt - wnt * wnt
    if det > 0.0:
        rn = -(wtt * bn - wnt * bt) / det
        rt = -(wnn * bt - wnt * bn) / det
        if rn >= 0.0 and abs(rt) <= mu * rn:
            return rn, rt
    best_n, best_t, best = 0.0, 0.0, 0.0
    for sign in (1.0, -1.0):
        et = sign * mu
        curvature = wnn + 2.0 * et * wnt + et * et * wtt
        slope = bn + et * bt
        if curvature > 0.0 and slope < 0.0:
            alpha = -slope / curvature
            value = -0.5 * slope * slope / curvature
            if value < best:
                best_n, best_t, best = alpha, alpha * et, value
    return best_n, best_t


@njit(cache=True)
def convex_sweeps(matrix, impulses, shift, count):
    """``count`` Gauss–Seidel sweeps on J (module docstring) for the shift ``shift`` (n,) m s-1:
    each point in turn takes :func:`cone_minimiser` of its block with the others frozen
    (b = its velocity less its own block's share, plus s on the normal), in place on
    ``impulses``. Unlike :func:`solver.nlgs.local_solve` (Coulomb's law, which J's minimiser
    meets only when s = mu |u_t|), each local step never raises J."""
    indptr, indices, data, q, mu = matrix
    rn, rt = impulses
    n = mu.size
    for _ in range(count):
        for k in range(n):
            un = q[2 * k]
            ut = q[2 * k + 1]
            wnn = wnt = wtt = 0.0
            for e in range(indptr[2 * k], indptr[2 * k + 1]):
                c = indices[e]
                un += data[e] * (rn[c // 2] if c % 2 == 0 else rt[c // 2])
                if c == 2 * k:
                    wnn += data[e]
                elif c == 2 * k + 1:
                    wnt += data[e]
            for e in range(indptr[2 * k + 1], indptr[2 * k + 2]):
                c = indices[e]
                ut += data[e] * (rn[c // 2] if c % 2 == 0 else rt[c // 2])
                if c == 2 * k + 1:
                    wtt += data[e]
            bn = un - wnn * rn[k] - wnt * rt[k] + shift[k]
            bt = ut - wnt * rn[k] - wtt * rt[k]
            rn[k], rt[k] = cone_minimiser(bn, bt, wnn, wnt, wtt, mu[k])


def _objective(x, u, q, shift):
    """J(r) = 1/2 r . W r + (q + s e_n) . r from r and u = W r + q, both (2n,); ``shift`` (2n,)
    holds s on the normal rows."""
    return 0.5 * float(x @ (u - q)) + float(x @ (q + shift))


def solve_recorded(W, q, mu, tolerance, max_iterations, initial, *, coarse=True, pre_sweeps=1, post_sweeps=1,
                   regularisation=1e-8, rebuild_fraction=0.05, smoother="coulomb") -> TwoLevelResult:
    """The cycles of the module docstring from ``initial`` (n, 2), recorded.

    Parameters
    ----------
    W : (2n, 2n) scipy.sparse CSR, the Delassus matrix (s kg-1), storing every diagonal block.
    q : (2n,) free local velocities (m s-1); mu : (n,) friction coefficients.
    tolerance : the local-law residual |F| / |r| at which the cycles stop.
    max_iterations : the largest number of cycles.
    initial : (n, 2) starting impulses (N s).
    coarse : with the multigrid step (False: sweeps only, the control).
    pre_sweeps, post_sweeps : NLGS sweeps before and after the coarse step.
    regularisation : eps of the truncated matrix's diagonal (module docstring).
    rebuild_fraction : the share of points changing class that triggers a new hierarchy.
    smoother : ``coulomb``, the NLGS sweep of :func:`solver.nlgs.solve_matrix` (Coulomb's local
        law); ``convex``, :func:`convex_sweeps` (J's local minimiser at the cycle's shift, the
        smoother TNNMG's convergence proof asks for).

    Returns
    -------
    TwoLevelResult: the :class:`ContactSolution` (iterations = cycles), the starting residual and
    one :class:`CycleRecord` per cycle.
    """
    from solver import nlgs
    from solver.contact_problem import check_problem

    W, q, mu, n = check_problem(W, q, mu)
    initial = np.asarray(initial, dtype=np.float64).reshape(-1)
    if initial.size != 2 * n or not np.all(np.isfinite(initial)):
        raise ParameterError(f"initial must hold 2 finite impulses per point ({2 * n} values), got {initial.size}")
    initial = initial.reshape(n, 2)
    if int(max_iterations) < 1 or not (np.isfinite(tolerance) and tolerance > 0):
        raise ParameterError(f"tolerance={tolerance!r}, max_iterations={max_iterations!r}: expected a positive "
                             "number and an integer >= 1")
    if pre_sweeps < 0 or post_sweeps < 0 or (not coarse and pre_sweeps + post_sweeps == 0):
        raise ParameterError(f"pre_sweeps={pre_sweeps}, post_sweeps={post_sweeps}: expected counts >= 0, "
                             "at least one sweep when coarse=False")
    if smoother not in ("coulomb", "convex"):
        raise ParameterError(f"smoother={smoother!r}: expected 'coulomb' or 'convex'")
    if not (0.0 <= regularisation < 1.0) or not (0.0 <= rebuild_fraction <= 1.0):
        raise ParameterError(f"regularisation={regularisation}, rebuild_fraction={rebuild_fraction}: expected "
                             "regularisation in [0, 1) and rebuild_fraction in [0, 1]")
    rn = np.ascontiguousarray(initial[:, 0], dtype=np.float64).copy()
    rt = np.ascontiguousarray(initial[:, 1], dtype=np.float64).copy()
    matrix = MatrixProblem(W.indptr.astype(np.int64), W.indices.astype(np.int64), W.data, q, mu)
    x = np.empty(2 * n)

    def gather():
        x[0::2], x[1::2] = rn, rt
        return x

    def sweeps(count):
        if count and smoother == "coulomb":
            nlgs.solve_matrix(matrix, Impulses(rn, rt), Limits(1e-300, 1e-300, int(count), 0))
        elif count:
            convex_sweeps(matrix, Impulses(rn, rt), shift[0::2].copy(), int(count))

    rho = 1.0 / W.diagonal()[0::2]
    u = W @ gather() + q

    def residual(u):
        impulse = x.reshape(n, 2)
        return local_law_residual(natural_map_at(impulse, u.reshape(n, 2), mu, rho), impulse)

    law = initial_law = residual(u)
    shift = np.zeros(2 * n)
    shift[0::2] = mu * np.abs(u[1::2])
    face = Face(W, regularisation) if coarse else None
    near_null = np.kron(np.ones((n, 1)), np.eye(2))
    hierarchy, built_on, builds = None, None, 0
    records = []
    while law > tolerance and len(records) < max_iterations:
        start = time.perf_counter()
        j_start = _objective(x, u, q, shift)
        sweeps(pre_sweeps)
        step, coarse_decrease, rebuilt, changed, free, setup = np.nan, 0.0, False, 0.0, 0, 0.0
        if coarse:
            u = W @ gather() + q
            j_before = _objective(x, u, q, shift)
            impulse = x.reshape(n, 2)
            classes = classify(impulse, mu)
            changed = 1.0 if built_on is None else float(np.mean(classes != built_on))
            clock = time.perf_counter()
            basis = face_basis(classes, mu)
            A, frozen = face.matrix(basis)
            free = int(2 * n - frozen.sum())
            if hierarchy is None or changed > rebuild_fraction or len(hierarchy.levels) == 1:
                hierarchy, built_on, rebuilt = _hierarchy(A, near_null), classes, True
                builds += 1
                changed = 0.0
            else:
                hierarchy.change_solve_matrix(A)
            setup = time.perf_counter() - clock
            gradient = (u + shift).reshape(n, 2)
            d = hierarchy.aspreconditioner(cycle="V") @ (-np.einsum("kji,kj->ki", basis, gradient).reshape(-1))
            d = np.where(frozen, 0.0, d.reshape(n, 2))
            delta = project_on_cones(impulse + np.einsum("kij,kj->ki", basis, d), mu) - impulse
            w_delta = W @ delta.reshape(-1)
            slope = float(delta.reshape(-1) @ gradient.reshape(-1))
            curvature = float(delta.reshape(-1) @ w_delta)
            if curvature > 0.0:
                step = min(max(-slope / curvature, 0.0), 1.0)
            else:
                step = 1.0 if slope < 0.0 else 0.0
            rn += step * delta[:, 0]
            rt += step * delta[:, 1]
            u = u + step * w_delta
            coarse_decrease = j_before - _objective(gather(), u, q, shift)
        sweeps(post_sweeps)
        u = W @ gather() + q
        decrease = j_start - _objective(x, u, q, shift)
        law = residual(u)
        shift[0::2] = mu * np.abs(u[1::2])
        records.append(CycleRecord(law, step, coarse_decrease, decrease,
                                   coarse_decrease / decrease if decrease > 0.0 else np.nan, rebuilt, changed, free,
                                   setup, time.perf_counter() - start))
    solution = contact_solution(W, q, mu, gather().reshape(n, 2).copy(), len(records), law <= tolerance)
    return TwoLevelResult(solution, initial_law, records, builds)


def solve(W, q, mu, tolerance, max_iterations, initial, **options) -> ContactSolution:
    """:func:`solve_recorded`'s solution alone (the signature of the matrix methods of
    :mod:`solver.contact_solvers`; ``options`` are :func:`solve_recorded`'s keywords)."""
    return solve_recorded(W, q, mu, tolerance, max_iterations, initial, **options).solution
