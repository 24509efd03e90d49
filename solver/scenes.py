"""The paper's protocol as scenes (Sec. II.B): a geometric deposit, isotropic compaction under
sigma_0 on the right and top walls with zero gravity, then biaxial compression with the top
wall moving down at constant velocity and sigma_0 held on the right wall. Every number is a
parameter whose default is the paper's.
"""

from __future__ import annotations

import sys

import numpy as np
from grainview.contract import portable_math
from grainview.contract.errors import ParameterError
from grainview.contract.schema import MAX_STEP_INDEX

from .interrupt import interruptible, progress_bar, resume_instructions, stop_exception, stop_reason
from .output import Recorder
from .packing import PAPER_DIAMETERS, PAPER_FRACTIONS, box_width_for, deposit
from .shape_families import regular_vertex_count, sample_shapes
from .parameters import BiaxialTest, Parameters, Preparation, check_time_step, check_values
from .stepper import Simulation
from .walls import STRESS, Walls



def gravity_scene(position, angle, radius, n_vertices, *, gravity=9.81, tilt=0.0, sides=None, shapes=None,
                  **parameters) -> Simulation:
    """Particles on a fixed floor (the line y = 0, optional side walls at x = sides[0], sides[1])
    under gravity of magnitude ``gravity`` (m s-2) tilted by ``tilt`` (rad): the vector
    g (sin tilt, -cos tilt), which is the same as a floor inclined by ``tilt`` in a vertical
    gravity field, seen in the floor's frame. ``parameters`` go to :class:`Parameters`
    (friction with the floor is ``wall_friction``). For tests and demonstrations with analytic
    answers (resting bodies, a column, a block on an inclined plane). ``shapes``: the particles'
    :class:`solver.shapes.Shapes` (then ``radius`` and ``n_vertices`` are None), as
    :class:`Simulation` takes them."""
    if not (np.isfinite(gravity) and np.isfinite(tilt)):
        raise ParameterError(f"gravity={gravity!r}, tilt={tilt!r}: expected finite numbers (m s-2, rad)")
    g = (float(gravity) * np.sin(tilt), -float(gravity) * np.cos(tilt))
    params = Parameters(gravity=g, **parameters)
    return Simulation(position, angle, radius, n_vertices, Walls.floor(sides=sides), params, shapes=shapes)


def compaction_sample(n=Preparation.particles, shape=Preparation.shape, *, sigma0=Preparation.sigma0,
                      seed=Preparation.seed, diameters=PAPER_DIAMETERS, fractions=PAPER_FRACTIONS,
                      aspect=Preparation.aspect, wall_mass=None, max_wall_speed=Preparation.max_wall_speed,
                      **parameters) -> Simulation:
    """A deposited sample in its box, ready for isotropic compaction: bottom and left walls
    fixed, right and top walls pushed by ``sigma0`` (Pa), zero gravity. ``wall_mass``
    defaults to the total particle mass (kg); the pushed walls move inwards at most at
    ``max_wall_speed`` (m s-1) while they close the loose deposit. ``shape``: a regular shape,
    a family of random convex polygons or a file of them (:mod:`solver.shape_families`); the
    deposit places the circumscribed disks of the size mix either way. ``parameters`` go to
    :class:`Parameters` (friction, wall_friction, time_step...: their defaults are its own);
    ``seed`` is also the NLGS's."""
    check_values(Preparation, sigma0=sigma0)
    nv = regular_vertex_count(shape)
    width = box_width_for(n, diameters, fractions, aspect_ratio=aspect)
    position, angle, radius, n_vertices, height = deposit(n, diameters, fractions, nvert=nv, width=width, seed=seed)
    shapes, turned = sample_shapes(shape, radius, seed)
    angle = angle if turned is None else turned
    walls = Walls.box(width, height + 0.5 * float(radius.min()))
    params = Parameters(seed=seed, **parameters)
    sim = Simulation(position, angle, walls=walls, parameters=params, shapes=shapes)
    mass = float(sim.mass.sum()) if wall_mass is None else float(wall_mass)
    walls.drive_stress("right", sigma0, mass, max_wall_speed)
    walls.drive_stress("top", sigma0, mass, max_wall_speed)
    sim.history.sigma0 = sigma0
    return sim


