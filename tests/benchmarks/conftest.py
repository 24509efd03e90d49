"""Benchmarks as modules: ``benchmarks`` is a package (run with ``python -m``), so a test
imports a current benchmark as ``benchmarks.<name>`` and an archived study as
``benchmarks.archive.<name>``."""

import importlib

import netCDF4
import numpy as np
import pytest


def load_benchmark(name):
    """The module ``benchmarks.<name>``: ``load_benchmark("sweep_cost")``, or an archived
    study's, ``load_benchmark("archive.same_sample")``."""
    return importlib.import_module(f"benchmarks.{name}")


def load_solver_bench(name):
    """The module ``benchmarks.solver_bench.<name>`` (the solver's sections of RESULTS.md)."""
    return importlib.import_module(f"benchmarks.solver_bench.{name}")


def shear_sweeps(sim, steps):
    """The NLGS sweeps of each of the first ``steps`` steps of ``sim``'s shear as the shear
    benchmarks run it (``benchmarks.shear.shear``), with nothing timed or profiled: the reference
    that a measured run of the same steps must repeat."""
    shear = load_benchmark("shear")
    sweeps = []

    def count(info):
        sweeps.append(info.iterations)
        if len(sweeps) == steps:
            raise shear.Done

    shear.shear(sim, count)
    return sweeps


@pytest.fixture(scope="session")
def pentagon_sample(tmp_path_factory):
    """The path of a compacted sample of 60 pentagons ('fast' route, Anderson sweeps, seed 0),
    saved once by ``benchmarks/compaction.py`` for every test that shears one; each test loads
    its own copy from the file."""
    path = str(tmp_path_factory.mktemp("samples") / "pentagons.pkl")
    load_benchmark("compaction").compact("pentagon", 60, 0, "fast", acceleration="anderson", save=path)
    return path


def stored_values(path, name):
    """Variable ``name`` of the netCDF file ``path`` as stored, masked slots filled (NaN for
    floats, -1 otherwise), for bit-for-bit comparisons of two files."""
    with netCDF4.Dataset(path) as nc:
        values = nc[name][:]
    return np.ma.filled(values, np.nan) if values.dtype.kind == "f" else np.ma.filled(values, -1)
