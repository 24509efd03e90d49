"""Compile every numba kernel of the solver and the analysis into numba's on-disk cache.

The kernels are compiled with ``cache=True``: the first process that calls one compiles it
(about half a minute for the whole solver on one core) and writes the machine code to the
cache folder, and every later process loads it in a fraction of a second. A run started on a
cold cache spends its first step compiling, and a signal such as SIGTERM, which the solver
acts on between whole steps, waits for that step. :func:`warm_up` runs a tiny workload that
calls every kernel with the argument types a run uses (pentagons and disks; plain and
Anderson sweeps; one and two domains; the stall test; the written snapshots and their
residuals; the analyses' kernels), so that the runs that follow start at once.

The cache lives where numba puts it: ``NUMBA_CACHE_DIR`` when it is set, otherwise a
``__pycache__`` folder beside each module (or a user cache folder when that one is not
writable). :func:`cache_location` says which.
"""

from __future__ import annotations

import importlib
import os
import pkgutil
import tempfile
import warnings
from pathlib import Path

__all__ = ["warm_up", "kernels", "cache_location"]

PACKAGES = ("solver", "grainview.analysis._kernels")
"""The packages whose modules hold numba kernels."""


def cache_location() -> str:
    """Where numba writes and reads its compiled kernels: ``NUMBA_CACHE_DIR`` (made absolute)
    when it is set, else the ``__pycache__`` folders beside the modules."""
    from numba.core.config import CACHE_DIR

    if CACHE_DIR:
        return f"{os.path.abspath(CACHE_DIR)} (NUMBA_CACHE_DIR)"
    import solver

    return (f"__pycache__ folders beside the modules, e.g. {Path(solver.__file__).parent / '__pycache__'} "
            "(NUMBA_CACHE_DIR unset; set it to choose a folder)")


def kernels() -> dict:
    """Every numba kernel of :data:`PACKAGES`: {"module.name": dispatcher}, in module order.
    Kernels marked ``inline="always"`` are compiled into their callers and not listed."""
    from numba.core.registry import CPUDispatcher

    found = {}
    for package in PACKAGES:
        root = importlib.import_module(package)
        for info in pkgutil.iter_modules(root.__path__):
            module = importlib.import_module(f"{package}.{info.name}")
            for name, value in vars(module).items():
                if (isinstance(value, CPUDispatcher) and value.__module__ == module.__name__
                        and value.targetoptions.get("inline", "never") != "always"):
                    found[f"{module.__name__}.{name}"] = value
    return found


def _steps(shape, steps=3, **parameters):
    """A tiny compaction sample of ``shape`` stepped ``steps`` times with ``parameters``."""
    from solver import compaction_sample

    sim = compaction_sample(24, shape, seed=0, **parameters)
    for _ in range(steps):
        sim.step()
    return sim


def _stages(folder):
    """The workload, as (what it compiles, callable) pairs in the order they run."""
    from solver import biaxial_test

    def solver_shape(shape):
        from solver import contact_solvers

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
        for shape in ("pentagon", "disk"):
            biaxial_test(_steps(shape, steps=1), Path(folder) / f"{shape}.nc", strain=5e-4, every=2,
                         near_contacts=True, progress=False, compress=False)

    def matrix():
        import numpy as np

        from solver.contact_problem import solve_contact_problem

        W = np.array([[2.0, 0.5, 0.0, 0.0], [0.5, 2.0, 0.0, 0.0], [0.0, 0.0, 2.0, 0.0], [0.0, 0.0, 0.0, 2.0]])
        solve_contact_problem(W, np.array([-1.0, 0.2, 0.5, 0.1]), np.array([0.4, 0.4]))

    def analysis():
        from ..contract.io import open_dataset

        with open_dataset(Path(folder) / "pentagon.nc") as ds:
            ds.grain.xi_network().compute()
            ds.grain.coarse_grained(width=0.05, spacing=0.05).compute()
            ds.grain.network_persistence().compute()
            ds.grain.force_chains(follow=True)

    return [("solver: pentagon steps (plain, Anderson, shuffled, stall test, 2 domains)", solver_shape("pentagon")),
            ("solver: disk steps (plain, Anderson, shuffled, stall test, 2 domains)", solver_shape("disk")),
            ("solver: a written biaxial test and its residuals", written),
            ("solver: a contact problem given as a matrix", matrix),
            ("analysis: the xi-network, the coarse-grained fields, the network's topology, the force chains",
             analysis)]


def warm_up(log=print) -> dict:
    """Compile (or load from the cache) every numba kernel the solver and the analysis use.

    Runs :func:`_stages`' tiny workload in a temporary folder, calling ``log`` with a line per
    stage, then checks that each kernel of :func:`kernels` has a compiled version.

    Parameters
    ----------
    log : callable, default print
        Called with one line per stage (progress).

    Returns
    -------
    dict
        ``{"kernels": number of kernels, "compiled": kernels with a compiled version,
        "missing": [names of the others], "cache": cache_location()}``.
    """
    from ..contract.errors import ConvergenceWarning

    with tempfile.TemporaryDirectory(prefix="grainview-warmup-") as folder, warnings.catch_warnings():
        warnings.simplefilter("ignore", ConvergenceWarning)
        warnings.simplefilter("ignore", RuntimeWarning)  # 2 domains on a machine told to let threads sleep
        stages = _stages(folder)
        for k, (what, run) in enumerate(stages, 1):
            log(f"[{k}/{len(stages)}] {what}")
            run()
    found = kernels()
    missing = [name for name, dispatcher in found.items() if not dispatcher.signatures]
    return {"kernels": len(found), "compiled": len(found) - len(missing), "missing": missing,
            "cache": cache_location()}
