"""Whole biaxial steps, every way of solving, interleaved: the same sheared sample stepped on
by each candidate in turn, a chunk of steps at a time.

    python -m benchmarks.step_variants --build --particles 1000     # the samples (~3 min, cached)
    python -m benchmarks.step_variants --particles 1000 --steps 3000  # write results/step-variants.md

The sample: the shape compacted with the 'fast' preparation and sheared to eps_1 = 0.03 (top
wall 1 cm/s, sigma0 = 10 kPa, dt = 5e-4 s), pickled in benchmarks/_data/step_variants/. Each
candidate starts from a copy of it and follows its own trajectory (its sweeps change its
forces, and so its next steps: the sweep counts of two candidates compare only statistically,
unlike benchmarks/solve_variants.py, which solves the very same problems). What this adds is
the whole step: detection, building the problem, the overlap-recovery pass, integration and the
step's diagnostics, besides the solve.

Timing: the candidates take turns, ``--chunk`` steps each, so the VM's drift (up to 2x over
minutes) falls on all of them alike; a candidate's time is the sum over its chunks. The
speed-up is the plain NLGS's time over the candidate's. Candidates on two domains use two
threads: run on an otherwise idle machine.
"""

from __future__ import annotations

import argparse
import copy
import os
import pickle
import time
import warnings
from dataclasses import replace

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
from benchmarks.common import markdown_table, sheared_sample, write_results

OUT = os.path.join(HERE, "_data", "step_variants")
RESULTS = os.path.join(HERE, "results", "step-variants.md")
SHAPES = ("pentagon", "disk")
SHEAR = 0.03
CANDIDATES = [
    ("NLGS", dict(solver="nlgs", domains=1, stall_sweeps=0)),
    ("NLGS, stall 200", dict(solver="nlgs", domains=1, stall_sweeps=200)),
    ("NLGS, 2 domains", dict(solver="nlgs", domains=2, stall_sweeps=0)),
    ("Anderson m = 3, every sweep", dict(solver="anderson", anderson_period=1, domains=1, stall_sweeps=0)),
    ("Anderson m = 3, every 2 sweeps", dict(solver="anderson", anderson_period=2, domains=1, stall_sweeps=0)),
    ("Anderson m = 3, every 2 sweeps, stall 200", dict(solver="anderson", anderson_period=2, domains=1,
                                                       stall_sweeps=200)),
    ("Anderson m = 3, every 2 sweeps, stall 200, 2 domains", dict(solver="anderson", anderson_period=2,
                                                                  domains=2, stall_sweeps=200)),
]
"""Each candidate's name and the :class:`solver.parameters.Parameters` fields it sets."""


def cache_path(shape, particles):
    """Where the sheared sample of ``shape`` at ``particles`` is cached."""
    return os.path.join(OUT, f"{shape}_{particles}.pkl")


def build(shape, particles):
    """Compact and shear the sample of ``shape`` at ``particles`` (module docstring); cache it."""
    sim = sheared_sample(shape, particles, SHEAR, OUT)
    with open(cache_path(shape, particles), "wb") as f:
        pickle.dump(sim, f)
    print(f"{shape}, {particles}: sheared to eps_1 = {SHEAR}", flush=True)


def measure(shape, particles, steps, chunk, candidates=CANDIDATES):
    """Every candidate, ``steps`` steps each from the cached sample, in turns of ``chunk``
    steps: a table row per candidate."""
    with open(cache_path(shape, particles), "rb") as f:
        start_state = pickle.load(f)
    sims = {}
    for name, settings in candidates:
        sim = copy.deepcopy(start_state)
        sim.parameters = replace(sim.parameters, **settings).validate()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            sim.step()  # compile outside the timing
        sims[name] = sim
    found = {name: {"seconds": 0.0, "sweeps": [], "law": [], "points": []} for name in sims}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for _ in range(0, steps, chunk):
            for name, sim in sims.items():
                rec = found[name]
                begin = time.perf_counter()
                infos = [sim.step() for _ in range(chunk)]
                rec["seconds"] += time.perf_counter() - begin
                rec["sweeps"] += [i.iterations for i in infos]
                rec["law"] += [i.local_law_residual for i in infos]
                rec["points"] += [i.n_points for i in infos]
    base = found["NLGS"]["seconds"]
    rows = []
    for name, rec in found.items():
        sweeps, law = np.array(rec["sweeps"]), np.array(rec["law"])
        n = len(sweeps)
        rows.append([name, f"{np.median(sweeps):.0f}", f"{sweeps.mean():.1f}", f"{np.percentile(sweeps, 90):.0f}",
                     f"{np.median(law):.3g}", f"{1e6 * rec['seconds'] / (n * particles):.1f}",
                     f"{base / rec['seconds']:.2f}"])
    points = np.mean(found["NLGS"]["points"]) / particles
    header = ["candidate", "sweeps median", "mean", "p90", "local-law residual median", "µs / particle / step",
              "speed-up over NLGS"]
    n = len(found["NLGS"]["sweeps"])
    return (f"**{shape}s**, N = {particles}, {n} biaxial steps per candidate from eps_1 = {SHEAR} "
            f"(turns of {chunk} steps), {points:.2f} contact points per particle.\n\n"
            + markdown_table(header, rows))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", action="store_true", help="compact and shear the samples first")
    parser.add_argument("--shapes", default=",".join(SHAPES))
    parser.add_argument("--particles", default="1000", help="sample sizes, comma-separated")
    parser.add_argument("--steps", type=int, default=3000, help="steps per candidate")
    parser.add_argument("--chunk", type=int, default=100, help="steps per turn")
    parser.add_argument("--out", default=RESULTS, help="the results file (default benchmarks/results/step-variants.md)")
    parser.add_argument("--serial", action="store_true", help="leave out the candidates on two domains (for a "
                        "machine whose other core is busy)")
    args = parser.parse_args(argv)
    candidates = [c for c in CANDIDATES if not (args.serial and c[1]["domains"] > 1)]
    if args.steps < 1 or args.chunk < 1:
        parser.error(f"--steps {args.steps}, --chunk {args.chunk}: expected positive whole numbers")
    sets = [(shape, int(n)) for n in args.particles.split(",") for shape in args.shapes.split(",")]
    if args.build:
        for shape, particles in sets:
            build(shape, particles)
    sections = [measure(shape, particles, args.steps, args.chunk, candidates) for shape, particles in sets
                if os.path.exists(cache_path(shape, particles))]
    write_results(args.out, "Whole steps, every way of solving",
                  "Written by `python -m benchmarks.step_variants` (its docstring gives the method). Each candidate "
                  "follows its own trajectory from the same sheared sample; the candidates take turns, so the "
                  "speed-up (the plain NLGS's total time over the candidate's) is from one run under the same drift.",
                  sections)

if __name__ == "__main__":
    main()
