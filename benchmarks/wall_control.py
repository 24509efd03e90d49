"""Whether the stress-controlled wall's mass makes the walled biaxial test's stress swing.

The fidelity study's compacted samples (preparation 'paper', each shape and seed asked for,
cached in ``benchmarks/_data/fidelity/samples``) are sheared between walls (``solver.biaxial_test``: the top
wall at the fidelity study's speed for its size, the right wall pushed by sigma0) to eps_1 =
``--strain``, once per mass of the right wall (a multiple of the sample's mass; the compaction
gives it the whole mass, :func:`solver.scenes.isotropic_compaction`). Snapshots every
``--every`` steps. The table gives, over the snapshots with eps_q >= ``--window`` (the residual
window of docs/fidelity.md), the lateral stress sigma_xx against its target sigma0 (mean, 10th and
90th percentiles, the share below one half), p (10th, 50th and 90th percentiles, in kPa), q/p
(mean), and the sweeps per step and processor time per particle-step over the whole test.

    python -m benchmarks.wall_control          # 1000 pentagons and disks, seeds 0 and 1, masses 1 and 0.1
    python -m benchmarks.wall_control --quick  # 60 pentagons, seed 0, to eps_1 0.02, printed only
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
import warnings

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, "results", "wall-control.md")
MASSES = (1.0, 0.1)
"""The right wall's mass in units of the sample's, one run each (1: the compaction's)."""


def run_mass(sample_path, factor, strain, velocity, every, window, folder):
    """One walled test of the sample with the right wall's mass ``factor`` times the sample's;
    returns its row's numbers."""
    import grainview
    import solver
    from grainview.analysis.strain import shear_strain

    sim = solver.load_sample(sample_path)
    sigma0 = float(sim.history.sigma0)
    path = os.path.join(folder, f"mass_{factor:g}.nc")
    start = time.process_time()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        steps = solver.biaxial_test(sim, path, strain=strain, velocity=velocity, every=every, wall_mass=factor,
                                    overwrite=True, progress=False, compress=False)
    cpu = time.process_time() - start
    with grainview.open_dataset(path, chunks=None) as ds:
        keep = np.flatnonzero(shear_strain(ds).values >= window)
        res = ds.isel(time=keep)
        sxx = res.grain.stress_tensor().values[:, 0, 0] / sigma0
        inv = res.grain.stress_invariants()
        p = inv["p"].values / 1e3
        out = {"snapshots": len(keep), "sxx": sxx, "p": p, "q/p": float(inv["q_over_p"].mean())}
    out.update(steps=steps, sweeps=sim.counters["sweeps"] / steps, cpu=cpu / steps / sim.n_particles * 1e6)
    return out


def main(argv=None):
    from benchmarks.common import markdown_table, measured, print_or_write
    from benchmarks.fidelity.__main__ import Config
    from benchmarks.fidelity.runs import Run, make_sample

    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--particles", type=int, default=1000)
    parser.add_argument("--shapes", default="pentagon,disk", help="comma-separated (default pentagon,disk)")
    parser.add_argument("--seeds", default="0,1", help="the samples' seeds, comma-separated (default 0,1)")
    parser.add_argument("--strain", type=float, default=0.2, help="eps_1 at the end (default 0.2)")
    parser.add_argument("--every", type=int, default=100, help="steps between snapshots (default 100)")
    parser.add_argument("--window", type=float, default=0.4, help="eps_q from which snapshots count (default 0.4)")
    parser.add_argument("--masses", default=",".join(f"{m:g}" for m in MASSES),
                        help="the right wall's masses in units of the sample's, comma-separated")
    parser.add_argument("--quick", action="store_true", help="60 particles to eps_1 0.02, printed only")
    parser.add_argument("--out", default=None, help="the results file (default benchmarks/results/wall-control.md; "
                        "a --quick run prints only, unless given one)")
    args = parser.parse_args(argv)
    if args.quick:
        args.particles, args.strain, args.every, args.window = 60, 0.02, 20, 0.0
        args.shapes, args.seeds = "pentagon", "0"
    velocity = Config().velocity(args.particles)

    def run():
        return [shape_part(shape, int(seed)) for shape in args.shapes.split(",") for seed in args.seeds.split(",")]

    def shape_part(shape, seed):
        sample = make_sample(Run(shape=shape, particles=args.particles, seed=seed))
        rows = []
        with tempfile.TemporaryDirectory(prefix="wall_control_") as folder:
            for factor in (float(m) for m in args.masses.split(",")):
                r = run_mass(sample, factor, args.strain, velocity, args.every, args.window, folder)
                s, p = r["sxx"], r["p"]
                rows.append([f"{factor:g}", r["snapshots"], f"{s.mean():.3f}",
                             f"{np.percentile(s, 10):.2f}-{np.percentile(s, 90):.2f}", f"{np.mean(s < 0.5):.2f}",
                             " / ".join(f"{np.percentile(p, q):.1f}" for q in (10, 50, 90)), f"{r['q/p']:.3f}",
                             f"{r['sweeps']:.0f}", f"{r['cpu']:.1f}"])
        table = markdown_table(["right wall's mass / sample mass", "snapshots", "sigma_xx / sigma0 (mean)", "10-90%",
                                "share < 1/2", "p (kPa): 10% / 50% / 90%", "q/p (mean)", "sweeps / step",
                                "CPU us / particle-step"], rows)
        return (f"## {shape}s, N = {args.particles}, seed {seed}, eps_1 0 to {args.strain:g}, window eps_q >= "
                f"{args.window:g}\n\n{table}")

    parts, how = measured(run, "one process, one domain")
    intro = (f"The fidelity study's compacted samples (N = {args.particles}, preparation 'paper') "
             f"sheared between walls at v = {velocity * 100:g} cm/s (the fidelity study's wall speed for this size), "
             f"the right wall pushed by sigma0 = 10 kPa with the mass given, the solver settings the sample was "
             f"compacted with; snapshots every {args.every} steps. {how}")
    print_or_write(args.out or (None if args.quick else RESULTS),
                   "The stress-controlled wall's mass and the walled test's steadiness", intro, parts,
                   quick=args.quick)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
