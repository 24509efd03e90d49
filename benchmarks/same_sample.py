"""Does a way of solving change the study's physics?  The evidence for a solver default.

    python benchmarks/same_sample.py --seeds 0,1,2            # shears (~25 min per seed, 2 cores)
    python benchmarks/same_sample.py --compaction --seeds 0,1,2,3,4 --shapes disk
    python benchmarks/same_sample.py --table                  # RESULTS-same-sample.md's tables

Shears. Per seed and shape (400 particles, the 'paper' preparation, the study's defaults:
eps_1 = 0.2 at 1 cm/s, a snapshot every 200 steps, near contacts written), the deposit is
compacted twice, with plain NLGS sweeps (sample A) and with Anderson-accelerated sweeps (B). A
is sheared with plain sweeps (A-off) and with Anderson sweeps (A-and): the same sample, so the
difference is the solver's alone (and the chaotic divergence of two trajectories that any
change of round-off starts). B is sheared with Anderson sweeps (B-and): the whole study as it
runs with Anderson sweeps. The headline's residual-state numbers (eps_q >= 0.3;
grainview.report.run_summary) of each go to benchmarks/_data/same_sample/<shape>_<seed>.json;
the table gives, per quantity, the seeds' mean and standard deviation of A-off and of B-and, and
the mean and standard deviation over seeds of the differences A-and - A-off and B-and - A-off.

Compaction (``--compaction``). The state a compaction reaches depends on how well its steps are
solved (docs/solver.md, "Compaction"): per seed, the deposit is compacted with plain and with
Anderson sweeps at the default tolerance and at a 10x tighter one (sweep cap 10x higher), and
the compacted state's coordination z (force-bearing contacts, rattlers out;
``ds.grain.coordination``) and solid fraction are written to
benchmarks/_data/same_sample/compaction.jsonl.

Runs two processes at a time (one per core); timings are in the files but the point is the
physics: steps, sweeps and states are exact and reproducible.
"""

from __future__ import annotations

import argparse
import copy
import glob
import json
import os
import sys
import time
import warnings

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
OUT = os.path.join(HERE, "_data", "same_sample")
PARTICLES = 400
SHEARS = {"A-off": ("A", "off"), "A-and": ("A", "anderson"), "B-and": ("B", "anderson")}
"""Shear name: (which compacted sample, the shear's NLGS acceleration)."""
COMPACTIONS = {"A": "off", "B": "anderson"}
"""Compacted sample: the compaction's NLGS acceleration."""
QUANTITIES = ["q/p (residual)", "a (residual)", "a_n (residual)", "a_t (residual)", "z (residual)",
              "weak fraction", "very weak fraction", "alpha (strong-force pdf)", "solid fraction (initial)",
              "z (initial)"]


def shears(seed: int, shape: str) -> dict:
    """The three shears of one seed and shape (module docstring); writes and returns their
    residual-state summaries, seconds and the compactions' steps and seconds."""
    import grainview
    import solver
    from grainview.report import run_summary
    from solver.preparation import preparation, prepare_sample, record

    out = {"seed": seed, "shape": shape, "particles": PARTICLES}
    prep = preparation("paper", particles=PARTICLES, shape=shape, seed=seed)
    samples = {}
    for name, acceleration in COMPACTIONS.items():
        start = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            sim = prepare_sample(prep, acceleration=acceleration)
        out[f"compact_{name}"] = {"steps": int(sim.compaction_steps), "seconds": time.perf_counter() - start,
                                  "settled": bool(sim.settled)}
        samples[name] = (sim, record(sim))
    for run, (name, acceleration) in SHEARS.items():
        sim, attrs = samples[name]
        sim = copy.deepcopy(sim)
        sim.parameters.acceleration = acceleration
        path = os.path.join(OUT, f"{shape}_{seed}_{run}.nc")
        start = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            solver.biaxial_test(sim, path, strain=0.2, velocity=0.01, every=200, overwrite=True, progress=False,
                                attrs=attrs, near_contacts=True)
        seconds = time.perf_counter() - start
        with grainview.open_dataset(path) as ds:
            summary = run_summary(ds, 0.3)
        out[run] = {k: (float(v) if isinstance(v, (int, float)) else str(v)) for k, v in summary.items()}
        out[run]["seconds"] = seconds
        os.remove(path)
    with open(os.path.join(OUT, f"{shape}_{seed}.json"), "w") as fh:
        json.dump(out, fh, indent=1)
    return out


def compactions(seed: int, shape: str) -> list:
    """The four compactions of one seed and shape (module docstring); returns their rows."""
    import grainview
    from solver.output import Recorder
    from solver.preparation import preparation, prepare_sample, record
    from solver.stepper import Parameters

    defaults = Parameters()
    prep = preparation("paper", particles=PARTICLES, shape=shape, seed=seed)
    rows = []
    for acceleration in ("off", "anderson"):
        for tighter in (1, 10):
            start = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                sim = prepare_sample(prep, acceleration=acceleration, tolerance=defaults.tolerance / tighter,
                                     max_iterations=defaults.max_iterations * tighter)
            seconds = time.perf_counter() - start
            path = os.path.join(OUT, f"compacted_{shape}_{seed}_{acceleration}_{tighter}.nc")
            with Recorder(path, sim, attrs={"scene": "isotropic", **record(sim)}, overwrite=True,
                          compress=False) as rec:
                rec.write()
            with grainview.open_dataset(path) as ds:
                z = float(ds.grain.coordination()["z"].isel(time=0))
                phi = float(ds.grain.solid_fraction().isel(time=0))
            os.remove(path)
            rows.append({"shape": shape, "seed": seed, "acceleration": acceleration, "tighter": tighter,
                         "z": round(z, 4), "solid_fraction": round(phi, 4), "steps": int(sim.compaction_steps),
                         "seconds": round(seconds, 1)})
    return rows


