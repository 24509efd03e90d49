"""What one NLGS sweep costs per contact point, serially and on domains, on captured problems.

    python benchmarks/sweep_cost.py --sample benchmarks/_data/samples/pentagon_14400_fast.pkl
    python benchmarks/sweep_cost.py --sample ... --strips 1,2,4,8,16 --threads 1   # the domains' order, one thread

A sample saved by ``compaction.py --save`` is sheared as the shear benchmarks shear it
(``sweep_bursts.capture``) and the main contact problems of steps ``--first`` onwards are
captured with their warm starts. Each problem is then solved from its warm start for a fixed
number of sweeps (no tolerance) by the plain NLGS and by Anderson-accelerated sweeps (memory 3,
an extrapolation every 2 sweeps, as the shear benchmarks solve), serially and on each count of
``--strips`` domains (``solver.parallel_nlgs``), in ``--threads`` threads. The cost of a sweep
is the difference between ``--sweeps`` + 2 sweeps and 2 sweeps over ``--sweeps`` (set-up
and the first sweeps' transients cancel), per contact point; the table gives the median over
problems of the median over ``--repeats`` repeats.

With one thread and several domains the sweeps visit the points in the decomposition's order
(domain after domain, then their interface) on one core: the test of whether the order, rather
than the second core, makes a domain-decomposed sweep cheaper per point.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
sys.path.insert(0, HERE)

from common import load_sample, markdown_table, write_results  # noqa: E402

KINDS = ("plain", "anderson")
MEMORY, PERIOD = 3, 2


def _layout(caught: dict, domains: int):
    """(problem arrays, mobility arrays, state arrays, point blocks, decomposition or None) of a
    captured problem, laid out for ``domains`` domains (1: as captured)."""
    from solver import parallel_nlgs

    problem = caught["problem"]
    state = [caught[k].copy() for k in ("pn", "pt", "vx", "vy", "w")]
    if domains == 1:
        geometry = tuple(np.ascontiguousarray(getattr(problem, k)) for k in
                         ("a", "b", "nx", "ny", "rax", "ray", "rbx", "rby", "bias", "mu"))
        masses = tuple(np.ascontiguousarray(getattr(problem, k)) for k in ("minv_xx", "minv_xy", "minv_yy", "iinv"))
        return geometry, masses, tuple(state), np.array([0, problem.a.size]), None
    dec = parallel_nlgs.decompose(problem, caught["position"][:, 0], domains)
    geometry, masses, state = dec.gather(problem, *state)
    contiguous = [tuple(np.ascontiguousarray(v) for v in part) for part in (geometry, masses, state)]
    return contiguous[0], contiguous[1], contiguous[2], dec.blocks, dec


def sweep_seconds(caught: dict, domains: int, kind: str, sweeps: int, repeats: int) -> float:
    """Seconds per sweep of ``kind`` sweeps (``plain`` or ``anderson``) on a captured problem
    laid out for ``domains`` domains: the median over ``repeats`` of (time of sweeps + 2 sweeps
    minus time of 2 sweeps) / sweeps."""
    from solver import acceleration, nlgs, parallel_nlgs

    geometry, masses, state, blocks, dec = _layout(caught, domains)
    work = np.empty(acceleration.scratch_size(geometry[0].size, state[2].size, MEMORY))

    def run(count):
        s = tuple(v.copy() for v in state)
        start = time.perf_counter()
        if kind == "anderson":
            acceleration.solve_anderson(blocks, *geometry, *s, *masses, 0.0, 0.0, count, MEMORY, PERIOD, 0, work)
        elif dec is None:
            nlgs.solve(*geometry, *s, *masses, 0.0, 0.0, count, False, 0, 0)
        else:
            parallel_nlgs.solve_domains(dec.ptr, dec.points, dec.interface, *geometry, *s, *masses, 0.0, 0.0, count,
                                        0)
        return time.perf_counter() - start

    run(2)  # compiled or loaded from the cache
    return float(np.median([(run(sweeps + 2) - run(2)) / sweeps for _ in range(repeats)]))


def measure(problems: list, strips: list, sweeps: int, repeats: int) -> dict:
    """ns per point and sweep, {(kind, domains): median over problems}."""
    out = {}
    for kind in KINDS:
        for domains in strips:
            per_point = [1e9 * sweep_seconds(c, domains, kind, sweeps, repeats) / c["problem"].a.size
                         for c in problems]
            out[kind, domains] = float(np.median(per_point))
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sample", required=True, help="a pickled compacted sample (compaction.py --save)")
    parser.add_argument("--first", type=int, default=100, help="the first captured shear step (default 100)")
    parser.add_argument("--count", type=int, default=8, help="problems captured (default 8)")
    parser.add_argument("--sweeps", type=int, default=40, help="sweeps timed per solve (default 40)")
    parser.add_argument("--repeats", type=int, default=3, help="repeats per problem (default 3)")
    parser.add_argument("--strips", default="1,2", help="domain counts (default 1,2)")
    parser.add_argument("--threads", type=int, default=2, help="numba threads (default 2)")
    parser.add_argument("--out", help="the results file (default: printed only)")
    args = parser.parse_args(argv)
    if not os.path.exists(args.sample):
        raise SystemExit(f"sweep_cost.py: no sample at {args.sample}: make one with compaction.py --save")
    import numba

    from sweep_bursts import capture

    numba.set_num_threads(args.threads)
    sim, _ = load_sample(args.sample)
    n = sim.n_particles
    problems = capture(sim, args.first, args.first + args.count - 1)
    strips = [int(d) for d in args.strips.split(",")]
    result = measure(problems, strips, args.sweeps, args.repeats)
    points = int(np.median([c["problem"].a.size for c in problems]))
    rows = []
    for domains in strips:
        row = [domains]
        for kind in KINDS:
            ns = result[kind, domains]
            row.append(f"{ns:.2f}" + (f" ({result[kind, strips[0]] / ns:.2f}x)" if domains != strips[0] else ""))
        rows.append(row)
    table = markdown_table(["domains", "plain NLGS: ns per point-sweep", "Anderson (m = 3, every 2 sweeps): "
                            "ns per point-sweep"], rows)
    intro = (f"`python benchmarks/sweep_cost.py --sample {os.path.basename(args.sample)} --first {args.first} "
             f"--count {args.count} --sweeps {args.sweeps} --repeats {args.repeats} --strips {args.strips} "
             f"--threads {args.threads}`: "
             f"{n} particles, {len(problems)} problems of about {points} points, {args.threads} thread(s); "
             "the speed-up is over the first domain count.")
    if args.out:
        write_results(args.out, f"Cost of an NLGS sweep per contact point: {n} particles", intro, [table])
    else:
        print(intro + "\n\n" + table)


if __name__ == "__main__":
    main()
