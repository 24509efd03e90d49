"""Dense benchmark samples: compacted, equilibrated packings of 1000, 4000 and 14,400
pentagons and disks under the paper's preparation, built once and cached as files of the data
contract (benchmarks/_data/fidelity/samples/, the fidelity study's cache), so that every speed
figure can start from a dense packing (``solver.load_sample(path)``, then ``biaxial_test``).

    python -m benchmarks.samples                       # list: cached or missing, with cost
    python -m benchmarks.samples --build --sizes 1000,4000 [--jobs 2]

Listing reads only the files' attributes: particles, compaction steps and wall-clock time,
whether the compaction settled, solid fraction. A missing sample is listed with an estimate of
its compaction time from the cached ones (time per particle per step, and steps growing with
the sample's height, as measured from 1000 to 4000).
"""

from __future__ import annotations

import argparse
import os

HERE = os.path.dirname(os.path.abspath(__file__))

from benchmarks.fidelity.runs import Run, make_sample

SIZES = (1000, 4000, 14_400)
SHAPES = ("pentagon", "disk")


def describe(path):
    """Attributes of a cached sample: steps, seconds, settled, solid fraction."""
    import netCDF4
    import numpy as np

    with netCDF4.Dataset(path) as nc:
        steps = int(getattr(nc, "compaction_steps", -1))
        seconds = float(getattr(nc, "compaction_seconds", np.nan))
        settled = bool(getattr(nc, "compaction_settled", 0))
        n = len(nc.dimensions["particle"])
    import grainview

    ds = grainview.open_dataset(path, chunks=None)
    phi = float(ds.grain.solid_fraction().isel(time=-1))
    return {"particles": n, "steps": steps, "seconds": seconds, "settled": settled, "solid fraction": phi}


def estimate(shape, particles, known):
    """Compaction time (s) of a missing sample, extrapolated from the largest cached one of the
    shape: time per particle per step held, steps scaled with sqrt(N) (the box height)."""
    cached = [d for (s, n), d in known.items() if s == shape and d is not None]
    if not cached:
        return None
    ref = max(cached, key=lambda d: d["particles"])
    per = ref["seconds"] / (ref["particles"] * ref["steps"])
    steps = ref["steps"] * (particles / ref["particles"]) ** 0.5
    return per * particles * steps


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", default=",".join(map(str, SIZES)))
    parser.add_argument("--shapes", default=",".join(SHAPES))
    parser.add_argument("--build", action="store_true", help="compact the missing samples")
    parser.add_argument("--jobs", type=int, default=2, help="samples compacted at once (default 2)")
    args = parser.parse_args(argv)
    sizes = [int(s) for s in args.sizes.split(",")]
    shapes = args.shapes.split(",")
    runs = [Run(shape=shape, particles=n) for shape in shapes for n in sizes]
    if args.build:
        from concurrent.futures import ProcessPoolExecutor

        missing = [r for r in runs if not os.path.exists(r.sample_path())]
        with ProcessPoolExecutor(max_workers=args.jobs) as pool:
            list(pool.map(make_sample, missing))
    known = {(r.shape, r.particles): describe(r.sample_path()) if os.path.exists(r.sample_path()) else None
             for r in runs}
    print("| sample | steps | compaction time | settled | solid fraction | file |")
    print("|---|---|---|---|---|---|")
    for r in runs:
        d = known[(r.shape, r.particles)]
        if d is None:
            guess = estimate(r.shape, r.particles, known)
            cost = "-" if guess is None else f"~{guess / 3600:.1f} h on one core (estimate)"
            print(f"| {r.particles} {r.shape}s | - | missing: {cost} | - | - | `--build` |")
        else:
            print(f"| {d['particles']} {r.shape}s | {d['steps']:,} | {d['seconds']:.0f} s | "
                  f"{'yes' if d['settled'] else 'NO'} | {d['solid fraction']:.3f} | "
                  f"{os.path.relpath(r.sample_path(), os.getcwd())} |")


if __name__ == "__main__":
    main()