def wall_state(sim):
    """Stress (Pa) on and strain rate (s-1) of every wall: the normal force of the particles
    over the wall's length, and the wall's normal speed over the box size across it."""
    rate = np.sum(sim.walls.velocity * sim.walls.normal, axis=1) / _box_size_across(sim)
    return sim.wall_stresses(), rate


EQUILIBRIUM_WINDOW = 200
"""Steps over which a compaction's wall stresses and strain rates are averaged to judge
equilibrium (:func:`isotropic_compaction`)."""
STRESS_TOLERANCE = 0.01
"""Largest relative departure of a stress-driven wall's mean stress from sigma0 at equilibrium."""
STRAIN_RATE_TOLERANCE = 1e-3
"""Largest mean strain rate (s-1) of a stress-driven wall at equilibrium."""


def is_equilibrium(stresses, rates, sigma0, stress_tolerance=STRESS_TOLERANCE,
                   strain_rate_tolerance=STRAIN_RATE_TOLERANCE):
    """Equilibrium over a window of steps: on every stress-driven wall, the mean stress is
    within ``stress_tolerance`` (relative) of sigma0 and the mean strain rate below
    ``strain_rate_tolerance`` s-1. ``stresses`` and ``rates`` are (steps, driven walls).

    Means over a window, because a rigid wall on a rigid packing chatters from step to step
    while its momentum balance holds on average. The particles' kinetic energy is not used:
    in zero gravity a rattler keeps its velocity inside its cage forever.
    """
    stresses, rates = np.asarray(stresses), np.asarray(rates)
    ok_stress = np.all(np.abs(stresses.mean(0) / sigma0 - 1) <= stress_tolerance)
    return bool(ok_stress and np.all(np.abs(rates.mean(0)) <= strain_rate_tolerance))


def inertia_number_speed(inertia_number, size, mean_diameter, density, sigma0):
    """Wall speed (m s-1) at which a wall closing a box of extent ``size`` (m) strains the
    sample at the inertia number ``inertia_number``: I = eps_dot d sqrt(rho/sigma0) (GDR MiDi
    2004) with eps_dot = v/size, d the mean particle diameter (m), rho the grains' density
    (kg m-3) and sigma0 the confining stress (Pa); so v = I size / (d sqrt(rho/sigma0))."""
    return inertia_number * size / (mean_diameter * np.sqrt(density / sigma0))


