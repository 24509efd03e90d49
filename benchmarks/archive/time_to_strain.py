"""How long the paper's study takes: "time to eps_q = 0.4" from measured step rates and step
counts.

    python -m benchmarks.archive.time_to_strain --measure pentagon,disk   # shear 1000 particles (~30 min)
    python -m benchmarks.archive.time_to_strain --measure pentagon --acceleration anderson   # the same shear,
                                                                  # Anderson-accelerated sweeps
    python -m benchmarks.archive.time_to_strain --measure pentagon --acceleration anderson --domains 2
                                                                  # ... on two domains, one thread each
    python -m benchmarks.archive.time_to_strain --measure pentagon --acceleration anderson --period 2 \
        --stall 200 --particles 4000 --until 0.1                  # a check of the extrapolation (~1 h)
    python -m benchmarks.archive.time_to_strain                           # the tables from what was measured

Measured, per shape, on 1000 particles in one process on one core: the compaction of the
'paper' preparation (steps, seconds) and a whole biaxial test from that sample to eps_q = 0.4
(top wall 1 cm/s, sigma0 = 10 kPa, dt = 5e-4 s, default tolerance): steps, NLGS sweeps per
step (median, 90th percentile), contact points per particle, the local-law residual of the
steps (median, 90th percentile; solver.residuals) and microseconds per particle per step over
the whole shear. Written to benchmarks/_data/time_to_strain/<shape>.json, and every step's
eps_q, sweeps and seconds to <shape>_steps.npz beside it.

Extrapolated to N = 4000 and 14,400, and to the paper's pair of samples (14,400 pentagons and
10,000 disks side by side on two cores), with the assumptions the table states:

* shear steps to eps_q = 0.4 grow as the sample height, sqrt(N) (the top wall moves at a
  fixed speed; the eps_1 at which eps_q reaches 0.4 is the measured one);
* the time per particle per step stays the measured one (sweeps per step in the quasi-static
  shear do not grow with N: benchmarks/archive/solver-log.md; ns per point-sweep stays 16-20 up to 14,400);
* compaction steps: measured where a compaction of that size was run (here or by
  benchmarks/compaction.py) or a cached dense sample exists (benchmarks/samples.py), else grown
  as sqrt(N) from the measured 1000;
* compaction time per particle per step: it grows with N (the jamming phase's steps need more
  sweeps in a larger packing), so it is taken from the compactions measured at each size, solved
  as the shear is (Anderson or plain sweeps: benchmarks/_data/compaction_solvers.jsonl written by
  benchmarks/compaction.py, and the compactions of this script's cached samples, which are
  plain), and, at a size not measured, a power of N through the two sizes measured nearest to it.

A measurement at another size (``--particles``) is listed beside the extrapolation from 1000
to the same size: the check of these assumptions.
"""

from __future__ import annotations

import argparse
import json
import os
import time
import warnings

import numpy as np

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))  # benchmarks/
from benchmarks.common import load_sample, save_sample, way_of_solving
OUT = os.path.join(HERE, "_data", "time_to_strain")
TARGET_EPS_Q = 0.4
MEASURED_N = 1000
SIZES = (1000, 4000, 14_400)
PAPER = {"pentagon": 14_400, "disk": 10_000}
COMPACTION_STEPS = {("pentagon", 4000): 11_671, ("disk", 4000): 961, ("disk", 14_400): 2_001}
"""Compaction steps of the dense samples built by benchmarks/samples.py (paper preparation,
seed 0; docs/benchmarks.md)."""


COMPACTIONS = os.path.join(HERE, "_data", "compaction_solvers.jsonl")
"""The 'paper' compactions measured by benchmarks/compaction.py, solved plain or with Anderson
sweeps (docs/benchmarks.md)."""


class TargetReached(Exception):
    """Raised by the timed step once eps_q reaches the target: ends the test there."""


def compacted(shape: str, particles: int):
    """The 'paper' sample of ``shape`` at ``particles``, compacted with the plain serial NLGS
    (the same sample whatever the shear's solver), and the compaction's seconds: built once,
    then read from benchmarks/_data/time_to_strain/sample_<shape>_<N>.pkl."""
    from solver.preparation import prepare_sample, preparation

    path = os.path.join(OUT, f"sample_{shape}_{particles}.pkl")
    if os.path.exists(path):
        return load_sample(path)
    start = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sim = prepare_sample(preparation("paper", shape=shape, particles=particles), progress=False,
                             acceleration="off", domains=1, stall_sweeps=0)
    seconds = time.perf_counter() - start
    save_sample(path, sim, seconds)
    return sim, seconds


