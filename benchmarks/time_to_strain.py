"""How long the paper's study takes: "time to eps_q = 0.4" from measured step rates and step
counts.

    python benchmarks/time_to_strain.py --measure pentagon,disk   # shear 1000 particles (~30 min)
    python benchmarks/time_to_strain.py --measure pentagon --acceleration anderson   # the same shear,
                                                                  # Anderson-accelerated sweeps
    python benchmarks/time_to_strain.py --measure pentagon --acceleration anderson --domains 2
                                                                  # ... on two domains, one thread each
    python benchmarks/time_to_strain.py                           # the tables from what was measured

Measured, per shape, on 1000 particles in one process on one core: the compaction of the
'paper' preparation (steps, seconds) and a whole biaxial test from that sample to eps_q = 0.4
(top wall 1 cm/s, sigma0 = 10 kPa, dt = 5e-4 s, default tolerance): steps, NLGS sweeps per
step (median, 90th percentile), contact points per particle, the local-law residual of the
steps (median, 90th percentile; solver.residuals) and microseconds per particle per step over
the whole shear. Written to benchmarks/_data/time_to_strain/<shape>.json.

Extrapolated to N = 4000 and 14,400, and to the paper's pair of samples (14,400 pentagons and
10,000 disks side by side on two cores), with the assumptions the table states:

* shear steps to eps_q = 0.4 grow as the sample height, sqrt(N) (the top wall moves at a
  fixed speed; the eps_1 at which eps_q reaches 0.4 is the measured one);
* the time per particle per step stays the measured one (sweeps per step in the quasi-static
  shear do not grow with N: docs/solver.md; ns per point-sweep stays 16-20 up to 14,400);
* compaction steps: measured where a cached dense sample exists (benchmarks/samples.py),
  else grown as sqrt(N) from the measured 1000; compaction time per particle per step as
  measured at 1000.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
import warnings

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
OUT = os.path.join(HERE, "_data", "time_to_strain")
TARGET_EPS_Q = 0.4
MEASURED_N = 1000
SIZES = (1000, 4000, 14_400)
PAPER = {"pentagon": 14_400, "disk": 10_000}
COMPACTION_STEPS = {("pentagon", 4000): 11_671, ("disk", 4000): 961, ("disk", 14_400): 2_001}
"""Compaction steps of the dense samples built by benchmarks/samples.py (paper preparation,
seed 0; docs/benchmarks.md)."""


class TargetReached(Exception):
    """Raised by the timed step once eps_q reaches the target: ends the test there."""


def measure(shape: str, acceleration: str = "off", domains: int = 1) -> dict:
    """Compact 1000 particles of ``shape`` ('paper' preparation) and shear them to eps_q = 0.4,
    timing every step; the shear's NLGS sweeps plain or Anderson-accelerated
    (``acceleration``), serial or on ``domains`` domains (one thread each), the compaction
    always plain and serial (the same sample either way)."""
    import solver
    from solver.preparation import prepare_sample, preparation

    prep = preparation("paper", shape=shape, particles=MEASURED_N)
    start = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sim = prepare_sample(prep, progress=False)
    compaction_seconds = time.perf_counter() - start
    sim.parameters.acceleration = acceleration
    sim.parameters.domains = domains
    residuals = []
    lo, hi = sim.walls.box_bounds()
    h0, l0 = float(hi[1] - lo[1]), float(hi[0] - lo[0])
    sweeps, points, seconds = [], [], []
    step = sim.step

    def timed_step():
        t = time.perf_counter()
        info = step()
        seconds.append(time.perf_counter() - t)
        sweeps.append(info.iterations)
        points.append(info.n_points)
        residuals.append(info.local_law_residual)
        lo, hi = sim.walls.box_bounds()
        eps_q = np.log(h0 / float(hi[1] - lo[1])) - np.log(l0 / float(hi[0] - lo[0]))
        if eps_q >= TARGET_EPS_Q:
            raise TargetReached
        return info

    sim.step = timed_step
    path = os.path.join(OUT, f"{shape}_{acceleration}_{domains}_shear.nc")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            solver.biaxial_test(sim, path, strain=0.5, velocity=0.01, every=10**9, overwrite=True, progress=False)
    except TargetReached:
        pass
    lo, hi = sim.walls.box_bounds()
    eps_1 = float(np.log(h0 / float(hi[1] - lo[1])))
    os.remove(path)
    sweeps, seconds = np.array(sweeps), np.array(seconds)
    return {"shape": shape, "acceleration": acceleration, "domains": domains, "particles": MEASURED_N,
            "compaction_steps": int(sim.compaction_steps),
            "local_law_residual_median": float(np.median(residuals)),
            "local_law_residual_p90": float(np.percentile(residuals, 90)),
            "compaction_seconds": compaction_seconds, "shear_steps": int(len(sweeps)), "eps_1_at_target": eps_1,
            "shear_seconds": float(seconds.sum()), "sweeps_median": float(np.median(sweeps)),
            "sweeps_p90": float(np.percentile(sweeps, 90)), "sweeps_mean": float(sweeps.mean()),
            "points_per_particle": float(np.mean(points) / MEASURED_N),
            "us_per_particle_step": float(1e6 * seconds.sum() / (len(sweeps) * MEASURED_N))}


def variant(m: dict) -> str:
    """How a measurement's shear was solved, in words."""
    domains = m.get("domains", 1)
    return m.get("acceleration", "off") + (f", {domains} domains" if domains > 1 else "")


