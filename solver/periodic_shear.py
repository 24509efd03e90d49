"""Simple shear of a biperiodic cell under a controlled normal stress (``grainview run shear``).

A compacted sample between walls (:mod:`solver.scenes`) is put into the biperiodic cell of its
box (:func:`periodic_sample`): the particles that touched the left wall now touch the images of
those that touched the right one, within the walls' overlap. The cell is then sheared at the
imposed rate gamma_dot (its tilt grows at gamma_dot h; Lees–Edwards: the images one cell up
move at db/dt = (gamma_dot h, dh/dt)), its height held at sigma_yy = sigma0 with the inertia
of :data:`CELL_MASS` times the sample's mass, its rate solved with the contacts
(:mod:`solver.cell_coupling`), until the shear gamma = gamma_dot t reaches ``strain``; by
default gamma_dot is the biaxial test's pace (:func:`matching_shear_rate`). The particles start from the affine velocity field
gamma_dot (y - y_mid) e_x, so that the flow does not have to grow from the boundary.

The file is the contract's periodic layout (docs/schema.md, "The periodic cell"): ``cell`` per
snapshot, ``periodic`` (1, 1), centres wrapped into the cell, branches the minimum images.
"""

from __future__ import annotations

import sys

import numpy as np

from grainview.contract.errors import ParameterError
from grainview.contract.schema import MAX_STEP_INDEX

from .contact_solvers import check_cell_coupling
from .contact_points import rank_in_pair
from .interrupt import interruptible, progress_bar, resume_instructions, stop_exception, stop_reason
from .output import Recorder
from .parameters import SHEAR_STRAIN
from .periodic_cell import PeriodicCell
from .stepper import Simulation

SHEAR_EVERY = 200
"""Default steps between snapshots."""
CELL_MASS = 0.1
"""The cell's mass under stress control, in units of the sample's mass: a numerical setting of the
control (the quasi-static state does not depend on it); a tenth held sigma_yy closer to sigma0 in
fewer sweeps than the whole mass (benchmarks/results/periodic-control.md)."""


def periodic_sample(sim: Simulation, *, stress=None, mass=None, max_speed=np.inf) -> Simulation:
    """The particles of the walled ``sim`` in the biperiodic cell of its box (module doc), at
    rest, with ``sim``'s parameters, shapes and history, the particle pairs' last impulses as
    the warm start (shown as the contacts of the test's first snapshot); the height held at the normal stress
    ``stress`` (Pa; default ``sim.history.sigma0``; None for a fixed height when sigma0 is not
    known) with the inertia ``mass`` (kg; default :data:`CELL_MASS` times the particles' total
    mass)."""
    lo, hi = sim.walls.box_bounds()
    stress = sim.history.sigma0 if stress is None else stress
    stress = None if stress is None or not np.isfinite(stress) else float(stress)
    cell = PeriodicCell(lo, float(hi[0] - lo[0]), float(hi[1] - lo[1]), stress=stress,
                        mass=CELL_MASS * float(sim.mass.sum()) if mass is None else float(mass),
                        max_speed=max_speed)
    n = sim.n_particles
    out = Simulation(sim.position[:n], sim.angle, walls=None, parameters=sim.parameters, shapes=sim.shapes, cell=cell)
    out.history = sim.history
    out.time, out.step_index = sim.time, sim.step_index
    pts = sim.points
    if pts is not None and len(pts.pair):  # the particle pairs keep their last impulses as the warm start
        keep = pts.body_j < n
        rank = rank_in_pair(pts.pair)[keep]
        pairs, slot = np.unique(pts.pair[keep], return_inverse=True)
        normal, tangential = np.zeros((pairs.size, 2)), np.zeros((pairs.size, 2))
        normal[slot, rank] = sim.impulse[keep, 0]
        tangential[slot, rank] = sim.impulse[keep, 1]
        first = np.flatnonzero(keep)[np.unique(slot, return_index=True)[1]]
        out.set_warm_start(pts.body_i[first], pts.body_j[first], normal, tangential)
    out.show_warm_start()  # the test's first snapshot shows the sample's contacts and forces
    return out


