"""The cross-check's biaxial test in this project's solver, through its public API.

Run by ``python -m benchmarks.crosscheck`` in the project's environment::

    python engine_project.py SAMPLE.nc OUT.nc --strain 0.25 --every 100

``solver.load_sample`` rebuilds the simulation at the sample's last snapshot (walls driven as
recorded: the right wall by the stress sigma0 with the compaction's wall mass; warm start of
the next step); ``solver.biaxial_test`` then moves the top wall down at ``--velocity`` (m/s)
until eps_1 = ``--strain``, keeps sigma0 on the right wall and writes a contract file with a
snapshot every ``--every`` steps (step 0 first). The solver's parameters are those of the
sample (time step 5e-4 s, friction 0.4, frictionless walls, NLGS tolerance 1.7e-4, ...).
Writes ``OUT.json`` next to the file: wall time, steps, NLGS steps that hit the iteration cap.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
import warnings


def main(argv=None):
    parser = argparse.ArgumentParser(prog="engine_project.py", description=__doc__.split("\n\n")[0])
    parser.add_argument("sample", help="compacted sample (grainview run isotropic ... --out SAMPLE.nc)")
    parser.add_argument("out", help="contract file to write (replaced)")
    parser.add_argument("--strain", type=float, default=0.25, help="target eps_1 (default 0.25)")
    parser.add_argument("--every", type=int, default=100, help="steps between snapshots (default 100)")
    parser.add_argument("--velocity", type=float, default=0.01, help="top wall speed, m/s (default 0.01)")
    args = parser.parse_args(argv)

    import solver
    from grainview.contract.errors import ConvergenceWarning

    sim = solver.load_sample(args.sample)
    if not math.isfinite(sim.history.sigma0):  # samples written before isotropic files recorded sigma0_Pa
        sim.history.sigma0 = float(sim.walls.stress[sim.walls.index("right")])
    start = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        n_steps = solver.biaxial_test(sim, args.out, strain=args.strain, velocity=args.velocity, every=args.every,
                                      overwrite=True, progress=False,
                                      attrs={"engine_engine": "project", "engine_version": solver.__version__})
    elapsed = time.perf_counter() - start
    capped = sum(issubclass(w.category, ConvergenceWarning) for w in caught)
    meta = dict(engine="project", version=solver.__version__, n_steps=n_steps, wall_s=elapsed,
                nlgs_capped_steps=capped, tolerance=sim.parameters.tolerance,
                max_iterations=sim.parameters.max_iterations, sweeps=sim.counters["sweeps"],
                python=sys.version.split()[0])
    with open(args.out + ".json", "w") as fh:
        json.dump(meta, fh, indent=1)


if __name__ == "__main__":
    main()
