"""The cost of a step of the periodic simple shear against the walled biaxial test, at equal N.

One compacted sample per shape (the ``fast`` preparation, plain NLGS, as
benchmarks/common.py's ``sheared_sample``) is stepped two ways from the same state, with the
solver settings of every shear benchmark (Anderson sweeps every 2 sweeps, the stall test over
200 sweeps, one domain: benchmarks/shear.py):

* walled: ``solver.biaxial_test``, the top wall at 1 cm/s (strain rate v / h0);
* periodic: the same particles in the biperiodic cell of the box
  (``solver.periodic_shear.periodic_sample``), sheared at gamma_dot = 2 v / h0 (the walled
  test's pace in eps_q, ``solver.periodic_shear.matching_shear_rate``) under sigma_yy = sigma0,
  the cell's rate swept with the contacts (``solver.cell_coupling``).

Each run takes ``--warm`` steps (1000: compiling, the start's transient), then ``--steps`` (300) timed ones,
one after the other in this process: for each step its wall and processor time (``time.
perf_counter``, ``time.process_time``) and its sweeps. The table gives medians over the timed
steps of the processor time per particle-step, per particle-sweep, and the sweeps per step, and
the ratio periodic / walled. The machine has 2 cores shared with other jobs: processor time is
the measure; wall time is printed beside it.

    python -m benchmarks.periodic_shear                  # 400 particles, both shapes
    python -m benchmarks.periodic_shear --quick          # 60 particles, a few steps, printed only
"""

from __future__ import annotations

import argparse
import copy
import os
import tempfile
import time
import warnings

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, "results", "periodic-shear.md")


def compacted(shape, particles):
    """A compacted sample (the ``fast`` preparation, plain NLGS, no stall test)."""
    from solver.preparation import prepare_sample, preparation

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return prepare_sample(preparation("fast", shape=shape, particles=particles), progress=False, solver="nlgs",
                              stall_sweeps=0)


def _settings(sim):
    from dataclasses import replace

    sim.parameters = replace(sim.parameters, solver="anderson", anderson_period=2, stall_sweeps=200,
                             domains=1).validate()


class Done(Exception):
    pass


def timed_steps(sim, run, warm, steps):
    """Run ``run(sim, path)`` (a scene) and time steps ``warm`` .. ``warm + steps - 1``; returns
    per-step arrays of wall seconds, processor seconds and sweeps."""
    wall, cpu, sweeps, seen = [], [], [], [0]
    mark = {}

    def before():
        mark["wall"], mark["cpu"], mark["sweeps"] = time.perf_counter(), time.process_time(), sim.counters["sweeps"]

    def after(info):
        seen[0] += 1
        if seen[0] > warm:
            wall.append(time.perf_counter() - mark["wall"])
            cpu.append(time.process_time() - mark["cpu"])
            sweeps.append(sim.counters["sweeps"] - mark["sweeps"])
        if seen[0] >= warm + steps:
            raise Done

    folder = tempfile.mkdtemp(prefix="periodic_bench_")
    try:
        with warnings.catch_warnings(), sim.watch(after=after, before=before):
            warnings.simplefilter("ignore")
            run(sim, os.path.join(folder, "run.nc"))
    except Done:
        pass
    finally:
        import shutil

        shutil.rmtree(folder, ignore_errors=True)
    return np.array(wall), np.array(cpu), np.array(sweeps)


def walled(strain=0.5):
    def run(sim, path):
        import solver

        solver.biaxial_test(sim, path, strain=strain, velocity=0.01, every=10**9, overwrite=True, progress=False,
                            compress=False)
    return run


def periodic(rate):
    def run(sim, path):
        from solver.periodic_shear import shear_test

        shear_test(sim, path, strain=10.0, shear_rate=rate, every=10**9, overwrite=True, progress=False,
                   compress=False)
    return run


WAYS = ("walled", "periodic")
"""The runs of each shape by default (``--ways``): between walls, and in the cell under sigma0
with the default cell mass. Also known: ``periodic:M`` (the cell's mass M times the sample's) and
``fixed`` (the cell's height held at the box's: no unknown of the cell in the sweeps)."""


