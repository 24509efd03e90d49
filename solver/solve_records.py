"""The records that carry a contact problem, its unknowns and the solvers' scratch through the
compiled kernels.

Every record is a ``NamedTuple`` of arrays (structure of arrays) or of numbers, which numba
passes as one argument: a kernel takes ``problem, impulses, velocities`` and reads
``problem.rax[k]`` instead of taking the arrays one by one, so a field is named in one place
(here) and a new field reaches every kernel without editing a signature. Numba compiles a
kernel for the record's field types, so the machine code is that of the loose arrays.

Units: lengths m, velocities m s-1, angular velocities rad s-1, impulses N s, inverse masses
kg-1, inverse moments of inertia kg-1 m-2, Delassus entries s kg-1 (velocity per impulse).
P is the number of contact points, B the number of bodies (particles then walls).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = ["ContactProblem", "PeriodicContactProblem", "StressedCellProblem", "Impulses", "Velocities", "DelassusBlocks", "Limits", "AndersonScratch",
           "MatrixProblem", "StepStart", "StepLaw"]


class ContactProblem(NamedTuple):
    """The frictional contact problem of one time step, one entry per contact point
    (structure of arrays; body arrays indexed by body id, particles then walls).

    Attributes
    ----------
    a, b : int64 (P,)
        The two bodies of each point (the impulse acts on b, its reaction on a).
    nx, ny : float64 (P,)
        Unit normal from a to b.
    rax, ray, rbx, rby : float64 (P,)
        Lever arms (m) from the centre of a and of b to the point (0 for a wall).
    bias : float64 (P,)
        Signorini shift b_k (m s-1): u_n + b_k >= 0 (:mod:`solver.nlgs`).
    mu : float64 (P,)
        Friction coefficient.
    minv_xx, minv_xy, minv_yy : float64 (B,)
        Inverse mass matrix of each body (kg-1; a wall pushed by a stress translates along
        its normal only).
    iinv : float64 (B,)
        Inverse moment of inertia (kg-1 m-2).
    """

    a: np.ndarray
    b: np.ndarray
    nx: np.ndarray
    ny: np.ndarray
    rax: np.ndarray
    ray: np.ndarray
    rbx: np.ndarray
    rby: np.ndarray
    bias: np.ndarray
    mu: np.ndarray
    minv_xx: np.ndarray
    minv_xy: np.ndarray
    minv_yy: np.ndarray
    iinv: np.ndarray


class PeriodicContactProblem(NamedTuple):
    """A :class:`ContactProblem` in a periodic cell whose boundary moves (:mod:`solver.periodic_cell`):
    the same fields and ``slip`` (P,), the tangential velocity (m s-1) of the image of body b
    relative to body b along t = (-n_y, n_x) at each point (0 for a pair inside the cell); the
    image's normal velocity is in ``bias``. Every kernel that takes a ContactProblem takes it
    (:func:`solver.nlgs.tangential_slip`)."""

    a: np.ndarray
    b: np.ndarray
    nx: np.ndarray
    ny: np.ndarray
    rax: np.ndarray
    ray: np.ndarray
    rbx: np.ndarray
    rby: np.ndarray
    bias: np.ndarray
    mu: np.ndarray
    minv_xx: np.ndarray
    minv_xy: np.ndarray
    minv_yy: np.ndarray
    iinv: np.ndarray
    slip: np.ndarray


class StressedCellProblem(NamedTuple):
    """A :class:`PeriodicContactProblem` whose cell's height is held at a normal stress, its rate
    solved with the points (:mod:`solver.cell_coupling`): the same fields and ``image`` (P,)
    float, the image number n_k across the cell's height of each point's body b, and ``cell``
    (4,): the rate dh/dt the bias and slip hold at assembly and now (m s-1), the cell's mass (kg)
    and the external impulse h sigma0 l t (N s) (:data:`solver.cell_coupling.RATE_AT_ASSEMBLY`
    ...)."""

    a: np.ndarray
    b: np.ndarray
    nx: np.ndarray
    ny: np.ndarray
    rax: np.ndarray
    ray: np.ndarray
    rbx: np.ndarray
    rby: np.ndarray
    bias: np.ndarray
    mu: np.ndarray
    minv_xx: np.ndarray
    minv_xy: np.ndarray
    minv_yy: np.ndarray
    iinv: np.ndarray
    slip: np.ndarray
    image: np.ndarray
    cell: np.ndarray


class Impulses(NamedTuple):
    """The contact impulses over the step, one entry per point (the solvers' unknowns).

    Attributes
    ----------
    pn, pt : float64 (P,)
        Normal and tangential impulse (N s) in the point's frame (n, t), t = (-n_y, n_x).
    """

    pn: np.ndarray
    pt: np.ndarray


class Velocities(NamedTuple):
    """The bodies' velocities, one entry per body (particles then walls).

    Attributes
    ----------
    vx, vy : float64 (B,)
        Velocity of the centre (m s-1).
    w : float64 (B,)
        Angular velocity (rad s-1, counter-clockwise).
    """

    vx: np.ndarray
    vy: np.ndarray
    w: np.ndarray


class DelassusBlocks(NamedTuple):
    """The diagonal 2x2 Delassus block of every point, W_k = H_k^T M^-1 H_k (the velocity
    change at point k per unit impulse at point k; :func:`solver.nlgs.delassus_block`).

    Attributes
    ----------
    nn, nt, tt : float64 (P,)
        Entries W_nn, W_nt (= W_tn) and W_tt (s kg-1).
    """

    nn: np.ndarray
    nt: np.ndarray
    tt: np.ndarray


STALL_IMPROVEMENT = 0.05
"""Least relative fall of the best quadratic norm over ``Limits.stall`` sweeps below which the
NLGS's stall test stops the sweeps (:func:`solver.nlgs.stalled`; kept here, beside the limits and
away from the kernels, so that the settings can quote it without loading numba)."""


class Limits(NamedTuple):
    """When the sweeps stop (:mod:`solver.nlgs`).

    Attributes
    ----------
    tolerance : float
        Tolerance of the quadratic norm of the impulse change (dimensionless).
    max_tolerance : float
        Tolerance of the max norm (dimensionless).
    max_iterations : int
        The most sweeps run.
    stall : int
        Sweeps between two checks of the stall test (:func:`solver.nlgs.stalled`); 0: none.
    """

    tolerance: float
    max_tolerance: float
    max_iterations: int
    stall: int


class AndersonScratch(NamedTuple):
    """Working memory of the Anderson-accelerated sweeps (:mod:`solver.acceleration`); m is the
    memory (past iterates combined).

    Attributes
    ----------
    xn, xt : float64 (P,)
        The iterate x (N s).
    fn, ft : float64 (P,)
        Its residual f = G(x) - x (N s); during an extrapolation, the extrapolated impulses
        before their projection onto the Coulomb cone.
    fn_prev, ft_prev, gn_prev, gt_prev : float64 (P,)
        f and G(x) of the previous history pass (N s).
    dfn, dft, dgn, dgt : float64 (m, P)
        History rows: differences dF, dG of successive f and G(x) (N s).
    hvx, hvy, hw : float64 (B,)
        The bodies' velocities at the previous history pass (m s-1, rad s-1).
    dvx, dvy, dw : float64 (m, B)
        History rows of the velocity differences dV = M^-1 H dG (m s-1, rad s-1).
    gram : float64 (m, m)
        The normal equations' matrix dF_i . dF_j (N2 s2).
    row, rhs : float64 (m,)
        A new row of ``gram`` and the right-hand side dF_j . f (N2 s2).
    """

    xn: np.ndarray
    xt: np.ndarray
    fn: np.ndarray
    ft: np.ndarray
    fn_prev: np.ndarray
    ft_prev: np.ndarray
    gn_prev: np.ndarray
    gt_prev: np.ndarray
    dfn: np.ndarray
    dft: np.ndarray
    dgn: np.ndarray
    dgt: np.ndarray
    hvx: np.ndarray
    hvy: np.ndarray
    hw: np.ndarray
    dvx: np.ndarray
    dvy: np.ndarray
    dw: np.ndarray
    gram: np.ndarray
    row: np.ndarray
    rhs: np.ndarray


class MatrixProblem(NamedTuple):
    """A frictional contact problem given by its matrix: u = W r + q, rows 2k and 2k + 1 the
    normal and tangential velocity of point k (:func:`solver.nlgs.solve_matrix`,
    :mod:`solver.projected_cg`).

    Attributes
    ----------
    indptr, indices : int64 (2n + 1,), (nnz,)
        W (2n x 2n) in CSR form.
    data : float64 (nnz,)
        Its entries (s kg-1).
    q : float64 (2n,)
        The velocity without impulses, Signorini shift included (m s-1).
    mu : float64 (n,)
        Friction coefficient of each point.
    """

    indptr: np.ndarray
    indices: np.ndarray
    data: np.ndarray
    q: np.ndarray
    mu: np.ndarray


class StepStart(NamedTuple):
    """The bodies at the start of a step, what :func:`solver.problem_assembly.assemble` reads.

    Attributes
    ----------
    centre : float64 (B, 2)
        Centres of the particles, then the walls' reference points (m).
    velocity : float64 (B, 2)
        Start-of-step velocities (m s-1; imposed walls at their imposed velocity).
    omega : float64 (B,)
        Start-of-step angular velocities (rad s-1).
    n_particles : int
        Bodies before the first wall.
    """

    centre: np.ndarray
    velocity: np.ndarray
    omega: np.ndarray
    n_particles: int


class StepLaw(NamedTuple):
    """The time scheme and friction of a step (:func:`solver.problem_assembly.assemble`).

    Attributes
    ----------
    time_step : float
        h (s).
    theta : float
        The Moreau–Jean parameter.
    friction, wall_friction : float
        Friction coefficient between particles and between a particle and a wall.
    """

    time_step: float
    theta: float
    friction: float
    wall_friction: float