def table(results: dict) -> str:
    """The extrapolated table for one way of solving (``results``: a measurement per shape)."""
    rows = ["| shape | N | compaction steps | compaction time | shear steps to eps_q = 0.4 | shear time | "
            "total | basis |", "|---|---|---|---|---|---|---|---|"]
    totals = {}
    for shape, m in results.items():
        per_compaction = m["compaction_seconds"] / (m["compaction_steps"] * m["particles"])
        per_shear = m["shear_seconds"] / (m["shear_steps"] * m["particles"])
        for n in sorted(set(SIZES) | {PAPER[shape]}):
            grow = (n / m["particles"]) ** 0.5
            c_steps = m["compaction_steps"] if n == m["particles"] else COMPACTION_STEPS.get(
                (shape, n), int(m["compaction_steps"] * grow))
            s_steps = int(m["shear_steps"] * grow)
            c_time = per_compaction * n * c_steps
            s_time = per_shear * n * s_steps
            totals[(shape, n)] = c_time + s_time
            basis = ("measured" if n == m["particles"] else
                     ("compaction steps measured, " if (shape, n) in COMPACTION_STEPS else "") + "extrapolated")
            rows.append(f"| {shape} | {n:,} | {c_steps:,} | {c_time / 3600:.2f} h | {s_steps:,} | "
                        f"{s_time / 3600:.2f} h | {(c_time + s_time) / 3600:.2f} h | {basis} |")
    lines = ["\n".join(rows)]
    if all((s, PAPER[s]) in totals for s in PAPER):
        if all(m.get("domains", 1) == 1 for m in results.values()):
            both = max(totals[(s, PAPER[s])] for s in PAPER)
            how = "side by side on two cores"
            which = "the longer of the two"
        else:
            both = sum(totals[(s, PAPER[s])] for s in PAPER)
            how = "one after the other, each on both cores"
            which = "the sum of the two"
        lines.append(f"\nThe paper's pair, {PAPER['pentagon']:,} pentagons and {PAPER['disk']:,} disks {how}: "
                     f"**{both / 3600:.1f} h** ({which}; target <= 6 h).")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--measure", default="", help="shapes to measure now, comma-separated")
    parser.add_argument("--acceleration", default="off", choices=("off", "anderson"),
                        help="NLGS sweeps of the measured shear (the table extrapolates the plain ones)")
    parser.add_argument("--domains", type=int, default=1, help="NLGS domains of the measured shear (threads)")
    args = parser.parse_args(argv)
    os.makedirs(OUT, exist_ok=True)
    for shape in filter(None, args.measure.split(",")):
        result = measure(shape, args.acceleration, args.domains)
        suffix = ("" if args.acceleration == "off" else f"_{args.acceleration}") + (
            f"_d{args.domains}" if args.domains > 1 else "")
        with open(os.path.join(OUT, f"{shape}{suffix}.json"), "w") as fh:
            json.dump(result, fh, indent=1)
        print(json.dumps(result), flush=True)
    measured = []
    for name in sorted(os.listdir(OUT)):
        if name.endswith(".json"):
            with open(os.path.join(OUT, name)) as fh:
                measured.append(json.load(fh))
    variants = {}
    for m in measured:
        variants.setdefault(variant(m), {})[m["shape"]] = m
    results = variants.get("off", {})
    if not results:
        print("nothing measured yet: run with --measure pentagon,disk")
        return
    from common import machine_description

    print(machine_description() + "\n")
    print("| shape | N | sweeps | compaction steps, time | shear steps to eps_q = 0.4 (eps_1) | sweeps / step median, "
          "p90 | contact points / particle | local-law residual median, p90 | us / particle / step (shear) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for m in measured:
        law = (f"{m['local_law_residual_median']:.1e}, {m['local_law_residual_p90']:.1e}"
               if "local_law_residual_median" in m else "-")
        print(f"| {m['shape']} | {m['particles']} | {variant(m)} | {m['compaction_steps']:,}, "
              f"{m['compaction_seconds']:.0f} s | {m['shear_steps']:,} ({m['eps_1_at_target']:.3f}) | "
              f"{m['sweeps_median']:.0f}, {m['sweeps_p90']:.0f} | {m['points_per_particle']:.2f} | {law} | "
              f"{m['us_per_particle_step']:.1f} |")
    for name, found in variants.items():
        if set(found) == set(PAPER):
            print(f"\n**Sweeps: {name}** (time per particle and step as measured with them)\n")
            print(table(found))


if __name__ == "__main__":
    main()