def isotropic_compaction(sim: Simulation, *, max_steps=Preparation.max_steps, window=EQUILIBRIUM_WINDOW,
                         stress_tolerance=STRESS_TOLERANCE, strain_rate_tolerance=STRAIN_RATE_TOLERANCE,
                         max_inertia_number=Preparation.max_inertia_number,
                         pressure_ramp=Preparation.pressure_ramp, progress=None, checkpoint=None, resume=None):
    """Step ``sim`` until the last ``window`` steps are at equilibrium (:func:`is_equilibrium`)
    or for ``max_steps``. Returns the number of steps taken and records in ``sim.history``
    (:class:`solver.sample_history.SampleHistory`) ``settled`` (False when ``max_steps`` ran
    out first), ``compaction_stress`` (the window's mean wall stresses, Pa) and
    ``compaction_inertia_number`` (the largest inertia number of a pushed wall over the
    compaction). The wall speed cap is lifted once settled, so that a
    following test drives the walls by their stress alone.

    Quasi-static compaction: with ``max_inertia_number`` the inward speed of each pushed wall
    is capped, step by step, at the speed that strains the sample at that inertia number,
    I = (v / L) d sqrt(rho / sigma0) (:func:`inertia_number_speed`; L the box extent across
    the wall, d the mean diameter), on top of the walls' own ``max_speed``. With
    ``pressure_ramp`` (s) the stress on the pushed walls rises linearly from 0 to its target
    over that time; equilibrium is only looked for once the ramp is over.

    Checkpoints: ``checkpoint`` (a :class:`solver.compaction_checkpoint.CompactionCheckpoint`)
    writes the compaction's state when it is due and when Ctrl-C or SIGTERM stops the loop;
    ``resume`` (the :class:`solver.compaction_progress.CompactionProgress` that
    :meth:`~solver.compaction_checkpoint.CompactionCheckpoint.load` returns with ``sim``) goes on
    from it, so that the steps taken are those of an uninterrupted compaction, bit for bit, and
    the number returned counts the steps before the checkpoint too.
    """
    from .compaction_progress import CompactionProgress

    check_values(Preparation, max_inertia_number=max_inertia_number, pressure_ramp=pressure_ramp)
    sigma0 = sim.history.sigma0
    h = sim.parameters.time_step
    driven = np.flatnonzero(sim.walls.mode == STRESS)
    state = CompactionProgress.start(sim.walls, driven, window) if resume is None else resume
    mean_diameter = 2.0 * float(sim.radius.mean())
    scale = mean_diameter * np.sqrt(sim.parameters.density / sigma0)
    ramp_steps = int(np.ceil(pressure_ramp / h))
    stresses, rates = state.stresses, state.rates
    sim.history.settled = False
    with interruptible() as flag, progress_bar(max_steps, "isotropic compaction", progress) as bar:
        bar.update(state.steps)
        for k in range(state.steps, max_steps):
            if k < ramp_steps:
                sim.walls.stress[driven] = state.target * (k + 1) / ramp_steps
            if max_inertia_number is not None:
                size = _box_size_across(sim)[driven]
                sim.walls.max_speed[driven] = np.minimum(
                    state.own_cap, inertia_number_speed(max_inertia_number, size, mean_diameter,
                                                        sim.parameters.density, sigma0))
            sim.step()
            bar.update(1)
            stress, rate = wall_state(sim)
            state.largest_inertia = max(state.largest_inertia,
                                        float(np.max(np.abs(rate[driven]), initial=0.0)) * scale)
            stresses.append(stress[driven])
            rates.append(rate[driven])
            state.steps = k + 1
            if k >= ramp_steps and len(stresses) == window and k % 10 == 0 and is_equilibrium(
                    stresses, rates, sigma0, stress_tolerance, strain_rate_tolerance):
                sim.history.settled = True
                break
            if flag["stop"]:
                if checkpoint is not None:
                    checkpoint.write(sim, state)
                    print(f"{stop_reason(flag)} after compaction step {state.steps}: {checkpoint.path} holds the "
                          "compaction so far; the same command resumes it", file=sys.stderr)
                raise stop_exception(flag)
            if checkpoint is not None and state.steps < max_steps and checkpoint.due(state.steps):
                checkpoint.write(sim, state)
    sim.walls.stress[driven] = state.target
    sim.history.compaction_stress = np.mean(stresses, axis=0) if stresses else np.zeros(len(driven))
    sim.history.compaction_inertia_number = state.largest_inertia
    sim.walls.max_speed[:] = np.inf
    return state.steps


def _box_size_across(sim):
    """Extent (m) of the box across each wall: the height for bottom/top, the width for sides."""
    lo, hi = sim.walls.box_bounds()
    return np.where(sim.walls.length_axis == 0, hi[1] - lo[1], hi[0] - lo[0])