def measure(shape: str, acceleration: str = "off", domains: int = 1, particles: int = MEASURED_N,
            stall: int = 0, until: float = TARGET_EPS_Q, period: int = 1, sample: str | None = None) -> dict:
    """Compact ``particles`` particles of ``shape`` ('paper' preparation, :func:`compacted`) and
    shear them to eps_q = 0.4, timing every step; the shear's NLGS sweeps plain or
    Anderson-accelerated (``acceleration``, the default memory, an extrapolation every
    ``period`` sweeps), serial or on ``domains`` domains (one thread each), with the stall
    test over ``stall`` sweeps (0: none; solver.nlgs); ``until``: the eps_q at which the shear
    stops (part of a shear, to check the extrapolation at a larger size in less time);
    ``sample``: a pickled compacted simulation and its compaction's seconds to shear instead
    (``benchmarks/compaction.py --save``, e.g. a sample of the 'fast' route)."""
    import solver

    if sample:
        sim, compaction_seconds = load_sample(sample)
        from solver.shapes import n_vertices_of

        if sim.n_particles != particles or np.any(sim.n_vertices != n_vertices_of(shape)):
            raise SystemExit(f"--sample {sample}: holds {sim.n_particles} particles, expected {particles} {shape}s")
    else:
        sim, compaction_seconds = compacted(shape, particles)
    sim.parameters.acceleration = acceleration
    sim.parameters.domains = domains
    sim.parameters.stall_sweeps = stall
    sim.parameters.anderson_period = period
    residuals = []
    lo, hi = sim.walls.box_bounds()
    h0, l0 = float(hi[1] - lo[1]), float(hi[0] - lo[0])
    sweeps, points, seconds, strains = [], [], [], []
    started = [0.0]

    def start_clock():
        started[0] = time.perf_counter()

    def timed_step(info):
        seconds.append(time.perf_counter() - started[0])
        sweeps.append(info.iterations)
        points.append(info.n_points)
        residuals.append(info.local_law_residual)
        lo, hi = sim.walls.box_bounds()
        eps_q = np.log(h0 / float(hi[1] - lo[1])) - np.log(l0 / float(hi[0] - lo[0]))
        strains.append(eps_q)
        if eps_q >= until:
            raise TargetReached

    path = os.path.join(OUT, f"{shape}_{particles}_{acceleration}_{domains}_{stall}_shear.nc")
    try:
        with warnings.catch_warnings(), sim.watch(after=timed_step, before=start_clock):
            warnings.simplefilter("ignore")
            solver.biaxial_test(sim, path, strain=0.5, velocity=0.01, every=10**9, overwrite=True, progress=False)
    except TargetReached:
        pass
    lo, hi = sim.walls.box_bounds()
    eps_1 = float(np.log(h0 / float(hi[1] - lo[1])))
    os.remove(path)
    sweeps, seconds = np.array(sweeps), np.array(seconds)
    return {"shape": shape, "acceleration": acceleration, "domains": domains, "particles": particles,
            "anderson_memory": sim.parameters.anderson_memory, "anderson_period": sim.parameters.anderson_period,
            "stall_sweeps": stall, "eps_q_target": until, "sample": os.path.basename(sample) if sample else "paper",
            "compaction_steps": int(sim.compaction_steps),
            "local_law_residual_median": float(np.median(residuals)),
            "local_law_residual_p90": float(np.percentile(residuals, 90)),
            "compaction_seconds": compaction_seconds, "shear_steps": int(len(sweeps)), "eps_1_at_target": eps_1,
            "shear_seconds": float(seconds.sum()), "sweeps_median": float(np.median(sweeps)),
            "sweeps_p90": float(np.percentile(sweeps, 90)), "sweeps_mean": float(sweeps.mean()),
            "points_per_particle": float(np.mean(points) / particles),
            "us_per_particle_step": float(1e6 * seconds.sum() / (len(sweeps) * particles)),
            "per_step": {"eps_q": np.array(strains), "sweeps": sweeps, "seconds": seconds}}


