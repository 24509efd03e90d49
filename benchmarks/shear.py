"""Shearing a saved sample as the shear benchmarks do, and capturing its contact problems.

The shear benchmarks (solver_bench/scaling.py, step_profile.py, sweep_cost.py and the archived
studies) shear a compacted sample (``benchmarks/compaction.py --save``) the same way, so that
their rows compare: :func:`shear` runs ``solver.biaxial_test`` with Anderson sweeps
extrapolated every 2 sweeps and the stall test over 200 sweeps on one domain, calling back
after every step; :func:`capture` keeps the main contact problem of a range of shear steps with
its warm start, to be solved again offline.
"""

import os
import shutil
import tempfile
import time
import warnings


class Done(Exception):
    """Raised by an ``after_step`` callback of :func:`shear` to end the shear there."""


def shear(sim, after_step, before_step=None, domains=1) -> float:
    """Run ``solver.biaxial_test`` on ``sim`` (top wall at 1 cm/s, no snapshots but the first,
    warnings silenced) with Anderson sweeps every 2 sweeps and the stall test over 200 on
    ``domains`` domains (one by default), calling ``before_step()`` (if given) right before every
    step and ``after_step(info)`` after it (either raises :class:`Done` to stop), through
    :meth:`solver.stepper.Simulation.watch`. Returns the seconds."""
    from dataclasses import replace

    import solver

    sim.parameters = replace(sim.parameters, solver="anderson", anderson_period=2, stall_sweeps=200,
                             domains=domains).validate()
    folder = tempfile.mkdtemp(prefix="shear_")  # a file of its own: runs side by side do not meet
    path = os.path.join(folder, "shear.nc")
    start = time.perf_counter()
    try:
        with warnings.catch_warnings(), sim.watch(after=after_step, before=before_step):
            warnings.simplefilter("ignore")
            solver.biaxial_test(sim, path, strain=0.5, velocity=0.01, every=10**9, overwrite=True, progress=False)
    except Done:
        pass
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    return time.perf_counter() - start


def capture(sim, first: int, last: int) -> list:
    """Shear ``sim`` as :func:`shear` does until shear step ``last`` and return the main contact
    problem of steps ``first``..``last`` (the step's own, taken with
    :meth:`solver.stepper.Simulation.contact_problem` right before it; not the overlap
    recovery's) as dicts: step, problem, warm-start impulses pn, pt, free velocities vx, vy, w,
    the stopping limits as ``options`` (tolerance, max_tolerance, max_iterations, stall), the
    particles' positions, and the sweeps the step took and the local-law residual of its
    solution (its :class:`solver.stepper.StepInfo`)."""
    caught, done = [], [0]

    def take():
        if first <= done[0] <= last:
            posed = sim.contact_problem()
            pn, pt, vx, vy, w = (a.copy() for a in posed.state)
            caught.append(dict(step=done[0], problem=posed.problem, pn=pn, pt=pt, vx=vx, vy=vy, w=w,
                               options=posed.limits._asdict(), position=sim.position[:sim.n_particles].copy()))

    def count(info):
        if first <= done[0] <= last:
            caught[-1]["sweeps"] = info.iterations
            caught[-1]["law"] = info.local_law_residual
        done[0] += 1
        if done[0] > last:
            raise Done

    shear(sim, count, before_step=take)
    return caught
