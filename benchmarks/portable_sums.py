"""What the processor-independent sums of the Anderson history cost: the kernels alone, whole
shear steps and solves of the same captured problems, against the parent commit's reassociated
sums.

    python -m benchmarks.portable_sums --sample benchmarks/_data/samples/pentagon_2000_fast.pkl
    python -m benchmarks.portable_sums --sample ... --variant lanes8=/tmp/acceleration.py   # a candidate too

The sums of :mod:`solver.acceleration`'s history pass, ``_dot2`` (a . b + c . d) and
``_residual`` (f = G(x) - x and |f|^2), add in :data:`LANES <solver.acceleration.LANES>`
interleaved partial sums combined in an order the code writes (the same bits for any vector
width; docs/reproducibility.md); ``_dot2_pair`` takes a history row's Gram term and
right-hand side term in one pass, each in ``_dot2``'s order. Before commit 2875063 they were
one running sum compiled with ``fastmath={"reassoc"}``, which the compiler may vectorise in
any order (``--base``, default b3039cc, that commit's parent).

1. Kernels. The solver's sums ("lanes", now) against the parent's reassociated ones and a
   plain sequential sum (one accumulator, no fastmath), the latter two defined here: ``_dot2``
   on the new row and every row of an ``--memory``-row history; the history pass's Gram row
   and right-hand side (the solver's ``_dot2_pair`` per row, the others' two ``_dot2``
   calls); ``_residual`` on six arrays of a block. Each is called from a compiled loop
   repeated for about ``--seconds`` per timing, at each of ``--sizes`` points (the sizes of a
   block of a 2000- and a 14,400-particle problem); CPU ns per point and sum (the thread's CPU
   clock: a loaded machine's waits left out), in ``--kernel-rounds`` rounds whose order of
   kernels rotates. The rounds' ratio lanes / reassociated gives the median and range. The
   three ``_dot2`` sums' largest relative difference on random data (normal values spread over
   12 decades, as the solver's own order test draws them) says how far apart their roundings
   fall.
2. Whole steps. The sample (``--sample``, a pickled dense packing of
   ``solver_bench.scaling.build_sample``) is sheared as the shear benchmarks shear it
   (:func:`benchmarks.shear.shear`: Anderson every 2 sweeps, the stall test over 200, one
   domain, ``--threads`` numba threads), in a fresh process per run, with this working tree's
   ``solver`` package ("now") and with the same package but for ``solver/acceleration.py`` of
   ``--base`` ("parent"), each a copy under ``--work`` with its own ``NUMBA_CACHE_DIR`` (filled
   by an untimed run first). ``--variant LABEL=FILE`` adds a copy with FILE as its acceleration.py. Steps
   ``--skip`` + 1 .. ``--skip`` + ``--steps`` are timed, the copies in turns (the order
   reversed every other round). The two trajectories part after the first Anderson step (other
   roundings), so the same steps' window holds other contact problems: the table gives the
   sweeps per step of each, and the time per sweep (the solve's time over its sweeps) as well
   as per step. Times are the process's CPU time (``time.process_time``; the stepper's stage
   timings read that clock in these runs), and the window's wall time beside it: on a machine
   shared with other jobs the wall time mostly measures their load. A round's ratio divides its
   two runs, taken one after the other.
3. The same problems. The main contact problems of ``--count`` shear steps from ``--first`` on
   are captured once (this tree's solver) and solved by each copy in a fresh process, in
   rounds as above: the serial Anderson solve for a fixed number of sweeps (``--sweeps``, no
   tolerance; :func:`benchmarks.sweep_cost.sweep_seconds`), and its point-history pass (the
   two sums' pass) and plain sweep from the same solve driven kernel by kernel
   (:func:`benchmarks.sweep_cost.stage_seconds`), CPU ns per point. The work is the same
   but for the roundings of the iterates.

Writes a results file (``--out``; default: printed only).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np
from numba import njit

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
BASE = "b3039cc"
"""The parent of the commit that replaced the reassociated sums (2875063)."""
SIZES = (3000, 6000, 12_000, 25_000, 50_000)
WORK = os.path.join(HERE, "_data", "portable_sums")

from benchmarks.common import markdown_table, measured, write_results  # noqa: E402


# The parent commit's sums (b3039cc:solver/acceleration.py), and the same loops without
# reassociation: one running sum in the order of the points.

@njit(cache=True, fastmath={"reassoc"})
def reassociated_dot2(a, b, c, d):
    total = 0.0
    for k in range(a.size):
        total += a[k] * b[k] + c[k] * d[k]
    return total


@njit(cache=True, fastmath={"reassoc"})
def reassociated_residual(gn, gt, xn, xt, fn, ft):
    size = 0.0
    for k in range(gn.size):
        a, b = gn[k] - xn[k], gt[k] - xt[k]
        fn[k], ft[k] = a, b
        size += a * a + b * b
        xn[k], xt[k] = gn[k], gt[k]
    return size


@njit(cache=True)
def sequential_dot2(a, b, c, d):
    total = 0.0
    for k in range(a.size):
        total += a[k] * b[k] + c[k] * d[k]
    return total


@njit(cache=True)
def sequential_residual(gn, gt, xn, xt, fn, ft):
    size = 0.0
    for k in range(gn.size):
        a, b = gn[k] - xn[k], gt[k] - xt[k]
        fn[k], ft[k] = a, b
        size += a * a + b * b
        xn[k], xt[k] = gn[k], gt[k]
    return size


# The loops that time them: the history pass's calls, repeated. A loop adds into ``out``, which
# may alias the rows as far as the compiler knows, so no call is hoisted out of the repetition.
# One loop per kernel: a kernel passed as an argument would not be cached.

def _lanes():
    from solver import acceleration

    return acceleration


@njit(cache=True)
def _dot2_reassociated(fn, ft, dfn, dft, out, times):
    for _ in range(times):
        for j in range(dfn.shape[0]):
            out[j] += reassociated_dot2(fn, dfn[j], ft, dft[j])


@njit(cache=True)
def _dot2_sequential(fn, ft, dfn, dft, out, times):
    for _ in range(times):
        for j in range(dfn.shape[0]):
            out[j] += sequential_dot2(fn, dfn[j], ft, dft[j])


@njit(cache=True)
def _gram_reassociated(nfn, nft, fn, ft, dfn, dft, row, rhs, times):
    for _ in range(times):
        for j in range(dfn.shape[0]):
            row[j] += reassociated_dot2(nfn, dfn[j], nft, dft[j])
            rhs[j] += reassociated_dot2(fn, dfn[j], ft, dft[j])


@njit(cache=True)
def _gram_sequential(nfn, nft, fn, ft, dfn, dft, row, rhs, times):
    for _ in range(times):
        for j in range(dfn.shape[0]):
            row[j] += sequential_dot2(nfn, dfn[j], nft, dft[j])
            rhs[j] += sequential_dot2(fn, dfn[j], ft, dft[j])


@njit(cache=True)
def _residual_reassociated(gn, gt, xn, xt, fn, ft, times):
    total = 0.0
    for _ in range(times):
        total += reassociated_residual(gn, gt, xn, xt, fn, ft)
    return total


@njit(cache=True)
def _residual_sequential(gn, gt, xn, xt, fn, ft, times):
    total = 0.0
    for _ in range(times):
        total += sequential_residual(gn, gt, xn, xt, fn, ft)
    return total


def _dot2_lanes_loop():
    dot2 = _lanes()._dot2

    @njit
    def loop(fn, ft, dfn, dft, out, times):
        for _ in range(times):
            for j in range(dfn.shape[0]):
                out[j] += dot2(fn, dfn[j], ft, dft[j])
    return loop


def _gram_lanes_loop():
    pair = _lanes()._dot2_pair

    @njit
    def loop(nfn, nft, fn, ft, dfn, dft, row, rhs, times):
        for _ in range(times):
            for j in range(dfn.shape[0]):
                gram, right = pair(nfn, nft, dfn[j], dft[j], fn, ft)
                row[j] += gram
                rhs[j] += right
    return loop


def _residual_lanes_loop():
    residual = _lanes()._residual

    @njit
    def loop(gn, gt, xn, xt, fn, ft, times):
        total = 0.0
        for _ in range(times):
            total += residual(gn, gt, xn, xt, fn, ft)
        return total
    return loop


KERNELS = ("lanes (now)", "reassociated (parent)", "sequential")
"""The kernels compared, in the table's order; the first is the solver's."""
SUMS = {"dot2": "`_dot2`", "gram": "Gram row and right-hand side", "residual": "`_residual`"}
"""The sums timed and their rows' names: ``_dot2`` alone; the history pass's 2 x memory sums
(the solver's ``_dot2_pair`` per history row, two ``_dot2`` calls of the others); ``_residual``."""


def _short(kernel: str) -> str:
    return kernel.split(" ")[0]


def kernel_loops() -> dict:
    """{(sum, kernel): the compiled loop that repeats it} over :data:`SUMS` and :data:`KERNELS`."""
    return {("dot2", KERNELS[0]): _dot2_lanes_loop(), ("dot2", KERNELS[1]): _dot2_reassociated,
            ("dot2", KERNELS[2]): _dot2_sequential, ("gram", KERNELS[0]): _gram_lanes_loop(),
            ("gram", KERNELS[1]): _gram_reassociated, ("gram", KERNELS[2]): _gram_sequential,
            ("residual", KERNELS[0]): _residual_lanes_loop(), ("residual", KERNELS[1]): _residual_reassociated,
            ("residual", KERNELS[2]): _residual_sequential}


def random_terms(n: int, seed: int):
    """a, b, c, d of ``n`` points: normal values times 10^U(-6, 6), as tests/solver's order test draws them."""
    rng = np.random.default_rng(seed)
    return rng.normal(size=(4, n)) * 10.0 ** rng.uniform(-6, 6, (4, n))


def sums_apart(n: int, seed: int = 0) -> dict:
    """The three ``dot2`` sums of random terms (:func:`random_terms`): each one's relative
    error against the exact sum (``math.fsum``) and the largest relative difference between two
    of them, both relative to the sum of the terms' magnitudes (the scale of a rounding)."""
    a, b, c, d = random_terms(n, seed)
    sums = {KERNELS[0]: _lanes()._dot2(a, b, c, d), KERNELS[1]: reassociated_dot2(a, b, c, d),
            KERNELS[2]: sequential_dot2(a, b, c, d)}
    terms = a * b + c * d
    exact, scale = math.fsum(terms), math.fsum(np.abs(terms))
    values = list(sums.values())
    apart = max(abs(x - y) for x in values for y in values) / scale
    return dict(sums=sums, error={k: abs(v - exact) / scale for k, v in sums.items()}, apart=apart)


def time_kernels(sizes, rounds: int, memory: int, seconds: float, log=print) -> list:
    """Rows {sum, kernel, points, ns (per point and sum, one per round)} of the kernels timed at
    each size, in ``rounds`` rounds (the kernels' order rotating); each timing repeats its call
    about ``seconds``."""
    loops = kernel_loops()
    rows = []
    for n in sizes:
        rng = np.random.default_rng(n)
        nfn, nft, fn, ft = rng.normal(size=(4, n))
        dfn, dft = rng.normal(size=(2, memory, n))
        row, rhs = np.zeros(memory), np.zeros(memory)
        six = rng.normal(size=(6, n))
        args = {"dot2": lambda times: (fn, ft, dfn, dft, row, times),
                "gram": lambda times: (nfn, nft, fn, ft, dfn, dft, row, rhs, times),
                "residual": lambda times: (*six, times)}
        per_call = {"dot2": memory * n, "gram": 2 * memory * n, "residual": n}  # points (of a sum) per repetition
        for s in SUMS:
            mine = [(k, loops[s, k]) for k in KERNELS]
            for _, loop in mine:  # compile or load, and a first estimate of the time per repetition
                loop(*args[s](1))
            start = time.thread_time()
            loops[s, KERNELS[0]](*args[s](3))
            times = max(1, int(seconds / max((time.thread_time() - start) / 3, 1e-9)))
            ns = {k: [] for k in KERNELS}
            for r in range(rounds):
                order = mine[r % len(mine):] + mine[:r % len(mine)]
                for k, loop in order:
                    start = time.thread_time()
                    loop(*args[s](times))
                    ns[k].append(1e9 * (time.thread_time() - start) / (times * per_call[s]))
            rows += [dict(sum=s, kernel=k, points=n, ns=ns[k]) for k in KERNELS]
            log(f"{s} at {n} points: " + ", ".join(f"{k} {statistics.median(ns[k]):.3f}" for k in KERNELS)
                + " ns per point", flush=True)
    return rows


def kernel_table(rows: list, apart: dict) -> str:
    """Markdown: per sum and size, each kernel's median ns per point, and the rounds' ratio of
    lanes to each other kernel (median and range); ``apart`` maps a size to :func:`sums_apart`."""
    out = []
    for s in SUMS:
        for n in sorted({r["points"] for r in rows if r["sum"] == s}):
            ns = {r["kernel"]: r["ns"] for r in rows if r["sum"] == s and r["points"] == n}
            cells = [f"{statistics.median(ns[k]):.3f}" for k in KERNELS]
            for k in KERNELS[1:]:
                ratios = [x / y for x, y in zip(ns[KERNELS[0]], ns[k])]
                cells.append(f"{statistics.median(ratios):.2f} ({min(ratios):.2f}-{max(ratios):.2f})")
            extra = f"{apart[n]['apart']:.1e}" if s == "dot2" and n in apart else ""
            out.append([SUMS[s], f"{n:,}", *cells, extra])
    header = ["sum", "points", *(f"{k}: CPU ns per point" for k in KERNELS),
              *(f"lanes / {_short(k)}: median (range)" for k in KERNELS[1:]),
              "largest difference between the three"]
    return markdown_table(header, out)


# Whole steps, each copy of the solver in processes of its own.

CHILD = r"""
import json, sys, time, types
tree, root, sample, skip, steps = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4]), int(sys.argv[5])
sys.path.insert(0, tree)
sys.path.append(root)
import solver
assert solver.__file__.startswith(tree), solver.__file__
from solver import stepper
assert stepper.time is time
stepper.time = types.SimpleNamespace(perf_counter=time.process_time)  # its stage timings in CPU seconds
from benchmarks.common import load_sample
from benchmarks.shear import Done, shear
sim, _ = load_sample(sample)
done, mark = [0], {}
def before():
    if done[0] == skip:
        mark.update(start=time.perf_counter(), cpu=time.process_time(), sweeps=sim.counters["sweeps"],
                    solve=sim.timings["solve"])
def after(info):
    done[0] += 1
    if done[0] == skip + steps:
        mark.update(end=time.perf_counter(), cpu=time.process_time() - mark["cpu"],
                    sweeps=sim.counters["sweeps"] - mark["sweeps"], solve=sim.timings["solve"] - mark["solve"],
                    points=len(sim.points.gap))
        raise Done
shear(sim, after, before_step=before)
print(json.dumps(dict(seconds=mark["end"] - mark["start"], cpu=mark["cpu"], solve=mark["solve"],
                      sweeps=mark["sweeps"], points=mark["points"], steps=steps, particles=int(sim.n_particles))))
"""
"""A run of whole steps in a fresh process: ``tree`` (a folder holding a ``solver`` package)
first on the path, this repository last (for ``benchmarks``); prints one JSON line: the timed
window's wall and CPU seconds (``time.process_time``) and its solve's CPU seconds (the
stepper's stage timings, whose clock is made the process's CPU clock here)."""


CHILD_SOLVES = r"""
import json, pickle, statistics, sys, time, types
tree, root, path, sweeps, repeats = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4]), int(sys.argv[5])
sys.path.insert(0, tree)
sys.path.append(root)
import solver
assert solver.__file__.startswith(tree), solver.__file__
from benchmarks import sweep_cost
assert sweep_cost.time is time
sweep_cost.time = types.SimpleNamespace(perf_counter=time.process_time)  # its timings in CPU seconds
with open(path, "rb") as fh:
    problems = pickle.load(fh)
solve = [1e9 * sweep_cost.sweep_seconds(c, 1, "anderson", sweeps, repeats) / c["problem"].a.size for c in problems]
sweep_cost.stage_seconds(problems[0], sweeps)  # its kernels loaded
history, sweep = [], []
for c in problems:
    seconds, (passes, _), _, _ = sweep_cost.stage_seconds(c, sweeps)
    history.append(1e9 * seconds["point history"] / (passes * c["problem"].a.size))
    sweep.append(1e9 * seconds["sweep"] / (sweeps * c["problem"].a.size))
print(json.dumps(dict(solve=statistics.median(solve), history=statistics.median(history),
                      sweep=statistics.median(sweep), points=statistics.median(c["problem"].a.size for c in problems))))
"""
"""Anderson solves of captured problems in a fresh process (``tree``'s ``solver``, as
:data:`CHILD`): :func:`benchmarks.sweep_cost.sweep_seconds` (a fixed number of sweeps, no
tolerance) and the point-history pass of :func:`benchmarks.sweep_cost.stage_seconds`, in CPU
time; prints one JSON line of CPU ns per point: per sweep of the solve, per history pass, per
plain sweep (medians over the problems)."""


def _git(*args) -> str:
    return subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True, check=True).stdout


