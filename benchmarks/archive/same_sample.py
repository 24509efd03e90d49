"""Does a way of solving change the study's physics?  The evidence for a solver default.

    python -m benchmarks.archive.same_sample --seeds 0,1,2            # shears (~25 min per seed, 2 cores)
    python -m benchmarks.archive.same_sample --compaction --seeds 0,1,2,3,4 --shapes disk
    python -m benchmarks.archive.same_sample --tighter 4 --seeds 0,1,2,3 --shapes pentagon
    python -m benchmarks.archive.same_sample --static --seeds 0 --shapes pentagon
    python -m benchmarks.archive.same_sample --table                  # archive/same-sample.md's tables

Shears. Per seed and shape (400 particles, the 'paper' preparation, the study's defaults:
eps_1 = 0.2 at 1 cm/s, a snapshot every 200 steps, near contacts written), the deposit is
compacted twice, with plain NLGS sweeps (sample A) and with Anderson-accelerated sweeps (B). A
is sheared with plain sweeps (A-off) and with Anderson sweeps (A-and): the same sample, so the
difference is the solver's alone (and the chaotic divergence of two trajectories that any
change of round-off starts). B is sheared with Anderson sweeps (B-and): the whole study as it
runs with Anderson sweeps. The headline's residual-state numbers (eps_q >= 0.3;
grainview.app.report.run_summary) of each go to benchmarks/_data/same_sample/<shape>_<seed>.json;
the table gives, per quantity, the seeds' mean and standard deviation of A-off and of B-and, and
the mean and standard deviation over seeds of the differences A-and - A-off and B-and - A-off.

Compaction (``--compaction``). The state a compaction reaches depends on how well its steps are
solved (benchmarks/archive/solver-log.md, "Compaction"): per seed, the deposit is compacted with plain and with
Anderson sweeps at the default tolerance and at a 10x tighter one (sweep cap 10x higher), and
the compacted state's coordination z (force-bearing contacts, rattlers out;
``ds.grain.coordination``) and solid fraction are written to
benchmarks/_data/same_sample/compaction.jsonl.

Tolerance (``--tighter K``). Does the default tolerance bias the physics? Per seed and shape,
sample B (compacted with Anderson sweeps at the default tolerance) is sheared twice with
Anderson sweeps, at the default tolerance (B-and, as above) and at a K times smaller one with a
K times higher sweep cap (B-tight); besides the residual-state summaries, each run's per-step
sweeps, local-law residual and unbalanced-force ratio (:mod:`solver.residuals`) are summarised.
Written to benchmarks/_data/same_sample/tolerance_<shape>_<seed>_<K>.json.

Static part (``--static``). Is a tolerance's effect that of the forces solved on the same
geometry, or of the path the grains take? Sample B is sheared with Anderson sweeps (as
``benchmarks.shear.capture`` shears: an extrapolation every 2 sweeps, the stall test over 200) to
shear step 30,000 (eps_q about 0.45 for 400 pentagons: the residual state), and every 20th
step's contact problem up to step 30,400 is re-solved from its warm start at the default
tolerance and 4, 10 and 100 times tighter (the shear's sweep cap, else 22,000). The q/p of each
solution's stress tensor (grainview.analysis.arrays.stress, the particle-wall contacts included) is
compared on the same geometry. Written to benchmarks/_data/same_sample/static_<shape>_<seed>.json.

Runs two processes at a time (one per core); timings are in the files but the point is the
physics: steps, sweeps and states are exact and reproducible on one machine (on another, the
round-off of its arithmetic starts another trajectory: docs/fidelity.md, section 6).
"""

from __future__ import annotations

import argparse
import copy
import glob
import json
import os
import time
import warnings

