"""Does passing records instead of loose arrays change the time of contact detection?

    python benchmarks/archive/detection_records.py --build            # the dense samples, once
    python benchmarks/archive/detection_records.py --label new >> turns.jsonl
    PYTHONPATH=/path/to/older/checkout python benchmarks/archive/detection_records.py --label base >> turns.jsonl
    python benchmarks/archive/detection_records.py --table turns.jsonl

Run as a file (not with ``python -m``), so that ``PYTHONPATH`` chooses the solver that is timed:
each turn prints one JSON line naming the solver it imported. Alternate the two versions, turn
by turn, so that the machine's drift falls on both alike; ``--table`` gives, per stage and
label, the median of the turns and their range.

Samples (``--build``; benchmarks/_data/detection/, not committed): 4000 pentagons, 4000 disks
and 100 pentagons of the paper's size mix (solver.compaction_sample, seed 0), compacted by the
pushed walls (sigma0 = 10 kPa) capped at 0.5 m/s for ``--steps`` steps: a dense packing (solid
fraction about 0.82 at 4000, about 10,400 contact points for the pentagons) with its walls, alert
and skin. In each turn, each sample, ``--calls`` calls of each stage after three unmeasured ones,
the median in ms:

- broad: :func:`solver.broadphase.candidate_pairs` and :func:`~solver.broadphase.wall_candidates`
  at alert + skin (the stepper's margin);
- narrow, narrow x2: :func:`solver.narrowphase.detect` of those candidates at the alert distance,
  on one thread and on two;
- deposit (4000 pentagons only): :func:`solver.packing.deposit` of the same particles.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import time

import numpy as np

DATA = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "_data", "detection")
SAMPLES = (("pentagon", 4000), ("disk", 4000), ("pentagon", 100))


def _path(shape, n):
    return os.path.join(DATA, f"{shape}_{n}.npz")


def build(steps):
    """Compact each sample of :data:`SAMPLES` for ``steps`` steps and save it (module doc)."""
    import warnings

    from solver import compaction_sample

    os.makedirs(DATA, exist_ok=True)
    for shape, n in SAMPLES:
        sim = compaction_sample(n, shape, seed=0, max_wall_speed=0.5)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            for _ in range(steps):
                sim.step()
        points = sim.detect()
        lo, hi = sim.walls.box_bounds()
        print(f"{shape} {n}: solid fraction {np.sum(sim.shapes.area) / np.prod(hi - lo):.3f}, "
              f"{len(points.gap)} contact points")
        np.savez(_path(shape, n), pos=sim.position, angle=sim.angle, radius=sim.radius,
                 nvert=sim.shapes.n_vertices, wall_point=sim.walls.point, wall_normal=sim.walls.normal,
                 alert=sim.alert, skin=sim.skin)


def _median_ms(run, calls):
    for _ in range(3):
        run()
    times = []
    for _ in range(calls):
        start = time.perf_counter()
        run()
        times.append(time.perf_counter() - start)
    return 1e3 * statistics.median(times)


def turn(label, calls):
    """One turn over every sample; returns the JSON-ready record."""
    import solver
    from solver import broadphase, narrowphase
    from solver.packing import deposit
    from solver.shapes import Shapes

    out = {"label": label, "solver": os.path.dirname(solver.__file__)}
    for shape, n in SAMPLES:
        s = dict(np.load(_path(shape, n)))
        shapes = Shapes.regular(s["radius"], s["nvert"])
        alert = float(s["alert"])
        margin = alert + float(s["skin"])
        pi, pj = broadphase.candidate_pairs(s["pos"], s["radius"], margin)
        wp, ww = broadphase.wall_candidates(s["pos"], s["radius"], s["wall_point"], s["wall_normal"], margin)
        name = f"{shape} {n}"
        out[f"{name}: broad"] = _median_ms(lambda: (
            broadphase.candidate_pairs(s["pos"], s["radius"], margin),
            broadphase.wall_candidates(s["pos"], s["radius"], s["wall_point"], s["wall_normal"], margin)), calls)
        for threads, stage in ((1, "narrow"), (2, "narrow x2")):
            out[f"{name}: {stage}"] = _median_ms(lambda: narrowphase.detect(
                s["pos"], s["angle"], shapes, s["wall_point"], s["wall_normal"], alert, pi, pj, wp, ww,
                double_alert=alert, threads=threads), calls)
        if (shape, n) == ("pentagon", 4000):
            out[f"{name}: deposit"] = _median_ms(lambda: deposit(n, nvert=5, seed=0), max(calls // 10, 3))
        out[f"{name}: points"] = len(narrowphase.detect(s["pos"], s["angle"], shapes, s["wall_point"],
                                                        s["wall_normal"], alert, pi, pj, wp, ww).gap)
    return out


def table(path):
    """Markdown table of the turns in the JSON-lines file ``path``: per stage and label, the
    median over the turns and their range (ms)."""
    rows = [json.loads(line) for line in open(path) if line.strip()]
    labels = list(dict.fromkeys(r["label"] for r in rows))
    stages = [k for k in rows[0] if k not in ("label", "solver")]
    head = " | ".join(f"{label}: ms (range), {sum(r['label'] == label for r in rows)} turns" for label in labels)
    lines = [f"| stage | {head} | {labels[-1]} / {labels[0]} |", "|---" * (len(labels) + 2) + "|"]
    for stage in stages:
        med = {label: statistics.median(r[stage] for r in rows if r["label"] == label) for label in labels}
        cells = []
        for label in labels:
            values = [r[stage] for r in rows if r["label"] == label]
            cells.append(f"{med[label]:.4g} ({min(values):.4g}-{max(values):.4g})")
        ratio = med[labels[-1]] / med[labels[0]] if med[labels[0]] else float("nan")
        lines.append(f"| {stage} | " + " | ".join(cells) + f" | {ratio:.3f} |")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", action="store_true", help="compact and save the samples")
    parser.add_argument("--steps", type=int, default=2000, help="compaction steps of --build")
    parser.add_argument("--label", default="turn", help="the name of this turn's version")
    parser.add_argument("--calls", type=int, default=30, help="timed calls per stage")
    parser.add_argument("--table", metavar="JSONL", help="print the table of the turns in this file")
    args = parser.parse_args(argv)
    if args.table:
        print(table(args.table))
    elif args.build:
        build(args.steps)
    else:
        print(json.dumps(turn(args.label, args.calls)), flush=True)


if __name__ == "__main__":
    main()