def solver_trees(work: str, base: str = BASE, variants=()) -> dict:
    """{label: folder}: copies of this working tree's ``solver`` package under ``work``, "now"
    as it is, "parent" with ``solver/acceleration.py`` of commit ``base``, and one per
    (label, file) of ``variants`` with that file as its acceleration.py. Each copy keeps its
    files' modification times (the parent's file gets its commit's), so that its numba cache
    (``<folder>/numba``) stays valid across runs while the sources are unchanged."""
    sources = {"now": None, "parent": ("git", base)}
    sources.update({label: ("file", path) for label, path in variants})
    trees = {}
    for label, source in sources.items():
        folder = os.path.join(work, label)
        package = os.path.join(folder, "solver")
        if os.path.exists(package):
            shutil.rmtree(package)
        os.makedirs(folder, exist_ok=True)
        shutil.copytree(os.path.join(ROOT, "solver"), package, ignore=shutil.ignore_patterns("__pycache__"))
        target = os.path.join(package, "acceleration.py")
        if source and source[0] == "git":
            with open(target, "w") as fh:
                fh.write(_git("show", f"{source[1]}:solver/acceleration.py"))
            stamp = int(_git("show", "-s", "--format=%ct", source[1]).strip())
            os.utime(target, (stamp, stamp))
        elif source:
            shutil.copy2(source[1], target)
        trees[label] = folder
    return trees