import numpy as np

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))  # benchmarks/
OUT = os.path.join(HERE, "_data", "same_sample")
PARTICLES = 400
SHEARS = {"A-off": ("A", "off"), "A-and": ("A", "anderson"), "B-and": ("B", "anderson")}
"""Shear name: (which compacted sample, the shear's NLGS acceleration)."""
COMPACTIONS = {"A": "off", "B": "anderson"}
"""Compacted sample: the compaction's NLGS acceleration."""
QUANTITIES = ["q/p (residual)", "a (residual)", "a_n (residual)", "a_t (residual)", "z (residual)",
              "weak fraction", "very weak fraction", "alpha (strong-force pdf)", "solid fraction (initial)",
              "z (initial)"]


def _compacted(seed: int, shape: str, acceleration: str, **options):
    """The seed's 'paper' deposit of PARTICLES ``shape``s compacted with ``acceleration``
    sweeps (``options``: other solver parameters), its warnings silenced."""
    from solver.preparation import preparation, prepare_sample

    prep = preparation("paper", particles=PARTICLES, shape=shape, seed=seed)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return prepare_sample(prep, acceleration=acceleration, **options)


def shears(seed: int, shape: str) -> dict:
    """The three shears of one seed and shape (module docstring); writes and returns their
    residual-state summaries, seconds and the compactions' steps and seconds."""
    from solver.preparation import record

    out = {"seed": seed, "shape": shape, "particles": PARTICLES}
    samples = {}
    for name, acceleration in COMPACTIONS.items():
        start = time.perf_counter()
        sim = _compacted(seed, shape, acceleration)
        out[f"compact_{name}"] = {"steps": int(sim.compaction_steps), "seconds": time.perf_counter() - start,
                                  "settled": bool(sim.settled)}
        samples[name] = (sim, record(sim))
    for run, (name, acceleration) in SHEARS.items():
        sim, attrs = samples[name]
        sim = copy.deepcopy(sim)
        sim.parameters.acceleration = acceleration
        out[run] = _shear_summary(sim, attrs, os.path.join(OUT, f"{shape}_{seed}_{run}.nc"))
    with open(os.path.join(OUT, f"{shape}_{seed}.json"), "w") as fh:
        json.dump(out, fh, indent=1)
    return out


def _shear_summary(sim, attrs: dict, path: str) -> dict:
    """Shear ``sim`` (eps_1 = 0.2 at 1 cm/s, a snapshot every 200 steps, near contacts written,
    to the temporary file ``path``): the residual-state summary (eps_q >= 0.3;
    grainview.app.report.run_summary), the seconds, and the median and 90th percentile of the
    steps' sweeps, local-law residual and unbalanced-force ratio."""
    import grainview
    import solver
    from grainview.app.report import run_summary

    steps = []

    def recorded(info):
        steps.append((info.iterations, info.local_law_residual, info.unbalanced_force))

    start = time.perf_counter()
    with warnings.catch_warnings(), sim.watch(after=recorded):
        warnings.simplefilter("ignore")
        solver.biaxial_test(sim, path, strain=0.2, velocity=0.01, every=200, overwrite=True, progress=False,
                            attrs=attrs, near_contacts=True)
    seconds = time.perf_counter() - start
    with grainview.open_dataset(path) as ds:
        summary = run_summary(ds, 0.3)
    os.remove(path)
    out = {k: (float(v) if isinstance(v, (int, float)) else str(v)) for k, v in summary.items()}
    steps = np.array(steps, dtype=float)
    out.update(seconds=seconds, steps=len(steps))
    for column, name in enumerate(("sweeps", "local-law residual", "unbalanced force")):
        out[f"{name} median"] = float(np.nanmedian(steps[:, column]))
        out[f"{name} p90"] = float(np.nanpercentile(steps[:, column], 90))
    return out