def shear_table(shape: str) -> str:
    """Markdown: A-off's seed mean (sd) and the differences' mean (sd) per quantity."""
    runs = [json.load(open(f)) for f in sorted(glob.glob(os.path.join(OUT, f"{shape}_*.json")))]
    if not runs:
        return f"(no {shape} runs)"

    def sd(v):
        return f"{v.std(ddof=1):.3f}" if len(v) > 1 else "-"

    lines = [f"**{PARTICLES} {shape}s, seeds {', '.join(str(r['seed']) for r in runs)}**", "",
             "| quantity | A-off: mean (sd over seeds) | B-and: mean (sd over seeds) | A-and - A-off: mean (sd) | "
             "B-and - A-off: mean (sd) |",
             "|---|---|---|---|---|"]
    for key in QUANTITIES:
        off = np.array([r["A-off"][key] for r in runs])
        both = np.array([r["B-and"][key] for r in runs])
        cells = [f"{off.mean():.3f} ({sd(off)})", f"{both.mean():.3f} ({sd(both)})"]
        for run in ("A-and", "B-and"):
            d = np.array([r[run][key] for r in runs]) - off
            cells.append(f"{d.mean():+.3f} ({sd(d)})")
        lines.append(f"| {key} | " + " | ".join(cells) + " |")
    seconds = {run: np.mean([r[run]["seconds"] for r in runs]) for run in SHEARS}
    compacting = {name: np.mean([r[f"compact_{name}"]["seconds"] for r in runs]) for name in COMPACTIONS}
    lines += ["", f"Mean seconds (two runs at a time on the 2 cores): shears A-off {seconds['A-off']:.0f}, "
              f"A-and {seconds['A-and']:.0f}, B-and {seconds['B-and']:.0f}; compactions A {compacting['A']:.0f}, "
              f"B {compacting['B']:.0f}."]
    return "\n".join(lines)


def compaction_table() -> str:
    """Markdown: z and solid fraction of the compacted samples, mean (sd) over seeds, per shape,
    acceleration and tolerance, and the paired differences that matter."""
    path = os.path.join(OUT, "compaction.jsonl")
    if not os.path.exists(path):
        return "(no compactions)"
    rows = [json.loads(line) for line in open(path) if line.strip()]
    lines = ["| shape | sweeps | tolerance | seeds | z: mean (sd) | solid fraction: mean (sd) |", "|---|---|---|---|---|---|"]
    by = {}
    for r in rows:
        by.setdefault((r["shape"], r["acceleration"], r["tighter"]), {})[r["seed"]] = r
    for (shape, acceleration, tighter), runs in sorted(by.items(), key=lambda kv: (kv[0][0], kv[0][2], kv[0][1] != "off")):
        z = np.array([r["z"] for r in runs.values()])
        phi = np.array([r["solid_fraction"] for r in runs.values()])
        lines.append(f"| {shape} | {acceleration} | {'default' if tighter == 1 else f'{tighter}x tighter'} | "
                     f"{len(runs)} | {z.mean():.3f} ({z.std(ddof=1):.3f}) | {phi.mean():.4f} ({phi.std(ddof=1):.4f}) |")
    lines += ["", "| shape | difference in z, paired by seed | mean | standard error |", "|---|---|---|---|"]
    for shape in sorted({k[0] for k in by}):
        pairs = {"Anderson - plain, default tolerance": (("anderson", 1), ("off", 1)),
                 "Anderson - plain, 10x tighter": (("anderson", 10), ("off", 10)),
                 "plain: 10x tighter - default": (("off", 10), ("off", 1)),
                 "Anderson: 10x tighter - default": (("anderson", 10), ("anderson", 1))}
        for name, (a, b) in pairs.items():
            ra, rb = by.get((shape, *a), {}), by.get((shape, *b), {})
            seeds = sorted(set(ra) & set(rb))
            if len(seeds) < 2:
                continue
            d = np.array([ra[s]["z"] - rb[s]["z"] for s in seeds])
            lines.append(f"| {shape} | {name} | {d.mean():+.3f} | {d.std(ddof=1) / np.sqrt(len(d)):.3f} |")
    return "\n".join(lines)


def main(argv=None):
    from concurrent.futures import ProcessPoolExecutor

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", default="0")
    parser.add_argument("--shapes", default="pentagon,disk")
    parser.add_argument("--compaction", action="store_true", help="the compactions instead of the shears")
    parser.add_argument("--table", action="store_true", help="print the tables of what was run and stop")
    args = parser.parse_args(argv)
    if args.table:
        for shape in ("pentagon", "disk"):
            print(shear_table(shape) + "\n")
        print(compaction_table())
        return
    os.makedirs(OUT, exist_ok=True)
    jobs = [(int(seed), shape) for seed in args.seeds.split(",") for shape in args.shapes.split(",")]
    with ProcessPoolExecutor(2) as pool:
        for result in pool.map(compactions if args.compaction else shears, *zip(*jobs)):
            if args.compaction:
                with open(os.path.join(OUT, "compaction.jsonl"), "a") as fh:
                    fh.writelines(json.dumps(r) + "\n" for r in result)
            print(json.dumps(result)[:300], flush=True)


if __name__ == "__main__":
    main()
