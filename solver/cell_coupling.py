"""The height of a periodic cell under a normal stress, solved with the contacts.

The images one cell up move at db/dt = (gamma_dot h, dh/dt) (:mod:`solver.periodic_cell`). A
point k between body a and the image n_k cells up of body b (n_k = -1, 0 or 1) sees the image's
velocity n_k db/dt in its Signorini bias and its slip (:mod:`solver.periodic_assembly`). Under
stress control dh/dt is not known before the step: the cell is a body of mass M on which the
points across its boundary push, and the external normal stress sigma0 pulls,

    M (hdot+ - hdot-) = sum_k n_k P_y,k - h sigma0 l t,

P_y,k = p_n n_y + p_t n_x the y-impulse of point k on the image (h the time step, l t the cell's
cross-section). It is solved with the points, as the biaxial test's walls are: the sweeps
(:func:`solver.nlgs.solve`, :func:`solver.acceleration.solve_anderson`) call
:func:`couple_cell` after every sweep and every extrapolation, which solves the cell's linear
equation exactly with the points' impulses frozen and moves the bias (n_k dhdot n_y) and slip
(n_k dhdot n_x) of the points across the boundary to the new rate. The rate is a function of the
impulses, so an extrapolated iterate gets its own. Convergence is the points': a change of the
rate changes the next sweep's impulses.

For every other problem (:class:`solver.solve_records.ContactProblem`,
:class:`~solver.solve_records.PeriodicContactProblem`) :func:`couple_cell` compiles to nothing.

A rate computed explicitly from the stress of the step before cannot stop a cell closing on a
jammed packing of rigid grains: the points cannot open, their impulses grow without bound and the
cell rebounds off the packing (benchmarks/results/periodic-control.md).
"""

from __future__ import annotations

from numba import njit
from numba.extending import overload

RATE_AT_ASSEMBLY, RATE, MASS, LOAD = 0, 1, 2, 3
"""The entries of a :class:`solver.solve_records.StressedCellProblem`'s ``cell`` (4,): dh/dt
that the bias and slip hold at assembly (m s-1), the one they hold now (updated in place), M
(kg) and h sigma0 l t (N s)."""


def couple_cell(problem, impulses):
    """Solve the cell's rate from ``impulses`` and move the bias and slip of the points across
    the boundary to it (module doc), in place; nothing for a problem without a ``cell``."""
    if hasattr(problem, "cell"):
        _couple(problem, impulses)


@njit(cache=True)
def cell_rate(problem, impulses):
    """dh/dt+ of a :class:`~solver.solve_records.StressedCellProblem` from ``impulses``."""
    pn, pt = impulses
    cell = problem.cell
    total = 0.0
    for k in range(pn.size):
        n = problem.image[k]
        if n != 0.0:
            total += n * (pn[k] * problem.ny[k] + pt[k] * problem.nx[k])
    return cell[RATE_AT_ASSEMBLY] + (total - cell[LOAD]) / cell[MASS]


@njit(cache=True)
def _couple(problem, impulses):
    new = cell_rate(problem, impulses)
    change = new - problem.cell[RATE]
    if change != 0.0:
        for k in range(problem.a.size):
            n = problem.image[k]
            if n != 0.0:
                problem.bias[k] += n * change * problem.ny[k]
                problem.slip[k] += n * change * problem.nx[k]
    problem.cell[RATE] = new


@overload(couple_cell, jit_options={"cache": True})
def _couple_cell(problem, impulses):
    if "cell" in getattr(problem, "fields", ()):
        return lambda problem, impulses: _couple(problem, impulses)
    return lambda problem, impulses: None