def _child(code: str, folder: str, args: list, threads: int) -> dict:
    """Run ``code`` with the ``solver`` of ``folder`` in a fresh process whose numba cache is
    ``<folder>/numba``, with ``threads`` numba threads (one domain needs one; a second waits for
    its share of each parallel pass, which a loaded machine delays at random); its JSON line."""
    env = dict(os.environ, NUMBA_CACHE_DIR=os.path.join(folder, "numba"), NUMBA_NUM_THREADS=str(threads))
    done = subprocess.run([sys.executable, "-c", code, folder, ROOT, *map(str, args)], cwd=folder, env=env,
                          capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"the run with {folder} failed:\n{done.stderr[-3000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def run_steps(folder: str, sample: str, skip: int, steps: int, threads: int = 1) -> dict:
    """Shear ``sample`` with the ``solver`` of ``folder`` (:data:`CHILD`); the timed window's record."""
    return _child(CHILD, folder, [os.path.abspath(sample), skip, steps], threads)


def run_solves(folder: str, problems: str, sweeps: int, repeats: int, threads: int = 1) -> dict:
    """Solve the captured problems pickled at ``problems`` with the ``solver`` of ``folder``
    (:data:`CHILD_SOLVES`); CPU ns per point of a sweep of the solve, a history pass, a plain sweep."""
    return _child(CHILD_SOLVES, folder, [os.path.abspath(problems), sweeps, repeats], threads)


def capture_problems(sample: str, first: int, count: int, path: str) -> int:
    """Pickle to ``path`` the main contact problems of shear steps ``first`` .. ``first`` +
    ``count`` - 1 of ``sample`` (:func:`benchmarks.shear.capture`, this tree's solver): the
    same problems for every copy. Returns their median number of points."""
    import pickle

    from benchmarks.common import load_sample
    from benchmarks.shear import capture

    sim, _ = load_sample(sample)
    caught = capture(sim, first, first + count - 1)
    with open(path, "wb") as fh:
        pickle.dump(caught, fh)
    return int(statistics.median(c["problem"].a.size for c in caught))


def time_solves(trees: dict, problems: str, sweeps: int, repeats: int, rounds: int, threads: int = 1,
                log=print) -> list:
    """Rows {label, round, solve, history, sweep, points} (:func:`run_solves`): an untimed run
    per copy, then ``rounds`` rounds of one run per copy, the order reversed every other round."""
    labels = list(trees)
    for label in labels:
        run_solves(trees[label], problems, 2 * MIN_SWEEPS, 1, threads)
    rows = []
    for r in range(rounds):
        for label in (labels if r % 2 == 0 else labels[::-1]):
            rows.append(dict(run_solves(trees[label], problems, sweeps, repeats, threads), label=label, round=r))
            log(f"round {r}, {label}: " + ", ".join(f"{k} {rows[-1][k]:.2f}" for k in ("solve", "history", "sweep"))
                + " CPU ns per point", flush=True)
    return rows


MIN_SWEEPS = 5
"""The fewest sweeps of a solve with an extrapolation (benchmarks.sweep_cost.MIN_STAGE_SWEEPS)."""


def time_steps(trees: dict, sample: str, skip: int, steps: int, rounds: int, threads: int = 1, log=print) -> list:
    """Rows {label, round, seconds, solve, sweeps, points, steps}: an untimed warm-up run per
    copy (compiling into its cache), then ``rounds`` rounds of one run per copy, the order
    reversed every other round."""
    labels = list(trees)
    for label in labels:
        start = time.perf_counter()
        run_steps(trees[label], sample, 0, 2, threads)
        log(f"warm-up of {label}: {time.perf_counter() - start:.0f} s", flush=True)
    rows = []
    for r in range(rounds):
        for label in (labels if r % 2 == 0 else labels[::-1]):
            rows.append(dict(run_steps(trees[label], sample, skip, steps, threads), label=label, round=r))
            got = rows[-1]
            log(f"round {r}, {label}: {1e3 * got['seconds'] / steps:.3f} ms per step, {1e3 * got['cpu'] / steps:.3f} "
                f"CPU ms, {got['sweeps'] / steps:.1f} sweeps per step", flush=True)
    return rows


def steps_table(rows: list) -> str:
    """Markdown: per copy, the median wall ms per step, CPU ms per step (whole and its solve),
    sweeps per step, CPU µs of the solve per sweep and ns per point-sweep, and each ratio to
    "parent" (the rounds' ratios: median and range)."""
    labels = list(dict.fromkeys(r["label"] for r in rows))
    per = {label: [r for r in rows if r["label"] == label] for label in labels}
    measures = {"wall ms per step": lambda r: 1e3 * r["seconds"] / r["steps"],
                "CPU ms per step": lambda r: 1e3 * r["cpu"] / r["steps"],
                "solve, CPU ms per step": lambda r: 1e3 * r["solve"] / r["steps"],
                "solve, CPU µs per sweep": lambda r: 1e6 * r["solve"] / r["sweeps"]}
    out = []
    for label in labels:
        mine = per[label]
        cells = [f"{statistics.median(f(r) for r in mine):.3f}" for f in measures.values()]
        sweeps = statistics.median(r["sweeps"] / r["steps"] for r in mine)
        ns = statistics.median(1e9 * r["solve"] / (r["sweeps"] * r["points"]) for r in mine)
        out.append([label, len(mine), *cells, f"{sweeps:.1f}", f"{ns:.2f}", *_ratio_cells(rows, label, measures)])
    header = ["solver", "runs", *measures, "sweeps per step", "solve, CPU ns per point-sweep",
              *(f"{m}: / parent, median (range)" for m in measures)]
    return markdown_table(header, out)


def _ratio_cells(rows: list, label: str, measures: dict) -> list:
    """The rounds' ratios of ``label``'s rows to "parent"'s of the same round, per measure:
    'median (min-max)', or '' for the parent itself or without one."""
    parent = [r for r in rows if r["label"] == "parent"]
    mine = [r for r in rows if r["label"] == label]
    cells = []
    for f in measures.values():
        pairs = [f(a) / f(b) for a in mine for b in parent if a["round"] == b["round"]]
        cells.append(f"{statistics.median(pairs):.3f} ({min(pairs):.3f}-{max(pairs):.3f})"
                     if pairs and label != "parent" else "")
    return cells


def solves_table(rows: list) -> str:
    """Markdown: per copy, the median CPU ns per point of a sweep of the Anderson solve, of a
    point-history pass and of a plain sweep, and each ratio to "parent" (the rounds' ratios:
    median and range)."""
    labels = list(dict.fromkeys(r["label"] for r in rows))
    measures = {"Anderson solve, per sweep": lambda r: r["solve"], "point history, per pass": lambda r: r["history"],
                "plain sweep": lambda r: r["sweep"]}
    out = []
    for label in labels:
        mine = [r for r in rows if r["label"] == label]
        out.append([label, len(mine), *(f"{statistics.median(f(r) for r in mine):.2f}" for f in measures.values()),
                    *_ratio_cells(rows, label, measures)])
    header = ["solver", "runs", *(f"{m}: CPU ns per point" for m in measures),
              *(f"{m}: / parent, median (range)" for m in measures)]
    return markdown_table(header, out)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sample", required=True, help="a pickled dense sample (solver_bench.scaling.build_sample)")
    parser.add_argument("--base", default=BASE, help=f"the commit whose solver/acceleration.py is 'parent' "
                        f"(default {BASE})")
    parser.add_argument("--variant", action="append", default=[], metavar="LABEL=FILE",
                        help="another acceleration.py to step with (repeatable)")
    parser.add_argument("--sizes", default=",".join(map(str, SIZES)), help="points of the kernels' arrays")
    parser.add_argument("--memory", type=int, default=3, help="history rows of a _dot2 timing (the default memory)")
    parser.add_argument("--seconds", type=float, default=0.05, help="length of a kernel timing (s)")
    parser.add_argument("--kernel-rounds", type=int, default=21, help="rounds of kernel timings")
    parser.add_argument("--skip", type=int, default=100, help="shear steps before the timed ones")
    parser.add_argument("--steps", type=int, default=300, help="shear steps timed")
    parser.add_argument("--rounds", type=int, default=9, help="rounds of whole-step runs")
    parser.add_argument("--threads", type=int, default=1, help="numba threads of a whole-step run (default 1)")
    parser.add_argument("--first", type=int, default=100, help="the first shear step whose problem is captured")
    parser.add_argument("--count", type=int, default=8, help="captured problems")
    parser.add_argument("--sweeps", type=int, default=40, help="sweeps of a solve of a captured problem")
    parser.add_argument("--repeats", type=int, default=7, help="repeats of a solve (their median)")
    parser.add_argument("--work", default=WORK, help="where the copies of the solver and their caches live")
    parser.add_argument("--quick", action="store_true", help="tiny sizes, one round: checks that it runs")
    parser.add_argument("--out", help="the results file (default: print only)")
    args = parser.parse_args(argv)
    if args.quick:
        args.sizes, args.seconds, args.kernel_rounds, args.rounds = "1000,4000", 0.005, 3, 1
        args.skip, args.steps, args.first, args.count, args.sweeps, args.repeats = 5, 10, 5, 2, MIN_SWEEPS, 1
    if not os.path.exists(args.sample):
        raise SystemExit(f"portable_sums.py: no sample at {args.sample}: make one with "
                         "benchmarks.solver_bench.scaling.build_sample")
    sizes = [int(s) for s in args.sizes.split(",")]
    variants = [tuple(v.split("=", 1)) for v in args.variant]

    def run():
        apart = {n: sums_apart(n) for n in sizes}
        kernels = time_kernels(sizes, args.kernel_rounds, args.memory, args.seconds)
        trees = solver_trees(args.work, args.base, variants)
        steps = time_steps(trees, args.sample, args.skip, args.steps, args.rounds, args.threads)
        problems = os.path.join(args.work, "problems.pkl")
        points = capture_problems(args.sample, args.first, args.count, problems)
        solves = time_solves(trees, problems, args.sweeps, args.repeats, args.rounds, args.threads)
        return apart, kernels, steps, solves, points

    (apart, kernels, steps, solves, solve_points), how = measured(run)
    particles, points = steps[0]["particles"], statistics.median(r["points"] for r in steps)
    command = "python -m benchmarks.portable_sums " + " ".join(
        [f"--sample {os.path.basename(args.sample)}"] + (["--quick"] if args.quick else [])
        + [f"--variant {v}" for v in args.variant])
    intro = (f"Made by `{command}` (the module's docstring says what it does): the Anderson history's sums in "
             f"LANES interleaved partial sums (now) against the reassociated single sum of {args.base} (parent). "
             f"The ratios come from one run on a shared machine. {how}")
    errors = "; ".join(f"{n:,} points " + ", ".join(f"{_short(k)} {e:.1e}" for k, e in apart[n]["error"].items())
                       for n in sizes)
    kernel_text = (f"## The kernels alone\n\nCPU ns per point and sum, the median of {args.kernel_rounds} rounds; "
                   f"`_dot2` on the new row and the {args.memory} rows of a history; the history pass's Gram row and "
                   "right-hand side (now `_dot2_pair`, one pass per history row for both sums; the others: two "
                   "`_dot2` calls); `_residual` on one block's six arrays. "
                   "A round's ratio divides two timings of that round. The last column: the largest relative "
                   "difference between two of the three sums of random terms, relative to the sum of the terms' "
                   f"magnitudes (their error against the exact sum: {errors}).\n\n" + kernel_table(kernels, apart))
    steps_text = (f"## Whole steps\n\n{particles} pentagons sheared from the dense sample, steps {args.skip + 1}-"
                  f"{args.skip + args.steps} timed ({points:,.0f} contact points at the end, the median of the runs), "
                  f"one domain and {args.threads} numba thread{'s' if args.threads > 1 else ''}, {args.rounds} "
                  f"round{'s' if args.rounds > 1 else ''} of a fresh process per solver. parent: this tree with "
                  f"`solver/acceleration.py` of {args.base}"
                  + "".join(f"; {label}: with {os.path.basename(path)}" for label, path in variants)
                  + ". Times are CPU time of the process but the first column's. The trajectories differ (other "
                    "roundings), so the sweeps per step do, and so do the problems the sweeps solve: the next table "
                    "solves the same problems.\n\n" + steps_table(steps))
    solves_text = (f"## The same problems\n\nThe main contact problems of shear steps {args.first}-"
                   f"{args.first + args.count - 1} of the sample, captured once with this tree's solver "
                   f"({solve_points:,} points, the median), solved from their warm starts by each copy in a fresh "
                   f"process, {args.rounds} round{'s' if args.rounds > 1 else ''}: the serial Anderson solve "
                   f"(memory 3, an extrapolation every 2 sweeps) for {args.sweeps} + 2 sweeps less 2, per sweep "
                   "(`benchmarks.sweep_cost`), its point-history pass (the sums' pass, every second sweep) and a "
                   f"plain sweep, from the same solve driven kernel by kernel (`sweep_cost --stages`); medians over "
                   f"the problems of the medians of {args.repeats} repeats, CPU time.\n\n" + solves_table(solves))
    title = "Portable sums: what the fixed order of the Anderson history's sums costs"
    if args.out:
        write_results(args.out, title, intro, [kernel_text, steps_text, solves_text])
    else:
        from benchmarks.common import results_text

        print(results_text(title, intro, [kernel_text, steps_text, solves_text]))


if __name__ == "__main__":
    main()
