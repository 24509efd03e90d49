"""Routes to a compacted sample: steps, NLGS sweeps and time of the isotropic compaction, and
the state it reaches, for routes that differ in how fast the walls close.

    python benchmarks/compaction.py --shape pentagon --particles 1000 --seeds 0,1,2 \
        --routes paper,approach,fast [--out benchmarks/_data/compaction.jsonl]

Every route deposits the sample of the 'paper' preparation (friction 0.4, sigma0 = 10 kPa on
the right and top walls) and compacts it until the equilibrium test of
solver.scenes.isotropic_compaction holds; they differ only in the closing walls' speed cap:

* ``paper``: 5 cm/s throughout (this project's default);
* ``approach``: 0.5 m/s while the solid fraction is below 0.70 (the deposit starts at about
  0.60; the packing offers no resistance yet), then 5 cm/s;
* ``fast``: 20 cm/s throughout;
* ``loose``: as ``paper``, with the NLGS tolerance 10x looser until the test first holds, then
  the default tolerance until it holds again.

The state reached: solid fraction, coordination z of the force-bearing contacts over the
particles with at least two (rattlers left out; a double contact counts once), the number of
rattlers, and the fabric anisotropy a = 2 (F_1 - F_2) of the particle-particle contact
normals. One JSON line per (route, seed) is appended to ``--out`` and printed; ``--table``
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
sys.path.insert(0, os.path.dirname(HERE))

ROUTES = {
    "paper": {"approach_speed": None, "until_solid_fraction": None, "loosen": 1.0, "speed": 0.05},
    "approach": {"approach_speed": 0.5, "until_solid_fraction": 0.70, "loosen": 1.0, "speed": 0.05},
    "fast": {"approach_speed": None, "until_solid_fraction": None, "loosen": 1.0, "speed": 0.2},
    "loose": {"approach_speed": None, "until_solid_fraction": None, "loosen": 10.0, "speed": 0.05},
}


def compact(shape: str, particles: int, seed: int, route: str) -> dict:
    """Compact one sample along ``route``; the numbers of the module docstring."""
    from solver.output import pair_contacts
    from solver.preparation import preparation
    from solver.scenes import compaction_sample, isotropic_compaction
    from solver.walls import STRESS

    r = ROUTES[route]
    prep = preparation("paper", shape=shape, particles=particles, seed=seed)
    sim = compaction_sample(prep.particles, prep.shape, sigma0=prep.sigma0, friction=prep.friction, seed=seed,
                            aspect=prep.aspect, max_wall_speed=r["speed"])
    driven = np.flatnonzero(sim.walls.mode == STRESS)
    solid = float((sim.mass / (sim.parameters.density * sim.parameters.thickness)).sum())
    default_tolerance = sim.parameters.tolerance
    sim.parameters.tolerance = default_tolerance * r["loosen"]
    approaching = r["approach_speed"] is not None
    if approaching:
        sim.walls.max_speed[driven] = r["approach_speed"]
    counts = {"sweeps": 0, "switch_step": None}
    step = sim.step

    def counted_step():
        nonlocal approaching
        info = step()
        counts["sweeps"] += info.iterations
        if approaching:
            lo, hi = sim.walls.box_bounds()
            if solid / float(np.prod(hi - lo)) >= r["until_solid_fraction"]:
                approaching = False
                counts["switch_step"] = sim.step_index
                sim.walls.max_speed[driven] = r["speed"]
        return info

    sim.step = counted_step
    start = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        steps = isotropic_compaction(sim, max_steps=prep.max_steps, progress=False)
        if r["loosen"] != 1.0:
            sim.parameters.tolerance = default_tolerance
            sim.walls.max_speed[driven] = r["speed"]
            steps += isotropic_compaction(sim, max_steps=prep.max_steps, progress=False)
    seconds = time.perf_counter() - start
    lo, hi = sim.walls.box_bounds()
    contacts = pair_contacts(sim, None, 10**6)
    i, j, normal = (np.asarray(contacts[k]) for k in ("i", "j", "normal"))
    pp = j < particles
    per_particle = np.bincount(i[pp], minlength=particles) + np.bincount(j[pp], minlength=particles)
    nx, ny = normal[pp, 0], normal[pp, 1]
    fabric = np.array([[np.mean(nx * nx), np.mean(nx * ny)], [np.mean(nx * ny), np.mean(ny * ny)]])
    low, high = np.linalg.eigvalsh(fabric)
    return {"shape": shape, "particles": particles, "seed": seed, "route": route, "steps": int(steps),
            "switch_step": counts["switch_step"], "sweeps": int(counts["sweeps"]), "seconds": round(seconds, 1),
            "settled": bool(sim.settled), "solid_fraction": round(solid / float(np.prod(hi - lo)), 4),
            "z": round(float(per_particle[per_particle >= 2].mean()), 3),
            "rattlers": int((per_particle < 2).sum()), "fabric_a": round(float(2 * (high - low)), 4)}


def table(path) -> str:
    """The Markdown table of a JSON-lines file written by this script: one row per route with
    the mean and the spread (min-max) over seeds."""
    rows = [json.loads(line) for line in open(path) if line.strip()]
    out = ["| sample | route | seeds | steps | NLGS sweeps (M) | time (s) | solid fraction | z | rattlers | a |",
           "|---|---|---|---|---|---|---|---|---|---|"]
    keys = sorted({(r["shape"], r["particles"], r["route"]) for r in rows},
                  key=lambda k: (k[0], k[1], list(ROUTES).index(k[2])))
    for shape, n, route in keys:
        rs = [r for r in rows if (r["shape"], r["particles"], r["route"]) == (shape, n, route)]

        def span(name, fmt="{:.0f}", scale=1.0):
            v = np.array([r[name] for r in rs], float) * scale
            return (fmt.format(v.mean()) + (f" ({fmt.format(v.min())}-{fmt.format(v.max())})" if len(v) > 1 else ""))

        out.append(f"| {n} {shape}s | {route} | {len(rs)} | {span('steps')} | {span('sweeps', '{:.2f}', 1e-6)} | "
                   f"{span('seconds')} | {span('solid_fraction', '{:.4f}')} | {span('z', '{:.3f}')} | "
                   f"{span('rattlers')} | {span('fabric_a', '{:.3f}')} |")
    return "\n".join(out)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--shape", default="pentagon")
    parser.add_argument("--particles", type=int, default=1000)
    parser.add_argument("--seeds", default="0")
    parser.add_argument("--routes", default="paper,fast")
    parser.add_argument("--out", default=os.path.join(HERE, "_data", "compaction.jsonl"))
    parser.add_argument("--table", action="store_true", help="print the table of --out and stop")
    args = parser.parse_args(argv)
    if args.table:
        print(table(args.out))
        return
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    for seed in map(int, args.seeds.split(",")):
        for route in args.routes.split(","):
            result = compact(args.shape, args.particles, seed, route)
            with open(args.out, "a") as fh:
                fh.write(json.dumps(result) + "\n")
            print(json.dumps(result), flush=True)


if __name__ == "__main__":
    main()