def compaction_rates(shape: str, acceleration: str, measured: list) -> dict:
    """Measured 'paper' compactions of ``shape`` solved with ``acceleration``: {N: (mean steps,
    mean seconds per particle per step)}, from benchmarks/compaction.py's rows (their CPU time,
    where recorded: the machine is shared) and, for plain sweeps, the compactions of this
    script's cached 'paper' samples (``measured``; a sample given with ``--sample`` was compacted
    another way)."""
    runs = {}
    if os.path.exists(COMPACTIONS):
        for line in open(COMPACTIONS):
            r = json.loads(line) if line.strip() else None
            if r and r["shape"] == shape and r["route"] == "paper" and r.get("acceleration", "off") == acceleration \
                    and not r.get("stall_sweeps", 0):
                runs.setdefault(r["particles"], []).append((r["steps"], r.get("cpu_seconds", r["seconds"])))
    if acceleration == "off":
        cached = {(m["particles"], m["compaction_steps"], m["compaction_seconds"]) for m in measured
                  if m["shape"] == shape and m.get("sample", "paper") == "paper"}
        for n, steps, seconds in cached:
            runs.setdefault(n, []).append((steps, seconds))
    return {n: (float(np.mean([s for s, _ in r])), float(np.mean([t / (s * n) for s, t in r])))
            for n, r in runs.items()}


def compaction_at(n: int, rates: dict):
    """Steps (None: not measured) and seconds per particle per step of a compaction of ``n``
    particles from ``rates`` (:func:`compaction_rates`): measured at ``n``, else a power of N
    through the two nearest sizes measured (the one size there is, when only one is)."""
    if n in rates:
        return rates[n]
    sizes = sorted(rates, key=lambda k: (abs(np.log(k / n)), k))[:2]
    if len(sizes) == 1:
        return None, rates[sizes[0]][1]
    (n1, (_, r1)), (n2, (_, r2)) = sorted((k, rates[k]) for k in sizes)
    power = np.log(r2 / r1) / np.log(n2 / n1)
    return None, r1 * (n / n1) ** power


