"""How steadily a periodic cell's height holds sigma_yy = sigma0 in simple shear, and at what cost.

One compacted sample (the fidelity study's: preparation 'paper', seed 0, cached in
``benchmarks/_data/fidelity/samples``) is put into the biperiodic cell of its box and sheared to
gamma = ``--strain`` at the pace of the biaxial test at the fidelity study's wall speed for its
size (``solver.periodic_shear.matching_shear_rate``), once per variant: the cell's mass (a
multiple of the sample's; ``solver.periodic_shear.CELL_MASS`` is the default) and the stepper
solver that sweeps the cell's rate with the contacts (``solver.cell_coupling``). Over the
snapshots with gamma >= strain / 4 (the start's transient left out) the table gives sigma_yy /
sigma0 (mean, 10th and 90th percentiles, the share of snapshots below one half), p / sigma0
(median: above 1 by the normal-stress difference of simple shear), z, q/p, the sweeps per step
(mean) and the processor time per particle-step.

    python -m benchmarks.periodic_control                   # 1000 pentagons, gamma 0.03
    python -m benchmarks.periodic_control --quick           # 60 pentagons, printed only
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
import warnings

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, "results", "periodic-control.md")
VARIANTS = ("anderson:1", "anderson:0.1", "anderson:0.01", "nlgs:0.1")
"""solver:mass (the cell's mass in units of the sample's) of each run."""


def run_variant(sample_path, variant, strain, velocity, folder):
    """One shear of the sample at ``variant``; returns its row's numbers."""
    from dataclasses import replace

    import grainview
    import solver
    from grainview.analysis.strain import shear_strain
    from solver.periodic_shear import matching_shear_rate, periodic_sample, shear_test

    method, mass = variant.split(":")
    sim = solver.load_sample(sample_path)
    rate = matching_shear_rate(sim, velocity)
    cell_sim = periodic_sample(sim, mass=float(mass) * float(sim.mass.sum()))
    cell_sim.parameters = replace(cell_sim.parameters, solver=method).validate()
    path = os.path.join(folder, variant.replace(":", "_") + ".nc")
    start = time.process_time()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        steps = shear_test(cell_sim, path, strain=strain, shear_rate=rate, every=50, overwrite=True, progress=False,
                           compress=False)
    cpu = time.process_time() - start
    sigma0 = cell_sim.cell.stress
    with grainview.open_dataset(path, chunks=None) as ds:
        keep = shear_strain(ds).values >= strain / 4
        res = ds.isel(time=np.flatnonzero(keep))
        syy = res.grain.stress_tensor().values[:, 1, 1] / sigma0
        inv = res.grain.stress_invariants()
        out = {"snapshots": int(keep.sum()), "syy": syy, "p": np.median(inv["p"].values) / sigma0,
               "z": float(res.grain.coordination()["z"].mean()), "q/p": float(inv["q_over_p"].mean())}
    out.update(steps=steps, rate=rate, sweeps=cell_sim.counters["sweeps"] / steps,
               cpu=cpu / steps / cell_sim.n_particles * 1e6)
    return out


def main(argv=None):
    from benchmarks.common import markdown_table, measured, print_or_write
    from benchmarks.fidelity.__main__ import Config
    from benchmarks.fidelity.runs import Run, make_sample

    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--particles", type=int, default=1000)
    parser.add_argument("--shape", default="pentagon")
    parser.add_argument("--strain", type=float, default=0.03, help="gamma at the end (default 0.03)")
    parser.add_argument("--variants", default=",".join(VARIANTS), help="solver:mass, comma-separated")
    parser.add_argument("--quick", action="store_true", help="60 particles to gamma 0.02, printed only")
    parser.add_argument("--out", default=None, help="the results file (default benchmarks/results/"
                        "periodic-control.md; a --quick run prints only, unless given one)")
    args = parser.parse_args(argv)
    if args.quick:
        args.particles, args.strain = 60, 0.02
    velocity = Config().velocity(args.particles)
    sample = make_sample(Run(shape=args.shape, particles=args.particles))

    def run():
        rows = []
        with tempfile.TemporaryDirectory(prefix="periodic_control_") as folder:
            for variant in args.variants.split(","):
                r = run_variant(sample, variant, args.strain, velocity, folder)
                s = r["syy"]
                rows.append([variant.split(":")[0], variant.split(":")[1], r["snapshots"], f"{s.mean():.3f}",
                             f"{np.percentile(s, 10):.2f}-{np.percentile(s, 90):.2f}", f"{np.mean(s < 0.5):.2f}",
                             f"{r['p']:.2f}", f"{r['z']:.2f}", f"{r['q/p']:.3f}", f"{r['sweeps']:.0f}",
                             f"{r['cpu']:.1f}"])
        table = markdown_table(["solver", "cell mass / sample mass", "snapshots", "sigma_yy / sigma0 (mean)",
                                "10-90%", "share < 1/2", "p / sigma0 (median)", "z", "q/p", "sweeps / step",
                                "CPU us / particle-step"], rows)
        return [f"## {args.shape}s, N = {args.particles}, gamma 0 to {args.strain:g}\n\n{table}"]

    parts, how = measured(run, "one process, one domain")
    intro = (f"The fidelity study's compacted sample ({args.shape}s, N = {args.particles}, preparation 'paper', seed 0) "
             f"in the biperiodic cell of its box, sheared to gamma = {args.strain:g} at gamma_dot = 2 v / h (v = "
             f"{velocity * 100:g} cm/s, the fidelity study's wall speed for this size) under sigma0 = 10 kPa, the "
             f"cell's rate swept with the contacts (solver.cell_coupling); snapshots every 50 steps, those with "
             f"gamma >= {args.strain / 4:g} counted. {how}")
    print_or_write(args.out or (None if args.quick else RESULTS),
                   "Periodic cell under a normal stress: steadiness and cost of the height's control", intro, parts,
                   quick=args.quick)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