def matching_shear_rate(sim: Simulation, velocity: float) -> float:
    """The shear rate gamma_dot (s-1) that deforms the compacted ``sim`` as fast as the biaxial
    test whose top wall moves at ``velocity`` (m s-1): gamma_dot = 2 v / h, h the height of the
    sample's box (m).

    Both tests are compared in the strain the residual state is read in: eps_q = eps_1 - eps_2
    in the biaxial test, gamma in simple shear (its principal strains are +-gamma/2). The top
    wall gives eps_1 at the rate v/h; a test at constant volume gives eps_2 at -v/h, so eps_q
    grows at 2 v/h, and a cell sheared at gamma_dot = 2 v/h reaches each strain in the same
    time, at the same inertia number gamma_dot d sqrt(rho/p)."""
    if sim.walls is not None:
        lo, hi = sim.walls.box_bounds()
        height = float(hi[1] - lo[1])
    else:
        height = float(sim.cell.height)
    if not (np.isfinite(velocity) and velocity > 0):
        raise ParameterError(f"velocity={velocity!r}: expected a positive speed in m s-1")
    return 2.0 * float(velocity) / height


def cell_settings(cell: PeriodicCell) -> dict:
    """Global attributes of how the cell is driven (read back by a resume)."""
    return {"cell_shear_rate_s": float(cell.shear_rate),
            "cell_stress_Pa": "none" if cell.stress is None else float(cell.stress),
            "cell_mass_kg": float(cell.mass), "cell_max_speed_m_s": float(cell.max_speed)}


def shear_test(sim: Simulation, path, *, strain=SHEAR_STRAIN, shear_rate, every=SHEAR_EVERY,
               overwrite=False, attrs=None, progress=None, near_contacts=False, compress=True, affine_start=True):
    """Shear the periodic ``sim`` (:func:`periodic_sample`) at ``shear_rate`` (s-1; the biaxial
    test's pace: :func:`matching_shear_rate`) until the
    shear gamma = ``strain``, a snapshot written to ``path`` every ``every`` steps and at the
    first and last (module doc). Returns the number of steps."""
    if sim.cell is None:
        raise ParameterError("shear_test: expected a simulation in a periodic cell (solver.periodic_shear."
                             "periodic_sample)")
    if not (np.isfinite(strain) and strain > 0 and np.isfinite(shear_rate) and shear_rate > 0):
        raise ParameterError(f"strain={strain!r}, shear_rate={shear_rate!r}: expected positive finite numbers")
    if not (isinstance(every, (int, np.integer)) and every >= 1):
        raise ParameterError(f"every={every!r}: expected a whole number of steps >= 1")
    steps = strain / shear_rate / sim.parameters.time_step
    if not np.isfinite(steps) or sim.step_index + steps > MAX_STEP_INDEX:
        raise ParameterError(f"the shear would take {steps:.3g} steps, beyond a file's step counter")
    n_steps = int(np.ceil(steps))
    cell = sim.cell
    if cell.stress is not None:
        check_cell_coupling(sim.parameters)
    cell.shear_rate = float(shear_rate)
    if affine_start:
        n = sim.n_particles
        middle = cell.origin[1] + 0.5 * cell.height
        sim.velocity[:n, 0] += shear_rate * (sim.position[:, 1] - middle)
    run_attrs = {"scene": "shear", "strain_target": float(strain), "snapshot_every": int(every),
                 "shear_steps": n_steps, "sigma0_Pa": sim.history.sigma0, **cell_settings(cell),
                 **sim.history.attrs()}
    run_attrs.update(attrs or {})
    with Recorder(path, sim, attrs=run_attrs, overwrite=overwrite, near_contacts=near_contacts,
                  compress=compress) as rec:
        rec.write()
        shear_steps(sim, rec, first=1, n_steps=n_steps, every=int(every), progress=progress)
    return n_steps


def shear_steps(sim: Simulation, recorder, *, first, n_steps, every, progress=None):
    """Steps ``first`` .. ``n_steps`` of a shear test, a snapshot every ``every`` steps and at
    the last; Ctrl-C or SIGTERM stops after the current step (as
    :func:`solver.scenes.biaxial_steps`)."""
    with interruptible() as flag, progress_bar(n_steps, "periodic shear", progress) as bar:
        bar.update(first - 1)
        for k in range(first, n_steps + 1):
            sim.step()
            bar.update(1)
            if k % every == 0 or k == n_steps:
                recorder.write()
            if flag["stop"] and k < n_steps:
                print(f"{stop_reason(flag)} after step {sim.step_index}: {recorder.writer.path} holds every "
                      f"snapshot written so far\n{resume_instructions(recorder.writer.path)}", file=sys.stderr)
                raise stop_exception(flag)