def biaxial_test(sim: Simulation, path, *, strain=BiaxialTest.strain, velocity=BiaxialTest.velocity,
                 every=BiaxialTest.every, wall_mass=BiaxialTest.wall_mass, overwrite=False, attrs=None, progress=None,
                 near_contacts=False, compress=True):
    """Biaxial compression of a compacted sample, written to ``path`` every ``every`` steps.

    The top wall moves down at ``velocity`` (m s-1) until eps_1 = ln(1 + dh/h0) reaches
    ``strain`` (defaults and checks: :class:`solver.parameters.BiaxialTest`); the right wall
    keeps the confining stress sigma0; bottom and left are fixed. ``wall_mass``: the right
    wall's mass in units of the sample's (attribute ``right_wall_mass_ratio``); None keeps the
    mass the compaction gave it. The wall's mass sets how far it overshoots when the sample
    fails and pushes it out, and so how far the lateral stress falls below sigma0
    (docs/fidelity.md, "Without walls").
    The snapshot at the start of the test is written first. Ctrl-C stops after the current
    step, with every written snapshot kept. ``near_contacts``: also write the pairs within the
    alert distance that carry no force (:class:`solver.output.Recorder`). The file records the
    test's settings and how the sample was prepared (``sim.history``, written by
    :func:`solver.preparation.prepare_sample` and read back by :func:`solver.load_sample`); ``attrs`` adds
    to them. The file is netCDF-3 while the test runs and is compressed once it has finished
    (``compress``: True, a zlib level 1-9, or False; :class:`solver.output.Recorder`).
    """
    BiaxialTest(strain, velocity, every, wall_mass).validate()
    check_time_step(sim.parameters.time_step, velocity, float(sim.radius.min()), "the top wall")
    lo, hi = sim.walls.box_bounds()
    h0 = float(hi[1] - lo[1])
    travel = h0 * (portable_math.exp(strain) - 1)
    steps = travel / velocity / sim.parameters.time_step
    if not np.isfinite(steps) or sim.step_index + steps > MAX_STEP_INDEX:
        raise ParameterError(
            f"the test would take {steps:.3g} steps of {sim.parameters.time_step:g} s to move the top wall "
            f"{travel:.3g} m at {velocity:g} m/s (the sample is {h0:.3g} m high), beyond a file's step counter "
            f"({MAX_STEP_INDEX} with the {sim.step_index} steps taken so far): expected a sample of sensible "
            "height (did the compaction settle?) or a faster wall; nothing was written")
    n_steps = int(np.ceil(steps))
    sim.walls.drive_velocity("top", (0.0, -velocity))
    if wall_mass is not None:
        sim.walls.mass[sim.walls.index("right")] = float(wall_mass) * float(sim.mass.sum())
    run_attrs = {"scene": "biaxial", "strain_target": strain, "wall_velocity_m_s": velocity,
                 "right_wall_mass_ratio": "none" if wall_mass is None else float(wall_mass),
                 "sigma0_Pa": sim.history.sigma0, "snapshot_every": int(every), "biaxial_steps": n_steps,
                 **sim.history.attrs()}
    run_attrs.update(attrs or {})
    with Recorder(path, sim, attrs=run_attrs, overwrite=overwrite, near_contacts=near_contacts,
                  compress=compress) as rec:
        rec.write()
        biaxial_steps(sim, rec, first=1, n_steps=n_steps, every=int(every), progress=progress)
    return n_steps


def biaxial_steps(sim: Simulation, recorder, *, first, n_steps, every, progress=None):
    """Steps ``first`` .. ``n_steps`` (counted from the start of the test) of a biaxial test,
    with a snapshot every ``every`` steps and at the last one; shared by :func:`biaxial_test`
    and :func:`solver.restart.resume`. Ctrl-C or SIGTERM stops after the current step (its
    snapshot written if one is due) and prints how to resume; then raises KeyboardInterrupt
    (:class:`solver.interrupt.Terminated` for SIGTERM)."""
    with interruptible() as flag, progress_bar(n_steps, "biaxial test", progress) as bar:
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
