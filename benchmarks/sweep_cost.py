"""What one NLGS sweep costs per contact point, serially and on domains, on captured problems.

    python -m benchmarks.sweep_cost --sample benchmarks/_data/samples/pentagon_14400_fast.pkl
    python -m benchmarks.sweep_cost --sample ... --strips 1,2,4,8,16 --threads 1   # the domains' order, one thread

A sample saved by ``compaction.py --save`` is sheared as the shear benchmarks shear it
(``benchmarks.shear.capture``) and the main contact problems of steps ``--first`` onwards are
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

``--stages``: the serial Anderson solve taken apart instead. The same iteration as
:func:`solver.acceleration.solve_anderson` (no stopping test), driven from Python, calls the
solver's own kernels one by one and times each: the sweep, the points' and the bodies' history
passes, the small least-squares solve, the extrapolation of the bodies' velocities and of the
points' impulses (with its projection onto the Coulomb cones); ns per point, per sweep or per
extrapolation, and the share of points the projection moved. Each kernel is called once on the
first problem before the timing (loading compiled code); each timed call includes its dispatch
from Python, a few microseconds that the solver's own loop does not pay (most of the least
squares' time).
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))

from benchmarks.common import load_sample, markdown_table, write_results

KINDS = ("plain", "anderson")
MEMORY, PERIOD = 3, 2


def _layout(caught: dict, domains: int):
    """(problem, impulses, velocities, point blocks, decomposition or None) of a captured
    problem (records of :mod:`solver.solve_records`, contiguous arrays), laid out for
    ``domains`` domains (1: as captured)."""
    from solver import parallel_nlgs
    from solver.solve_records import Impulses, Velocities

    problem = caught["problem"]
    state = [caught[k].copy() for k in ("pn", "pt", "vx", "vy", "w")]
    if domains == 1:
        problem = type(problem)(*(np.ascontiguousarray(v) for v in problem))
        return problem, Impulses(*state[:2]), Velocities(*state[2:]), np.array([0, problem.a.size]), None
    dec = parallel_nlgs.decompose(problem, caught["position"][:, 0], domains)
    renumbered, impulses, velocities = dec.gather(problem, *state)
    return renumbered, impulses, velocities, dec.blocks, dec


def sweep_seconds(caught: dict, domains: int, kind: str, sweeps: int, repeats: int) -> float:
    """Seconds per sweep of ``kind`` sweeps (``plain`` or ``anderson``) on a captured problem
    laid out for ``domains`` domains: the median over ``repeats`` of (time of sweeps + 2 sweeps
    minus time of 2 sweeps) / sweeps."""
    from solver import acceleration, nlgs, parallel_nlgs
    from solver.solve_records import Limits

    problem, impulses, velocities, blocks, dec = _layout(caught, domains)
    work = np.empty(acceleration.scratch_size(problem.a.size, velocities.vx.size, MEMORY))

    def run(count):
        p, v = type(impulses)(*(x.copy() for x in impulses)), type(velocities)(*(x.copy() for x in velocities))
        limits = Limits(0.0, 0.0, count, 0)
        start = time.perf_counter()
        if kind == "anderson":
            acceleration.solve_anderson(blocks, problem, p, v, limits, MEMORY, PERIOD, work)
        elif dec is None:
            nlgs.solve(problem, p, v, limits, False, 0)
        else:
            parallel_nlgs.solve_domains(dec.ptr, dec.points, dec.interface, problem, p, v, limits)
        return time.perf_counter() - start

    run(2)  # compiled or loaded from the cache
    return float(np.median([(run(sweeps + 2) - run(2)) / sweeps for _ in range(repeats)]))


MIN_STAGE_SWEEPS = 2 * PERIOD + 1
"""The fewest sweeps for which a --stages solve can extrapolate (the first history pass has no
predecessor)."""
STAGES = ("sweep", "point history", "body history", "least squares", "extrapolation, bodies",
          "extrapolation, points")


def stage_seconds(caught: dict, sweeps: int) -> tuple:
    """A serial Anderson solve (memory 3, an extrapolation every 2 sweeps) of a captured
    problem, driven kernel by kernel and timed.

    Parameters
    ----------
    caught : dict
        A problem of ``benchmarks.shear.capture``.
    sweeps : int
        Sweeps of the solve (no tolerance).

    Returns
    -------
    seconds : dict
        Seconds in each of :data:`STAGES`.
    passes : tuple of int
        (history passes, extrapolations).
    moved : int
        Points whose extrapolated impulse the projection onto the Coulomb cone changed, summed
        over the extrapolations.
    impulses : tuple of ndarray
        The final (p_n, p_t): those of :func:`solver.acceleration.solve_anderson` run for as
        many sweeps without a tolerance.
    """
    from solver import acceleration as anderson, nlgs

    problem, impulses, velocities, _, _ = _layout(caught, 1)
    pn, pt = impulses
    m, n_bodies = problem.a.size, velocities.vx.size
    work = np.zeros(anderson.scratch_size(m, n_bodies, MEMORY))
    scratch, blocks = anderson.scratch_records(work, m, n_bodies, MEMORY)
    nlgs.delassus_into(problem, blocks)
    nlgs.velocities_from_impulses(problem, impulses, velocities)
    order = np.arange(m)
    gram, row, rhs = scratch.gram, scratch.row, scratch.rhs
    fn, ft = scratch.fn, scratch.ft
    scratch.xn[:], scratch.xt[:] = pn, pt
    seconds = dict.fromkeys(STAGES, 0.0)
    have_prev, count, head, last, histories, extrapolations, moved = False, 0, 0, np.inf, 0, 0, 0

    def timed(stage, function, *args):
        start = time.perf_counter()
        out = function(*args)
        seconds[stage] += time.perf_counter() - start
        return out

    for it in range(1, sweeps + 1):
        timed("sweep", nlgs.sweep, order, problem, impulses, velocities, blocks)
        if it % PERIOD or it == sweeps:  # as solve_anderson: the last sweep's iterate is kept
            continue
        slot = head if have_prev else -1
        used = min(count + 1, MEMORY) if have_prev else 0
        row[:], rhs[:] = 0.0, 0.0
        size = timed("point history", anderson._point_history, 0, m, slot, used, impulses, scratch, row, rhs)
        timed("body history", anderson._body_history, 0, n_bodies, slot, velocities, scratch)
        histories += 1
        have_prev = True
        if size > last or slot < 0:
            count, head, last = 0, 0, size
            continue
        last, count, head = size, used, (head + 1) % MEMORY
        gram[slot, :count] = row[:count]
        gram[:count, slot] = row[:count]
        gamma, ok = timed("least squares", anderson._small_solve, gram, rhs, count)
        if not ok:
            count, head = 0, 0
            continue
        timed("extrapolation, bodies", anderson._extrapolate_bodies, 0, n_bodies, gamma, count, velocities, scratch)
        timed("extrapolation, points", anderson._extrapolate_points, 0, m, gamma, count, problem, impulses,
              velocities, scratch)
        extrapolations += 1
        moved += int(np.count_nonzero((fn != pn) | (ft != pt)))  # fn, ft: the extrapolation before its projection
    return seconds, (histories, extrapolations), moved, (pn, pt)


def stages_table(problems: list, sweeps: int) -> str:
    """Markdown: ns per point of each stage of :func:`stage_seconds`, summed over the problems
    after a first untimed solve of the first one."""
    stage_seconds(problems[0], sweeps)  # compiled code loaded
    total, counts, moved, points = dict.fromkeys(STAGES, 0.0), dict(sweep=0, history=0, extrapolation=0), 0, 0
    for c in problems:
        seconds, (h, e), mv, _ = stage_seconds(c, sweeps)
        for k in STAGES:
            total[k] += seconds[k] * 1e9 / c["problem"].a.size
        counts["sweep"] += sweeps
        counts["history"] += h
        counts["extrapolation"] += e
        moved += mv
        points += c["problem"].a.size * e
    per = {k: ("sweep" if k == "sweep" else "history" if "history" in k else "extrapolation") for k in STAGES}
    rows = [[k, f"{total[k] / counts[per[k]]:.2f}" if counts[per[k]] else "-", f"per {per[k]} ({counts[per[k]]})"]
            for k in STAGES]
    rows.append(["points moved by the projection", f"{100 * moved / points:.1f}%" if points else "-",
                 "per extrapolation"])
    return markdown_table(["stage", "ns per point", "per (how many)"], rows)


def measure(problems: list, strips: list, sweeps: int, repeats: int) -> dict:
    """ns per point and sweep, {(kind, domains): median over problems}."""
    out = {}
    for kind in KINDS:
        for domains in strips:
            per_point = [1e9 * sweep_seconds(c, domains, kind, sweeps, repeats) / c["problem"].a.size
                         for c in problems]
            out[kind, domains] = float(np.median(per_point))
    return out


def _report(out, title, intro, table):
    """Write the results file ``out`` (:func:`common.write_results`), or print when none."""
    if out:
        write_results(out, title, intro, [table])
    else:
        print(intro + "\n\n" + table)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sample", required=True, help="a pickled compacted sample (compaction.py --save)")
    parser.add_argument("--first", type=int, default=100, help="the first captured shear step (default 100)")
    parser.add_argument("--count", type=int, default=8, help="problems captured (default 8)")
    parser.add_argument("--sweeps", type=int, default=40, help="sweeps timed per solve (default 40)")
    parser.add_argument("--repeats", type=int, default=3, help="repeats per problem (default 3)")
    parser.add_argument("--strips", default="1,2", help="domain counts (default 1,2)")
    parser.add_argument("--threads", type=int, default=2, help="numba threads (default 2)")
    parser.add_argument("--stages", action="store_true", help="the serial Anderson solve's stages instead")
    parser.add_argument("--out", help="the results file (default: printed only)")
    args = parser.parse_args(argv)
    import numba

    try:
        strips = [int(d) for d in args.strips.split(",")]
    except ValueError:
        parser.error(f"--strips {args.strips!r}: expected domain counts separated by commas, e.g. 1,2")
    if min(strips) < 1:
        parser.error(f"--strips {args.strips!r}: expected domain counts >= 1")
    if args.count < 1 or args.repeats < 1:
        parser.error(f"--count {args.count}, --repeats {args.repeats}: expected at least 1 each")
    if args.sweeps < (MIN_STAGE_SWEEPS if args.stages else 1):
        parser.error(f"--sweeps {args.sweeps}: expected at least {MIN_STAGE_SWEEPS if args.stages else 1}"
                     f"{' with --stages (the first extrapolation comes after the second history pass)' if args.stages else ''}")
    if not 1 <= args.threads <= numba.config.NUMBA_NUM_THREADS:
        parser.error(f"--threads {args.threads}: expected 1 to {numba.config.NUMBA_NUM_THREADS} (numba's threads)")
    if not os.path.exists(args.sample):
        raise SystemExit(f"sweep_cost.py: no sample at {args.sample}: make one with compaction.py --save")
    from benchmarks.shear import capture

    numba.set_num_threads(args.threads)
    sim, _ = load_sample(args.sample)
    n = sim.n_particles
    problems = capture(sim, args.first, args.first + args.count - 1)
    if args.stages:
        numba.set_num_threads(1)
        table = stages_table(problems, args.sweeps)
        intro = (f"`python -m benchmarks.sweep_cost --sample {os.path.basename(args.sample)} --first {args.first} "
                 f"--count {args.count} --sweeps {args.sweeps} --stages`: {n} particles, the serial Anderson solve "
                 "(memory 3, an extrapolation every 2 sweeps) taken apart.")
        _report(args.out, f"Stages of an Anderson solve: {n} particles", intro, table)
        return
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
    intro = (f"`python -m benchmarks.sweep_cost --sample {os.path.basename(args.sample)} --first {args.first} "
             f"--count {args.count} --sweeps {args.sweeps} --repeats {args.repeats} --strips {args.strips} "
             f"--threads {args.threads}`: "
             f"{n} particles, {len(problems)} problems of about {points} points, {args.threads} thread(s); "
             "the speed-up is over the first domain count.")
    _report(args.out, f"Cost of an NLGS sweep per contact point: {n} particles", intro, table)


if __name__ == "__main__":
    main()
