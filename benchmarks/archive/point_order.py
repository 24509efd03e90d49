"""Does the order of the contact points in memory set the cost of an NLGS sweep at large N?

    python -m benchmarks.archive.point_order --sizes 3600,14400,28800,57600 [--shape disk]

For each size: a deposited sample (solver.compaction_sample, no compaction: the geometric
deposit already touches), three steps, then the contact problem of the fourth step is captured
and one sweep (solver.nlgs.sweep) is timed on it with its points stored (gathered, contiguous)
in four orders: as the solver builds them; sorted by body a then b; by the Morton (Z-order)
key of body a's cell (4 largest radii), then a, b; and a random permutation (the worst case).
The bodies keep their numbering (the deposit's). A last column stores the order as built in
half the bytes (int32 body ids, float32 normals, lever arms and Delassus blocks; impulses and
velocities stay float64). Medians of 5 runs of 40 sweeps each, ns per contact point per sweep,
Delassus set-up excluded; the same problem for every order.
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np



def _morton(ij):
    """Z-order key of 2D integer cell indices (16 bits each)."""
    def spread(v):
        v = v & 0xFFFF
        v = (v | (v << 8)) & 0x00FF00FF
        v = (v | (v << 4)) & 0x0F0F0F0F
        v = (v | (v << 2)) & 0x33333333
        return (v | (v << 1)) & 0x55555555
    return spread(ij[:, 0]) | (spread(ij[:, 1]) << 1)


def measure(n: int, shape: str, repeats: int = 200) -> dict:
    """ns per point-sweep of each order for ``n`` particles of ``shape``."""
    from benchmarks.common import capture_contact_problems
    from solver import nlgs
    from solver.scenes import compaction_sample
    from solver.solve_records import ContactProblem, DelassusBlocks, Impulses, Velocities

    warnings.simplefilter("ignore")
    sim = compaction_sample(n, shape, seed=0)
    for _ in range(3):
        sim.step()
    p, pn, pt, vx, vy, w, _ = capture_contact_problems(sim)[0]
    m = p.a.size

    def per_sweep(perm, narrow=False):
        g = [np.ascontiguousarray(x[perm]) for x in p[:10]]  # the point arrays, a .. mu
        problem = ContactProblem(*g, *p[10:])
        blocks = nlgs.delassus(problem)
        order = np.arange(m)
        if narrow:  # half the bytes: int32 ids, float32 normals, lever arms and Delassus blocks
            order, g[0], g[1] = order.astype(np.int32), g[0].astype(np.int32), g[1].astype(np.int32)
            g[2:8] = [x.astype(np.float32) for x in g[2:8]]
            problem = ContactProblem(*g, *p[10:])
            blocks = DelassusBlocks(*(x.astype(np.float32) for x in blocks))
        args = (order, problem, Impulses(pn[perm].copy(), pt[perm].copy()), Velocities(vx.copy(), vy.copy(), w.copy()),
                blocks)
        nlgs.sweep(*args)
        runs = []
        for _ in range(5):
            start = time.perf_counter()
            for _ in range(repeats // 5):
                nlgs.sweep(*args)
            runs.append((time.perf_counter() - start) / (repeats // 5))
        return 1e9 * float(np.median(runs)) / m

    pos = sim.position[:sim.n_particles]
    ij = np.floor((pos - pos.min(0)) / (4 * float(sim.radius.max()))).astype(np.int64)
    key_a = _morton(ij)[np.minimum(p.a, sim.n_particles - 1)]
    return {"particles": n, "points": m, "as built": per_sweep(np.arange(m)),
            "by body a, b": per_sweep(np.lexsort((p.b, p.a))),
            "Morton cell of a": per_sweep(np.lexsort((p.b, p.a, key_a))),
            "random": per_sweep(np.random.default_rng(0).permutation(m)),
            "as built, 32-bit geometry": per_sweep(np.arange(m), narrow=True),
            "in body order": float(np.mean(np.diff(p.a) >= 0))}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", default="3600,14400,28800,57600")
    parser.add_argument("--shape", default="disk")
    args = parser.parse_args(argv)
    from benchmarks.common import machine_description

    print(machine_description() + "\n")
    orders = ("as built", "by body a, b", "Morton cell of a", "random", "as built, 32-bit geometry")
    print(f"| {args.shape}s | points | " + " | ".join(f"{o} (ns/point-sweep)" for o in orders) + " | consecutive points in body order |")
    print("|---" * (len(orders) + 3) + "|")
    for n in map(int, args.sizes.split(",")):
        r = measure(n, args.shape)
        print(f"| {n:,} | {r['points']:,} | " + " | ".join(f"{r[o]:.1f}" for o in orders)
              + f" | {r['in body order']:.4f} |", flush=True)


if __name__ == "__main__":
    main()
