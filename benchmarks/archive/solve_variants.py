"""The same contact problems solved by every candidate: plain NLGS and Anderson-accelerated
sweeps (memory m, extrapolated after every sweep or every k-th), serial and on two domains,
with and without the stall test (solver.nlgs: stop when the quadratic norm has fallen less than
5% over W sweeps).

    python -m benchmarks.archive.solve_variants --build --particles 1000   # capture (~8 min, cached)
    python -m benchmarks.archive.solve_variants --build --particles 4000 --shapes pentagon   # (~30 min)
    python -m benchmarks.archive.solve_variants        # solve every cached set, write archive/solve-variants.md

The problems: a sample of each shape and size compacted with the 'fast' preparation, sheared
to eps_1 = 0.03 (top wall 1 cm/s, sigma0 = 10 kPa, dt = 5e-4 s), then the contact problems of
its next 300 steps, each with the warm start and free velocities the solver received
(benchmarks/_data/solve_variants/<shape>_<N>.pkl). Unlike a benchmark that runs each
candidate over its own trajectory, every candidate here starts every problem from the same
state, so the sweep counts are exactly comparable; the local-law residual (solver.residuals)
of each solution says that they reach the same accuracy.

Timing: the candidates are interleaved problem by problem (the VM's speed drifts by up to 2x
over minutes; interleaving gives every candidate the same drift), the solve alone is timed,
and the ratio is to the plain NLGS of the same run. Candidates on two domains use two threads.
"""

from __future__ import annotations

import argparse
import os
import pickle
import time
import warnings

import numpy as np

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))  # benchmarks/
from benchmarks.common import capture_contact_problems, markdown_table, sheared_sample, write_results

OUT = os.path.join(HERE, "_data", "solve_variants")
RESULTS = os.path.join(HERE, "archive", "solve-variants.md")
SHAPES = ("pentagon", "disk")
SIZES = (1000, 4000)
SHEAR = 0.03
STEPS = 300
CANDIDATES = [
    ("NLGS", dict()),
    ("NLGS, stall 200", dict(stall=200)),
    ("NLGS, 2 domains", dict(domains=2)),
    ("Anderson m = 3, every sweep", dict(memory=3, period=1)),
    ("Anderson m = 3, every 2 sweeps", dict(memory=3, period=2)),
    ("Anderson m = 3, every 3 sweeps", dict(memory=3, period=3)),
    ("Anderson m = 3, every 2 sweeps, stall 200", dict(memory=3, period=2, stall=200)),
    ("Anderson m = 3, every 2 sweeps, stall 200, 2 domains", dict(memory=3, period=2, stall=200, domains=2)),
]


def cache_path(shape, particles):
    """Where the problems of ``shape`` at ``particles`` are cached."""
    return os.path.join(OUT, f"{shape}_{particles}.pkl")


def build(shape, particles):
    """Capture the problems of ``shape`` at ``particles`` (module docstring) into the cache."""
    sim = sheared_sample(shape, particles, SHEAR, OUT)
    captured = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for _ in range(STEPS):
            x = sim.position[:sim.n_particles, 0].copy()
            seen = capture_contact_problems(sim, 1)
            captured.append((*seen[0], x))  # the step's own solve first; an overlap recovery may follow
    with open(cache_path(shape, particles), "wb") as f:
        pickle.dump(captured, f)
    print(f"{shape}, {particles}: {len(captured)} problems captured", flush=True)


def solve(candidate, problem, state, options, x):
    """Solve one captured problem by ``candidate`` (in place on ``state``); the NLGSResult."""
    from solver import acceleration, nlgs, parallel_nlgs

    tolerances = dict(tolerance=options["tolerance"], max_tolerance=options["max_tolerance"],
                      max_iterations=options["max_iterations"], stall=candidate.get("stall", 0))
    domains = candidate.get("domains", 1)
    if "memory" in candidate:
        return acceleration.solve_problem_anderson(problem, *state, memory=candidate["memory"], domains=domains,
                                                   x=x, period=candidate["period"], **tolerances)
    if domains > 1:
        return parallel_nlgs.solve_problem_domains(problem, x, *state, domains=domains, **tolerances)
    return nlgs.solve_problem(problem, *state, **tolerances)


def measure(shape, particles, candidates=CANDIDATES):
    """Every candidate on every captured problem of ``shape`` at ``particles``: a table row per
    candidate."""
    from solver import residuals

    with open(cache_path(shape, particles), "rb") as f:
        captured = pickle.load(f)
    for _, candidate in candidates:  # compile outside the timing
        problem, *state, options, x = captured[0]
        solve(candidate, problem, [s.copy() for s in state], options, x)
    found = {name: [] for name, _ in candidates}
    for problem, *state, options, x in captured:
        for name, candidate in candidates:
            work = [s.copy() for s in state]
            start = time.perf_counter()
            result = solve(candidate, problem, work, options, x)
            seconds = time.perf_counter() - start
            law = residuals.local_law_residual(problem, *work)
            found[name].append((result.iterations, seconds, law, problem.a.size, options["max_iterations"]))
    base = sum(r[1] for r in found["NLGS"])
    rows = []
    for name, _ in candidates:
        a = np.array(found[name])
        sweeps, seconds, law, points, cap = a.T
        rows.append([name, f"{np.median(sweeps):.0f}", f"{sweeps.mean():.1f}", f"{np.percentile(sweeps, 90):.0f}",
                     f"{100 * np.mean(sweeps >= cap):.1f}", f"{np.median(law):.3g}", f"{np.percentile(law, 90):.3g}",
                     f"{np.percentile(law, 99):.3g}", f"{law.max():.3g}",
                     f"{1e3 * seconds.mean():.2f}", f"{base / seconds.sum():.2f}",
                     f"{1e9 * seconds.sum() / (sweeps * points).sum():.0f}"])
    points = np.mean([p[0].a.size for p in captured]) / particles
    header = ["candidate", "sweeps median", "mean", "p90", "% at the cap", "local-law residual median", "p90", "p99",
              "max", "solve ms / step", "speed-up over NLGS", "ns / point-sweep"]
    return (f"**{shape}s**, N = {particles}, {len(captured)} consecutive biaxial steps from eps_1 = {SHEAR}, "
            f"{points:.2f} contact points per particle.\n\n" + markdown_table(header, rows))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", action="store_true", help="capture the problems first")
    parser.add_argument("--shapes", default=",".join(SHAPES))
    parser.add_argument("--particles", default=",".join(map(str, SIZES)), help="sample sizes, comma-separated")
    parser.add_argument("--serial", action="store_true", help="leave out the candidates on two domains (for a "
                        "machine whose other core is busy)")
    args = parser.parse_args(argv)
    candidates = [c for c in CANDIDATES if not (args.serial and c[1].get("domains", 1) > 1)]
    sets = [(shape, int(n)) for n in args.particles.split(",") for shape in args.shapes.split(",")]
    if args.build:
        for shape, particles in sets:
            build(shape, particles)
    sections = [measure(shape, particles, candidates) for shape, particles in sets
                if os.path.exists(cache_path(shape, particles))]
    write_results(RESULTS, "The same contact problems, every solver candidate",
                  "Written by `python -m benchmarks.archive.solve_variants` (its docstring gives the method). The speed-up is "
                  "the plain NLGS's total solve time over the candidate's, from one run with the candidates "
                  "interleaved problem by problem; equal local-law residuals mean equal accuracy.", sections)

if __name__ == "__main__":
    main()
