"""Loading a script of benchmarks/ as a module, as the benchmarks themselves import each other
(their folder on sys.path while the script loads)."""

import importlib.util
import os
import sys

import pytest

BENCHMARKS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "benchmarks")


def load_benchmark(name):
    """The module of ``benchmarks/<name>.py``."""
    sys.path.insert(0, BENCHMARKS)
    try:
        spec = importlib.util.spec_from_file_location(f"bench_{name}", os.path.join(BENCHMARKS, f"{name}.py"))
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
    finally:
        sys.path.remove(BENCHMARKS)
    return module


def load_solver_bench(name):
    """The module ``solver_bench.<name>`` of benchmarks/ (the package the sections of
    RESULTS.md live in), imported with benchmarks/ on sys.path as ``benchmarks/run.py`` has it."""
    sys.path.insert(0, BENCHMARKS)
    try:
        return importlib.import_module(f"solver_bench.{name}")
    finally:
        sys.path.remove(BENCHMARKS)


def shear_sweeps(sim, steps):
    """The NLGS sweeps of each of the first ``steps`` steps of ``sim``'s shear as the shear
    benchmarks run it (``sweep_bursts._shear``), with nothing timed or profiled: the reference
    that a measured run of the same steps must repeat."""
    sweep_bursts = load_benchmark("sweep_bursts")
    sweeps = []

    def count(info):
        sweeps.append(info.iterations)
        if len(sweeps) == steps:
            raise sweep_bursts._Done

    sweep_bursts._shear(sim, count)
    return sweeps


@pytest.fixture(scope="session")
def pentagon_sample(tmp_path_factory):
    """The path of a compacted sample of 60 pentagons ('fast' route, Anderson sweeps, seed 0),
    saved once by ``benchmarks/compaction.py`` for every test that shears one; each test loads
    its own copy from the file."""
    path = str(tmp_path_factory.mktemp("samples") / "pentagons.pkl")
    load_benchmark("compaction").compact("pentagon", 60, 0, "fast", acceleration="anderson", save=path)
    return path
