"""Routes to a compacted sample: steps, NLGS sweeps and time of the isotropic compaction, and
the state it reaches, for routes that differ in how fast the walls close.

    python -m benchmarks.compaction --shape pentagon --particles 1000 --seeds 0,1,2 \
        --routes paper,approach,fast [--out benchmarks/_data/compaction.jsonl]
    python -m benchmarks.compaction --particles 4000 --routes paper --acceleration anderson \
        --stall 200                                    # the same route, solved another way
    python -m benchmarks.compaction --particles 14400 --routes fast --acceleration anderson \
        --domains 2 --report-every 250 --save sample.pkl  # on both cores; keep the sample

Every route deposits the sample of the 'paper' preparation (friction 0.4, sigma0 = 10 kPa on
the right and top walls) and compacts it until the equilibrium test of
solver.scenes.isotropic_compaction holds; they differ only in the closing walls' speed cap:

* ``paper``: 5 cm/s throughout (this project's default);
* ``approach``: 0.5 m/s while the solid fraction is below 0.70 (the deposit starts at about
  0.60; the packing offers no resistance yet), then 5 cm/s;
* ``fast``: 20 cm/s throughout;
* ``loose``: as ``paper``, with the NLGS tolerance 10x looser until the test first holds, then
  the default tolerance until it holds again.

The solver is the serial plain NLGS unless asked otherwise: ``--acceleration anderson`` (with
``--period``: an extrapolation every k sweeps), ``--stall W`` (the stall test over W sweeps;
solver.nlgs) and ``--domains D`` (D domains swept at once, a thread each; solver.parallel_nlgs)
solve the same route's steps another way; each row says how. ``--save`` pickles the compacted
simulation with its compaction's seconds, the form benchmarks/time_to_strain.py ``--sample``
shears.

The state reached: solid fraction, coordination z of the force-bearing contacts over the
particles with at least two (rattlers left out; a double contact counts once), the number of
rattlers, and the fabric anisotropy a = 2 (F_1 - F_2) of the particle-particle contact
normals. Time: wall-clock seconds and the process's CPU seconds (nearer the time on an idle
core when other processes share the machine). One JSON line per (route, seed) is appended to
``--out`` and printed; ``--table``
prints the Markdown table of a JSON-lines file.
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
from benchmarks.common import save_sample, way_of_solving

ROUTES = {
    "paper": {"approach_speed": None, "until_solid_fraction": None, "loosen": 1.0, "speed": 0.05},
    "approach": {"approach_speed": 0.5, "until_solid_fraction": 0.70, "loosen": 1.0, "speed": 0.05},
    "fast": {"approach_speed": None, "until_solid_fraction": None, "loosen": 1.0, "speed": 0.2},
    "loose": {"approach_speed": None, "until_solid_fraction": None, "loosen": 10.0, "speed": 0.05},
}


def compact(shape: str, particles: int, seed: int, route: str, acceleration: str = "off", period: int = 1,
            stall: int = 0, domains: int = 1, save: str | None = None, report_every: int = 0) -> dict:
    """Compact one sample along ``route`` with NLGS sweeps plain or Anderson-accelerated
    (``acceleration``, an extrapolation every ``period`` sweeps), serial or on ``domains``
    domains (a thread each), and the stall test over ``stall`` sweeps (0: none); the numbers of
    the module docstring, and the sweeps per step (median, 90th percentile) and the number of
    steps that met their tolerance late or never (stopped by the sweep cap or the stall test).
    ``save``: a pickle file for the compacted simulation (written whole or not at all);
    ``report_every``: a progress line on stderr every so many steps (0: none)."""
    from solver.output import pair_contacts
    from solver.preparation import preparation
    from solver.scenes import compaction_sample, isotropic_compaction
    from solver.walls import STRESS

    r = ROUTES[route]
    prep = preparation("paper", shape=shape, particles=particles, seed=seed)
    sim = compaction_sample(prep.particles, prep.shape, sigma0=prep.sigma0, friction=prep.friction, seed=seed,
                            aspect=prep.aspect, max_wall_speed=r["speed"], acceleration=acceleration,
                            anderson_period=period, stall_sweeps=stall, domains=domains)
    driven = np.flatnonzero(sim.walls.mode == STRESS)
    solid = float((sim.mass / (sim.parameters.density * sim.parameters.thickness)).sum())

    def solid_fraction():
        lo, hi = sim.walls.box_bounds()
        return solid / float(np.prod(hi - lo))

    default_tolerance = sim.parameters.tolerance
    sim.parameters.tolerance = default_tolerance * r["loosen"]
    approaching = r["approach_speed"] is not None
    if approaching:
        sim.walls.max_speed[driven] = r["approach_speed"]
    counts = {"sweeps": [], "unconverged": 0, "switch_step": None}

    def count(info):
        nonlocal approaching
        counts["sweeps"].append(info.iterations)
        counts["unconverged"] += not info.converged
        if report_every and sim.step_index % report_every == 0:
            print(f"step {sim.step_index}: solid fraction {solid_fraction():.4f}, "
                  f"{np.median(counts['sweeps'][-report_every:]):.0f} sweeps (median), "
                  f"{time.perf_counter() - start:.0f} s", file=sys.stderr, flush=True)
        if approaching and solid_fraction() >= r["until_solid_fraction"]:
            approaching = False
            counts["switch_step"] = sim.step_index
            sim.walls.max_speed[driven] = r["speed"]

    start, cpu = time.perf_counter(), time.process_time()
    with warnings.catch_warnings(), sim.watch(after=count):  # the counting is not part of the sample
        warnings.simplefilter("ignore")
        steps = isotropic_compaction(sim, max_steps=prep.max_steps, progress=False)
        if r["loosen"] != 1.0:
            sim.parameters.tolerance = default_tolerance
            sim.walls.max_speed[driven] = r["speed"]
            steps += isotropic_compaction(sim, max_steps=prep.max_steps, progress=False)
    seconds, cpu = time.perf_counter() - start, time.process_time() - cpu
    sim.history.compaction_steps = int(steps)
    if save:
        save_sample(save, sim, seconds)
    contacts = pair_contacts(sim, None, 10**6)
    i, j, normal = (np.asarray(contacts[k]) for k in ("i", "j", "normal"))
    pp = j < particles
    per_particle = np.bincount(i[pp], minlength=particles) + np.bincount(j[pp], minlength=particles)
    nx, ny = normal[pp, 0], normal[pp, 1]
    fabric = np.array([[np.mean(nx * nx), np.mean(nx * ny)], [np.mean(nx * ny), np.mean(ny * ny)]])
    low, high = np.linalg.eigvalsh(fabric)
    sweeps = np.array(counts["sweeps"])
    return {"shape": shape, "particles": particles, "seed": seed, "route": route, "solver": sim.parameters.solver,
            "acceleration": acceleration,
            "anderson_period": period, "stall_sweeps": stall, "domains": domains, "steps": int(steps),
            "switch_step": counts["switch_step"], "sweeps": int(sweeps.sum()),
            "sweeps_median": float(np.median(sweeps)), "sweeps_p90": float(np.percentile(sweeps, 90)),
            "unconverged_steps": int(counts["unconverged"]), "seconds": round(seconds, 1),
            "cpu_seconds": round(cpu, 1),
            "settled": bool(sim.settled), "solid_fraction": round(solid_fraction(), 4),
            "z": round(float(per_particle[per_particle >= 2].mean()), 3),
            "rattlers": int((per_particle < 2).sum()), "fabric_a": round(float(2 * (high - low)), 4)}


def table(path, rows=None) -> str:
    """The Markdown table of a JSON-lines file written by this script (or of ``rows``, the dicts
    of :func:`compact`): one row per route and way of solving, with the mean and the spread
    (min-max) over seeds."""
    rows = rows if rows is not None else [json.loads(line) for line in open(path) if line.strip()]
    out = ["| sample | route | sweeps | seeds | steps | NLGS sweeps (M) | sweeps / step median, p90 | "
           "unconverged steps | time (s) | CPU time (s) | solid fraction | z | rattlers | a |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    keys = sorted({(r["shape"], r["particles"], r["route"], way_of_solving(r)) for r in rows},
                  key=lambda k: (k[0], k[1], list(ROUTES).index(k[2]), k[3] != "off", k[3]))
    for shape, n, route, how in keys:
        rs = [r for r in rows if (r["shape"], r["particles"], r["route"], way_of_solving(r)) == (shape, n, route, how)]

        def span(name, fmt="{:.0f}", scale=1.0):
            if any(name not in r for r in rs):
                return "-"
            v = np.array([r[name] for r in rs], float) * scale
            return (fmt.format(v.mean()) + (f" ({fmt.format(v.min())}-{fmt.format(v.max())})" if len(v) > 1 else ""))

        out.append(f"| {n} {shape}s | {route} | {how} | {len(rs)} | {span('steps')} | "
                   f"{span('sweeps', '{:.2f}', 1e-6)} | {span('sweeps_median')}, {span('sweeps_p90')} | "
                   f"{span('unconverged_steps')} | {span('seconds')} | {span('cpu_seconds')} | {span('solid_fraction', '{:.4f}')} | "
                   f"{span('z', '{:.3f}')} | {span('rattlers')} | {span('fabric_a', '{:.3f}')} |")
    return "\n".join(out)


def main(argv=None):
    from solver.contact_solvers import ACCELERATIONS

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--shape", default="pentagon")
    parser.add_argument("--particles", type=int, default=1000)
    parser.add_argument("--seeds", default="0")
    parser.add_argument("--routes", default="paper,fast")
    parser.add_argument("--acceleration", choices=tuple(ACCELERATIONS), default="off",
                        help="the solver, by the former names of solver.contact_solvers.ACCELERATIONS: "
                        + ", ".join(f"{old} is {new}" for old, new in ACCELERATIONS.items()))
    parser.add_argument("--period", type=int, default=1, help="Anderson: sweeps between extrapolations")
    parser.add_argument("--stall", type=int, default=0, help="the stall test over this many sweeps (0: none)")
    parser.add_argument("--domains", type=int, default=1, help="NLGS domains swept at once (threads)")
    parser.add_argument("--save", default="", help="pickle the compacted simulation here (one seed and route only)")
    parser.add_argument("--report-every", type=int, default=0, help="a progress line every so many steps")
    parser.add_argument("--out", default=os.path.join(HERE, "_data", "compaction.jsonl"))
    parser.add_argument("--table", action="store_true", help="print the table of --out and stop")
    parser.add_argument("--results", help="also write the table of this run's rows as a results file here")
    args = parser.parse_args(argv)
    if args.table:
        print(table(args.out))
        return
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    if args.save and ("," in args.seeds or "," in args.routes):
        parser.error("--save keeps one sample: give one seed and one route")
    rows = []
    for seed in map(int, args.seeds.split(",")):
        for route in args.routes.split(","):
            result = compact(args.shape, args.particles, seed, route, args.acceleration, args.period, args.stall,
                             args.domains, args.save or None, args.report_every)
            with open(args.out, "a") as fh:
                fh.write(json.dumps(result) + "\n")
            print(json.dumps(result), flush=True)
            rows.append(result)
    if args.results:
        from benchmarks.common import machine_description

        with open(args.results, "w") as fh:
            fh.write("\n".join(["# Compaction routes", "", "Written by `python -m benchmarks.compaction "
                                 + " ".join(argv if argv is not None else sys.argv[1:]) + "` (its docstring defines the "
                                 "routes and the state measures); mean over seeds, min-max in parentheses.", "",
                                 machine_description(), "", table(None, rows), ""]))


if __name__ == "__main__":
    main()
