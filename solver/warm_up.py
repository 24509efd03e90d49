"""The solver's part of ``grainview warmup``'s workload (:mod:`grainview.app.warmup`): tiny runs
that call every kernel of the solver with the argument types a run uses, so that numba compiles
them into its cache before the runs that follow."""

from __future__ import annotations

from pathlib import Path


def _steps(shape, steps=3, **parameters):
    """A tiny compaction sample of ``shape`` stepped ``steps`` times with ``parameters``."""
    from .scenes import compaction_sample

    sim = compaction_sample(24, shape, seed=0, **parameters)
    for _ in range(steps):
        sim.step()
    return sim


def stages(folder) -> list:
    """The solver's workload, as (what it compiles, callable) pairs in the order they run. The
    third writes ``pentagon.nc`` (a short biaxial test of pentagons) in ``folder``, which the
    analysis's stage of the warm-up reads."""
    from .scenes import biaxial_test

    def solver_shape(shape):
        from . import contact_solvers

        def run():  # every solver of the registry the stepper can use, on its domains and in its orders
            for name in contact_solvers.stepper_methods():
                method = contact_solvers.method(name)
                _steps(shape, solver=name)
                if method.domains:
                    _steps(shape, solver=name, domains=2)
                if method.shuffle:
                    _steps(shape, solver=name, shuffle=True)
            _steps(shape, stall_sweeps=2, max_iterations=20)
        return run

    def written():
        from .periodic_shear import periodic_sample, shear_test

        for shape in ("pentagon", "disk"):
            biaxial_test(_steps(shape, steps=1), Path(folder) / f"{shape}.nc", strain=5e-4, every=2,
                         near_contacts=True, progress=False, compress=False)
            for name in ("anderson", "nlgs"):  # grainview run shear: the periodic cell's kernels
                shear_test(periodic_sample(_steps(shape, steps=1, solver=name)), Path(folder) / f"{shape}_shear.nc",
                           strain=2e-3, shear_rate=1.0, every=2, overwrite=True, progress=False, compress=False)

    def matrix():
        import numpy as np

        from .contact_problem import solve_contact_problem

        W = np.array([[2.0, 0.5, 0.0, 0.0], [0.5, 2.0, 0.0, 0.0], [0.0, 0.0, 2.0, 0.0], [0.0, 0.0, 0.0, 2.0]])
        solve_contact_problem(W, np.array([-1.0, 0.2, 0.5, 0.1]), np.array([0.4, 0.4]))

    return [("solver: pentagon steps (plain, Anderson, shuffled, stall test, 2 domains)", solver_shape("pentagon")),
            ("solver: disk steps (plain, Anderson, shuffled, stall test, 2 domains)", solver_shape("disk")),
            ("solver: a written biaxial test, a periodic shear and their residuals", written),
            ("solver: a contact problem given as a matrix", matrix)]