def tolerance(seed: int, shape: str, tighter: int) -> dict:
    """The tolerance study of one seed and shape (module docstring); writes and returns it."""
    from solver.preparation import record

    sample = _compacted(seed, shape, "anderson")
    out = {"seed": seed, "shape": shape, "particles": PARTICLES, "tighter": tighter}
    for run, factor in (("B-and", 1), ("B-tight", tighter)):
        sim = copy.deepcopy(sample)
        sim.parameters.acceleration = "anderson"
        sim.parameters.tolerance /= factor
        sim.parameters.max_iterations *= factor
        out[run] = _shear_summary(sim, record(sample), os.path.join(OUT, f"tolerance_{shape}_{seed}_{run}.nc"))
    with open(os.path.join(OUT, f"tolerance_{shape}_{seed}_{tighter}.json"), "w") as fh:
        json.dump(out, fh, indent=1)
    return out


STATIC_STEPS = (30_000, 30_400, 20)
"""Shear steps first, last and every of the ``--static`` re-solves."""
STATIC_FACTORS = (1, 4, 10, 100)
"""Tolerances of the ``--static`` re-solves: the default divided by these."""
STATIC_CAP = 22_000
"""Sweep cap of the tighter ``--static`` re-solves (the default's is the shear's own)."""


def _standard_error(d) -> float:
    """Standard error of the mean of the paired differences ``d`` (sample sd / sqrt(n))."""
    d = np.asarray(d, dtype=float)
    return float(d.std(ddof=1) / np.sqrt(d.size))


def _sd(v) -> str:
    """The seeds' sample standard deviation, or '-' for one seed."""
    return f"{np.std(v, ddof=1):.3f}" if len(v) > 1 else "-"


def _q_over_p(problem, pn, pt) -> float:
    """q/p of the stress tensor of one contact problem's impulses (the branch vector of a point
    is r_a - r_b: centre of a to centre of b, or to the contact point for a wall)."""
    from grainview.analysis.arrays.stress import stress_tensor
    from grainview.analysis.arrays.tensors import principal

    normal = np.stack([problem.nx, problem.ny], -1)
    branch = np.stack([problem.rax - problem.rbx, problem.ray - problem.rby], -1)
    s1, s2, _ = principal(stress_tensor(pn, pt, normal, branch, np.ones(pn.size, bool), 1.0))
    return float((s1 - s2) / (s1 + s2))


def static(seed: int, shape: str) -> dict:
    """The static part of the tolerance effect for one seed and shape (module docstring)."""
    from solver import acceleration, residuals
    from benchmarks.shear import capture

    sim = _compacted(seed, shape, "anderson")
    first, last, every = STATIC_STEPS
    rows = []
    for case in capture(sim, first, last):
        if (case["step"] - first) % every:
            continue
        problem, o = case["problem"], case["options"]
        row = {"step": case["step"]}
        for factor in STATIC_FACTORS:
            pn, pt = case["pn"].copy(), case["pt"].copy()
            vx, vy, w = case["vx"].copy(), case["vy"].copy(), case["w"].copy()
            result = acceleration.solve_problem_anderson(
                problem, pn, pt, vx, vy, w, tolerance=o["tolerance"] / factor, max_tolerance=o["max_tolerance"],
                max_iterations=o["max_iterations"] if factor == 1 else STATIC_CAP, memory=3, period=1, stall=0,
                domains=1)
            row[factor] = {"q/p": _q_over_p(problem, pn, pt), "sweeps": int(result.iterations),
                           "local-law residual": residuals.local_law_residual(problem, pn, pt, vx, vy, w)}
        rows.append(row)
    out = {"seed": seed, "shape": shape, "particles": PARTICLES, "rows": rows}
    with open(os.path.join(OUT, f"static_{shape}_{seed}.json"), "w") as fh:
        json.dump(out, fh, indent=1)
    return out


