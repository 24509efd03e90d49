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


def shear(sim, after_step, solve=None) -> float:
    """Run ``solver.biaxial_test`` on ``sim`` (top wall at 1 cm/s, no snapshots but the first,
    warnings silenced) with Anderson sweeps every 2 sweeps and the stall test over 200 on one
    domain, calling ``after_step(info)`` after every step (it raises :class:`Done` to stop),
    with ``solve`` (if given) in place of ``solver.acceleration.solve_problem_anderson``; the
    simulation's and the module's own functions are back afterwards. Returns the seconds."""
    import solver
    from solver import acceleration

    p = sim.parameters
    p.acceleration, p.anderson_period, p.stall_sweeps, p.domains = "anderson", 2, 200, 1
    original_solve, step = acceleration.solve_problem_anderson, sim.step

    def stepped():
        info = step()
        after_step(info)
        return info

    sim.step = stepped
    acceleration.solve_problem_anderson = solve or original_solve
    folder = tempfile.mkdtemp(prefix="shear_")  # a file of its own: runs side by side do not meet
    path = os.path.join(folder, "shear.nc")
    start = time.perf_counter()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            solver.biaxial_test(sim, path, strain=0.5, velocity=0.01, every=10**9, overwrite=True, progress=False)
    except Done:
        pass
    finally:
        acceleration.solve_problem_anderson = original_solve
        del sim.step  # the class's method again
        shutil.rmtree(folder, ignore_errors=True)
    return time.perf_counter() - start


def capture(sim, first: int, last: int) -> list:
    """Shear ``sim`` as :func:`shear` does until shear step ``last`` and return the main contact
    problem of steps ``first``..``last`` as dicts: step, problem, warm-start impulses pn, pt,
    free velocities vx, vy, w, the solver options, the particles' positions, and the sweeps the
    step took and the local-law residual of its solution."""
    from solver import acceleration, residuals

    tolerance = sim.parameters.tolerance
    caught, done = [], [0]
    solve = acceleration.solve_problem_anderson

    def capturing(problem, pn, pt, vx, vy, w, **options):
        main = options["tolerance"] == tolerance and first <= done[0] <= last
        if main:
            caught.append(dict(step=done[0], problem=problem, pn=pn.copy(), pt=pt.copy(), vx=vx.copy(),
                               vy=vy.copy(), w=w.copy(), options=dict(options),
                               position=sim.position[:sim.n_particles].copy()))
        result = solve(problem, pn, pt, vx, vy, w, **options)
        if main:
            caught[-1]["sweeps"] = result.iterations
            caught[-1]["law"] = residuals.local_law_residual(problem, pn, pt, vx, vy, w)
        return result

    def count(info):
        done[0] += 1
        if done[0] > last:
            raise Done

    shear(sim, count, capturing)
    return caught