def table(results: dict, measured: list) -> str:
    """The extrapolated table for one way of solving (``results``: a measurement per shape;
    ``measured``: every measurement, for the compactions of other sizes)."""
    rows = ["| shape | N | compaction steps | compaction time | shear steps to eps_q = 0.4 | shear time | "
            "total | basis |", "|---|---|---|---|---|---|---|---|"]
    totals = {}
    for shape, m in results.items():
        rates = compaction_rates(shape, m.get("acceleration", "off"), measured)
        # no compaction measured with these sweeps at this size: the cached sample's (plain)
        rates.setdefault(m["particles"], (m["compaction_steps"],
                                          m["compaction_seconds"] / (m["compaction_steps"] * m["particles"])))
        per_shear = m["shear_seconds"] / (m["shear_steps"] * m["particles"])
        for n in sorted(set(SIZES) | {PAPER[shape]}):
            grow = (n / m["particles"]) ** 0.5
            steps, per_compaction = compaction_at(n, rates)
            c_steps = int(steps) if steps is not None else COMPACTION_STEPS.get((shape, n),
                                                                               int(m["compaction_steps"] * grow))
            s_steps = int(m["shear_steps"] * grow)
            c_time = per_compaction * n * c_steps
            s_time = per_shear * n * s_steps
            totals[(shape, n)] = c_time + s_time
            basis = ("shear measured" if n == m["particles"] else "shear extrapolated") + (
                "; compaction measured" if n in rates else
                "; compaction steps measured, time per step extrapolated" if (shape, n) in COMPACTION_STEPS else
                "; compaction extrapolated")
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
    parser.add_argument("--particles", type=int, default=MEASURED_N,
                        help="sample size of the measurement (the tables extrapolate from 1000)")
    parser.add_argument("--stall", type=int, default=0, help="sweeps of the NLGS stall test of the shear (0: none)")
    parser.add_argument("--period", type=int, default=1, help="NLGS sweeps between Anderson extrapolations")
    parser.add_argument("--sample", default="",
                        help="a pickled compacted sample to shear (benchmarks/compaction.py --save); default: the "
                             "cached 'paper' sample, compacted first if missing")
    parser.add_argument("--until", type=float, default=TARGET_EPS_Q,
                        help="eps_q at which the measured shear stops (the tables extrapolate whole shears to 0.4)")
    args = parser.parse_args(argv)
    os.makedirs(OUT, exist_ok=True)
    for shape in filter(None, args.measure.split(",")):
        result = measure(shape, args.acceleration, args.domains, args.particles, args.stall, args.until, args.period,
                         args.sample or None)
        suffix = ("" if args.acceleration == "off" else f"_{args.acceleration}_p{result['anderson_period']}") + (
            f"_stall{args.stall}" if args.stall else "") + (f"_d{args.domains}" if args.domains > 1 else "") + (
            f"_n{args.particles}" if args.particles != MEASURED_N else "") + (
            f"_to{args.until:g}" if args.until != TARGET_EPS_Q else "") + (
            "_" + os.path.splitext(result["sample"])[0] if args.sample else "")
        np.savez(os.path.join(OUT, f"{shape}{suffix}_steps.npz"), **result.pop("per_step"))
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
        if m["particles"] == MEASURED_N and m.get("eps_q_target", TARGET_EPS_Q) == TARGET_EPS_Q:
            variants.setdefault(way_of_solving(m), {})[m["shape"]] = m
    results = variants.get("off", {})
    if not results:
        print("nothing measured yet: run with --measure pentagon,disk")
        return
    from benchmarks.common import machine_description

    print(machine_description() + "\n")
    print("| shape | N | sample | sweeps | compaction steps, time | shear steps to eps_q = 0.4 (eps_1) | sweeps / step median, "
          "p90 | contact points / particle | local-law residual median, p90 | us / particle / step (shear) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for m in measured:
        law = (f"{m['local_law_residual_median']:.1e}, {m['local_law_residual_p90']:.1e}"
               if "local_law_residual_median" in m else "-")
        print(f"| {m['shape']} | {m['particles']} | {m.get('sample', 'paper')} | {way_of_solving(m)} | "
              f"{m['compaction_steps']:,}, "
              f"{m['compaction_seconds']:.0f} s | {m['shear_steps']:,} ({m['eps_1_at_target']:.3f}) | "
              f"{m['sweeps_median']:.0f}, {m['sweeps_p90']:.0f} | {m['points_per_particle']:.2f} | {law} | "
              f"{m['us_per_particle_step']:.1f} |")
    for name, found in variants.items():
        if set(found) == set(PAPER):
            print(f"\n**Sweeps: {name}** (time per particle and step as measured with them)\n")
            print(table(found, measured))
    def same(m, base):
        return (base["particles"] == MEASURED_N and base["shape"] == m["shape"] and way_of_solving(base) == way_of_solving(m)
                and base.get("eps_q_target", TARGET_EPS_Q) == m.get("eps_q_target", TARGET_EPS_Q))

    checks = [(m, base) for m in measured if m["particles"] != MEASURED_N for base in measured if same(m, base)]
    if checks:
        print("\n**The extrapolation checked**: a shear measured at another size, against the "
              f"extrapolation from {MEASURED_N:,} particles solved the same way to the same eps_q\n")
        print("| shape | N | sweeps | to eps_q | shear steps: measured, extrapolated | sweeps / step median, mean: "
              f"measured, at {MEASURED_N:,} | us / particle / step: measured, at {MEASURED_N:,} | shear time: "
              "measured, extrapolated |")
        print("|---|---|---|---|---|---|---|---|")
        for m, base in checks:
            steps = int(base["shear_steps"] * (m["particles"] / base["particles"]) ** 0.5)
            guess = base["shear_seconds"] / (base["shear_steps"] * base["particles"]) * m["particles"] * steps
            print(f"| {m['shape']} | {m['particles']:,} | {way_of_solving(m)} | {m.get('eps_q_target', TARGET_EPS_Q):g} | "
                  f"{m['shear_steps']:,}, {steps:,} | {m['sweeps_median']:.0f}, {m['sweeps_mean']:.0f}; "
                  f"{base['sweeps_median']:.0f}, {base['sweeps_mean']:.0f} | {m['us_per_particle_step']:.1f}, "
                  f"{base['us_per_particle_step']:.1f} | {m['shear_seconds'] / 3600:.2f} h, {guess / 3600:.2f} h |")

if __name__ == "__main__":
    main()