def static_table(shape: str) -> str:
    """Markdown: per tolerance factor, the re-solved steps' mean q/p, its difference from the
    default's on the same step averaged per seed (the steps of one shear are 20 steps apart,
    so not independent: the seed is the unit), the mean of those over the seeds and their
    standard error, and the median sweeps and local-law residual."""
    runs = [json.load(open(f)) for f in sorted(glob.glob(os.path.join(OUT, f"static_{shape}_*.json")))]
    if not runs:
        return f"(no {shape} static re-solves)"
    rows = [r for run in runs for r in run["rows"]]
    seeds = ", ".join(str(r["seed"]) for r in runs)
    lines = [f"**{PARTICLES} {shape}s, seeds {seeds}: {len(rows)} residual-state steps re-solved on the same "
             "geometry**", "",
             f"| tolerance | q/p: mean | minus the default's, paired by step: mean per seed ({seeds}) | "
             "mean over seeds | standard error over seeds | sweeps median | local-law residual median |",
             "|---|---|---|---|---|---|---|"]
    for factor in STATIC_FACTORS:
        q = np.array([r[str(factor)]["q/p"] for r in rows])
        per_seed = np.array([np.mean([r[str(factor)]["q/p"] - r["1"]["q/p"] for r in run["rows"]]) for run in runs])
        se = f"{_standard_error(per_seed):.4f}" if len(runs) > 1 else "-"
        lines.append(f"| {'default' if factor == 1 else f'{factor}x tighter'} | {q.mean():.4f} | "
                     f"{', '.join(f'{d:+.4f}' for d in per_seed)} | {per_seed.mean():+.4f} | {se} | "
                     f"{np.median([r[str(factor)]['sweeps'] for r in rows]):.0f} | "
                     f"{np.median([r[str(factor)]['local-law residual'] for r in rows]):.2e} |")
    return "\n".join(lines)