def measure(shape, particles, warm, steps, ways=WAYS, whole=None):
    """Rows (shape, way, N, medians...) of one shape, one per way (:data:`WAYS`). ``whole``: the
    walled test runs to eps_1 = ``whole`` with every step timed (``warm`` and ``steps`` unused),
    the other ways as many steps as it took."""
    from solver.periodic_shear import matching_shear_rate, periodic_sample

    sample = compacted(shape, particles)
    rate = matching_shear_rate(sample, 0.01)
    rows = {}
    if whole is not None:
        ways = ["walled"] + [way for way in ways if way != "walled"]
        warm, steps = 0, 10**9
    for way in ways:
        if way == "walled":
            sim, run = copy.deepcopy(sample), walled(0.5 if whole is None else whole)
        elif way == "fixed":
            sim, run = periodic_sample(copy.deepcopy(sample), stress=float("nan")), periodic(rate)
        elif way.startswith("periodic"):
            mass = None if way == "periodic" else float(way.split(":")[1]) * float(sample.mass.sum())
            sim, run = periodic_sample(copy.deepcopy(sample), mass=mass), periodic(rate)
        else:
            raise SystemExit(f"--ways: unknown run {way!r}; expected walled, periodic, periodic:M or fixed")
        _settings(sim)
        rows[way] = timed_steps(sim, run, warm, steps)
        if whole is not None and way == "walled":
            steps = len(rows[way][1])
    return rows, rate


def table(shape, particles, rows, rate):
    from benchmarks.common import markdown_table

    out, base, base_mean = [], None, None
    for way, (wall, cpu, sweeps) in rows.items():
        per = np.median(cpu) / particles * 1e6
        per_sweep = np.median(cpu / np.maximum(sweeps, 1)) / particles * 1e6
        base = per if base is None else base
        mean = np.mean(cpu) / particles * 1e6
        base_mean = mean if base_mean is None else base_mean
        out.append([shape, way, particles, len(cpu), f"{per:.2f}", f"{per_sweep:.3f}", f"{np.median(sweeps):.0f}",
                    f"{np.median(wall) / particles * 1e6:.2f}", f"{per / base:.3f}", f"{mean:.2f}",
                    f"{np.mean(sweeps):.0f}", f"{mean / base_mean:.3f}"])
    return markdown_table(["shape", "run", "N", "steps timed", "CPU us / particle-step (median)",
                           "CPU us / particle-sweep (median)", "sweeps / step (median)",
                           "wall us / particle-step (median)", "CPU per step / walled", "CPU us / particle-step (mean)",
                           "sweeps / step (mean)", "CPU (mean) / walled"], out), rate


def main(argv=None):
    from benchmarks.common import measured, print_or_write

    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--particles", type=int, default=400)
    parser.add_argument("--shapes", default="pentagon,disk")
    parser.add_argument("--warm", type=int, default=1000, help="steps before the timed ones (default 1000)")
    parser.add_argument("--steps", type=int, default=300, help="steps timed (default 300)")
    parser.add_argument("--ways", default=",".join(WAYS), help="the runs, comma-separated: walled, periodic, "
                        "periodic:M (the cell's mass M times the sample's), fixed (the cell's height held)")
    parser.add_argument("--whole", type=float, default=None, metavar="EPS_1",
                        help="time whole tests instead: the walled one to eps_1 = EPS_1, the others as many steps")
    parser.add_argument("--quick", action="store_true", help="60 particles, 5 + 20 steps, printed only")
    parser.add_argument("--out", default=None, help="the results file (default benchmarks/results/periodic-shear.md; "
                        "a --quick run prints only, unless given one)")
    args = parser.parse_args(argv)
    if args.quick:
        args.particles, args.warm, args.steps = 60, 5, 20

    def run():
        parts = []
        for shape in args.shapes.split(","):
            rows, rate = measure(shape, args.particles, args.warm, args.steps, args.ways.split(","), args.whole)
            text, rate = table(shape, args.particles, rows, rate)
            parts.append(f"## {shape}s, N = {args.particles} (periodic at gamma_dot = {rate:.4g} s-1, the walled "
                         "test's 2 v / h0)\n\n" + text)
        return parts

    parts, how = measured(run, "one process, one domain, one numba thread")
    intro = (f"One compacted sample per shape (the `fast` preparation), stepped from the same state between walls "
             f"(`biaxial_test`, top wall at 1 cm/s) and in the biperiodic cell of its box (`periodic_shear`, "
             f"gamma_dot = 2 v / h0, sigma_yy held at sigma0 by the cell's height solved with the contacts), Anderson sweeps every 2 sweeps and the "
             f"stall test over 200 sweeps on one domain. " + (
                 f"Whole tests: every step of the walled test to eps_1 = {args.whole:g} is timed, and as many "
                 f"steps of each other run (the same strain at the same pace), the compilation included in the "
                 f"first run's first steps" if args.whole is not None else
                 f"Steps 1-{args.warm} of each run are not timed (compiling, the start's transient: the periodic "
                 f"sample's boundary contacts form and its height settles); the next {args.steps} are") +
             f", each on its own (processor time: the 2 cores are shared). {how}")
    print_or_write(args.out or (None if args.quick else RESULTS),
                   "Periodic shear against the walled test: cost per particle-step", intro, parts, quick=args.quick)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