def compactions(seed: int, shape: str) -> list:
    """The four compactions of one seed and shape (module docstring); returns their rows."""
    import grainview
    from solver.output import Recorder
    from solver.preparation import record
    from solver.stepper import Parameters

    defaults = Parameters()
    rows = []
    for acceleration in ("off", "anderson"):
        for tighter in (1, 10):
            start = time.perf_counter()
            sim = _compacted(seed, shape, acceleration, tolerance=defaults.tolerance / tighter,
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
    lines = [f"**{PARTICLES} {shape}s, seeds {', '.join(str(r['seed']) for r in runs)}**", "",
             "| quantity | A-off: mean (sd over seeds) | B-and: mean (sd over seeds) | A-and - A-off: mean (sd) | "
             "B-and - A-off: mean (sd) |",
             "|---|---|---|---|---|"]
    for key in QUANTITIES:
        off = np.array([r["A-off"][key] for r in runs])
        both = np.array([r["B-and"][key] for r in runs])
        cells = [f"{off.mean():.3f} ({_sd(off)})", f"{both.mean():.3f} ({_sd(both)})"]
        for run in ("A-and", "B-and"):
            d = np.array([r[run][key] for r in runs]) - off
            cells.append(f"{d.mean():+.3f} ({_sd(d)})")
        lines.append(f"| {key} | " + " | ".join(cells) + " |")
    seconds = {run: np.mean([r[run]["seconds"] for r in runs]) for run in SHEARS}
    compacting = {name: np.mean([r[f"compact_{name}"]["seconds"] for r in runs]) for name in COMPACTIONS}
    lines += ["", f"Mean seconds (two runs at a time on the 2 cores): shears A-off {seconds['A-off']:.0f}, "
              f"A-and {seconds['A-and']:.0f}, B-and {seconds['B-and']:.0f}; compactions A {compacting['A']:.0f}, "
              f"B {compacting['B']:.0f}."]
    return "\n".join(lines)


def tolerance_table(shape: str) -> str:
    """Markdown, per tightening factor K run: the tolerance study's B-and and B-tight, seed mean
    (sd), and their paired differences, mean and standard error, per quantity; then how each
    was solved."""
    files = sorted(glob.glob(os.path.join(OUT, f"tolerance_{shape}_*.json")))
    if not files:
        return f"(no {shape} tolerance runs)"
    by_factor = {}
    for f in files:
        run = json.load(open(f))
        by_factor.setdefault(run["tighter"], []).append(run)
    return "\n\n".join(_tolerance_table(runs, factor) for factor, runs in sorted(by_factor.items()))


def _tolerance_table(runs: list, tighter: int) -> str:
    n = len(runs)
    lines = [f"**{PARTICLES} {runs[0]['shape']}s, seeds {', '.join(str(r['seed']) for r in runs)}: the default "
             f"tolerance (B-and) and {tighter}x tighter (B-tight)**", "",
             "| quantity | B-and: mean (sd over seeds) | B-tight: mean (sd) | B-tight - B-and: mean | standard error |",
             "|---|---|---|---|---|"]
    for key in QUANTITIES:
        default = np.array([r["B-and"][key] for r in runs])
        tight = np.array([r["B-tight"][key] for r in runs])
        d = tight - default
        se = f"{_standard_error(d):.3f}" if n > 1 else "-"
        lines.append(f"| {key} | {default.mean():.3f} ({_sd(default)}) | {tight.mean():.3f} ({_sd(tight)}) | "
                     f"{d.mean():+.3f} | {se} |")
    lines += ["", "| run | steps | sweeps per step: median, p90 | local-law residual: median, p90 | "
              "unbalanced force: median, p90 | seconds |", "|---|---|---|---|---|---|"]
    for run in ("B-and", "B-tight"):
        def mean(key):
            return np.mean([r[run][key] for r in runs])
        lines.append(f"| {run} | {mean('steps'):.0f} | {mean('sweeps median'):.0f}, {mean('sweeps p90'):.0f} | "
                     f"{mean('local-law residual median'):.2e}, {mean('local-law residual p90'):.2e} | "
                     f"{mean('unbalanced force median'):.3f}, {mean('unbalanced force p90'):.3f} | "
                     f"{mean('seconds'):.0f} |")
    lines += ["", "(the second table: means over the seeds; two runs at a time on the 2 cores)"]
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
            lines.append(f"| {shape} | {name} | {d.mean():+.3f} | {_standard_error(d):.3f} |")
    return "\n".join(lines)


def main(argv=None):
    from concurrent.futures import ProcessPoolExecutor

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", default="0")
    parser.add_argument("--shapes", default="pentagon,disk")
    what = parser.add_mutually_exclusive_group()
    what.add_argument("--compaction", action="store_true", help="the compactions instead of the shears")
    what.add_argument("--tighter", type=int, default=0, metavar="K",
                      help="the tolerance study: shear at the default tolerance and K times tighter")
    what.add_argument("--static", action="store_true",
                      help="the static part: residual-state steps re-solved at tighter tolerances")
    what.add_argument("--table", action="store_true", help="print the tables of what was run and stop")
    args = parser.parse_args(argv)
    if args.table:
        for shape in ("pentagon", "disk"):
            print(shear_table(shape) + "\n")
        for shape in ("pentagon", "disk"):
            print(tolerance_table(shape) + "\n")
            print(static_table(shape) + "\n")
        print(compaction_table())
        return
    os.makedirs(OUT, exist_ok=True)
    jobs = [(int(seed), shape) for seed in args.seeds.split(",") for shape in args.shapes.split(",")]
    with ProcessPoolExecutor(2) as pool:
        if args.tighter:
            jobs = [job + (args.tighter,) for job in jobs]
        work = compactions if args.compaction else tolerance if args.tighter else static if args.static else shears
        for result in pool.map(work, *zip(*jobs)):
            if args.compaction:
                with open(os.path.join(OUT, "compaction.jsonl"), "a") as fh:
                    fh.writelines(json.dumps(r) + "\n" for r in result)
            print(json.dumps(result)[:300], flush=True)


if __name__ == "__main__":
    main()
