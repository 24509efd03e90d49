"""The two-level method of benchmarks.research.two_level (NLGS sweeps + one smoothed-aggregation V-cycle on
the truncated face, projection, line search, inside De Saxcé's fixed point on s = mu |u_t|) on
the problems of benchmarks/contact_solvers.py: cycles and seconds to a local-law residual of
1e-4 and 1e-6, against the same cycle without the V-cycle and plain NLGS.

    export NUMBA_NUM_THREADS=1 OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
    nice -n 10 python -m benchmarks.two_level --out benchmarks/results/two-level.md   # every problem (~15 min)
    nice -n 10 python -m benchmarks.two_level --only "pentagons 1000"                # some, printed only

``--out`` rewrites the generated part of the results file and keeps the notes below its marker
(benchmarks.common.NOTES_MARKER).

Needs pyamg (``pip install pyamg``) and the problems of benchmarks/contact_solvers.py in
benchmarks/_data/contact_solvers/ (its docstring says how they are made): Siconos' three 2D
granular-flow problems from r = 0, and the stepper's pentagon problems at 1000, 4000 and 14,400
(three each) from the warm start the stepper gave its NLGS.

Methods, each from the same start, one run per cell:

* ``two-level``: :func:`benchmarks.research.two_level.solve_recorded` as specified (1 NLGS sweep, the
  V-cycle on (T^T W T + 1e-8 diag) d = -g, projection, exact line search, 1 NLGS sweep);
* ``two-level convex``: the same with the smoother that minimises J point by point at the
  cycle's shift (the W_kk-metric projection on the cone: what TNNMG's convergence proof asks of
  the smoother) instead of the Coulomb local solve;
* ``two-level eps 0.3``: the same as ``two-level`` with the coarse system regularised by 0.3
  times its diagonal (a proximal term: the truncated W of a hyperstatic packing is singular);
* ``2 sweeps``: the cycle without the V-cycle (two NLGS sweeps, the residual after each cycle);
* ``nlgs``: ``solve_contact_problem(..., method='nlgs')`` run in chunks of about 5% of the
  sweeps done so far (at least 2), from the impulses the last chunk ended at, the local-law
  residual the solution reports read between chunks; its calls are timed whole.

The two-level runs stop at 1e-6 or after CYCLES cycles (``2 sweeps``: CONTROL_CYCLES), the NLGS
at 1e-6, NLGS_SWEEPS sweeps or NLGS_SECONDS s. Time to a target: the seconds of the cycles up
to the first within it (each cycle's own clock: sweeps, truncated matrix, hierarchy, V-cycle,
line search, residual), plus what the call spent before its first cycle (W as 2x2 blocks).
Setup: the seconds spent building hierarchies and truncated matrices up to the target. Step
lengths: the line search's t of every cycle of the run. Coarse share: the decrease of J (at the
cycle's shift) by the coarse step over its decrease over the cycle.

Then, on the first cycle of ``two-level`` on each pentagon problem, what the coarse step is
made of (``--diagnose``, also part of the full run): the size of T d against r, how much of
it the projection removes, the line search's t and the residual after it, for the one V-cycle
and for the truncated system solved exactly (scipy's sparse LU).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from benchmarks.common import markdown_table, measured, results_text, write_text_keeping_notes
from benchmarks.contact_solvers import problems

TITLE = "A two-level method (TNNMG-style) on the stored contact problems"
INTRO = ("Written by `python -m benchmarks.two_level --out benchmarks/results/two-level.md` (its docstring gives the "
         "methods, the caps and how each cell is timed): cycles (NLGS: sweeps) and seconds to a local-law residual of "
         "1e-4 and 1e-6 from the stored starts, one run per cell; then what the first coarse step is made of on each "
         "pentagon problem.")
TARGETS = (1e-4, 1e-6)
CYCLES = 300
CONTROL_CYCLES = 2500
NLGS_SWEEPS, NLGS_SECONDS = 20_000, 30.0
VARIANTS = {"two-level": {}, "two-level convex": {"smoother": "convex"},
            "two-level eps 0.3": {"regularisation": 0.3}, "2 sweeps": {"coarse": False}}


def run_variant(W, q, mu, initial, options):
    """A row for one two-level variant (module docstring)."""
    from benchmarks.research.two_level import solve_recorded

    cap = CONTROL_CYCLES if options.get("coarse", True) is False else CYCLES
    start = time.perf_counter()
    result = solve_recorded(W, q, mu, TARGETS[-1], cap, initial, **options)
    wall = time.perf_counter() - start
    cycles = result.cycles
    before = wall - sum(c.seconds for c in cycles)
    clock = before + np.cumsum([c.seconds for c in cycles])
    setup = np.cumsum([c.setup_seconds for c in cycles])
    reached = {}
    for target in TARGETS:
        hit = next((i for i, c in enumerate(cycles) if c.residual <= target), None)
        if result.initial_residual <= target:
            reached[target] = (0, 0.0, 0.0)
        elif hit is not None:
            reached[target] = (hit + 1, float(clock[hit]), float(setup[hit]))
    steps = np.array([c.step for c in cycles])
    steps = steps[np.isfinite(steps)]
    shares = np.array([c.coarse_share for c in cycles])
    return dict(cycles=len(cycles), seconds=wall, reached=reached,
                best=min([result.initial_residual] + [c.residual for c in cycles]),
                final=cycles[-1].residual if cycles else result.initial_residual,
                builds=result.builds, setup=float(setup[-1]) if cycles else 0.0,
                step_median=float(np.median(steps)) if steps.size else np.nan,
                step_long=float(np.mean(steps > 0.1)) if steps.size else np.nan,
                share_median=float(np.nanmedian(shares)) if np.any(np.isfinite(shares)) else np.nan,
                cycle_seconds=float(np.median([c.seconds for c in cycles])) if cycles else np.nan)


def run_nlgs(W, q, mu, initial):
    """The ``nlgs`` row (module docstring): sweeps counted as cycles."""
    from solver.contact_problem import solve_contact_problem
    from solver.contact_solution import local_law_residual, natural_map

    r = initial.copy()
    sweeps, seconds = 0, 0.0
    residual = local_law_residual(natural_map(W, q, mu, r)[0], r)
    best, reached = residual, {}
    for target in TARGETS:
        if residual <= target:
            reached[target] = (0, 0.0, 0.0)
    while residual > TARGETS[-1] and sweeps < NLGS_SWEEPS and seconds < NLGS_SECONDS:
        chunk = max(2, sweeps // 20)
        start = time.perf_counter()
        solution = solve_contact_problem(W, q, mu, method="nlgs", tolerance=1e-300, max_iterations=chunk, initial=r)
        seconds += time.perf_counter() - start
        sweeps += chunk
        r, residual = solution.impulse, solution.local_law_residual
        best = min(best, residual)
        for target in TARGETS:
            if residual <= target and target not in reached:
                reached[target] = (sweeps, seconds, 0.0)
    return dict(cycles=sweeps, seconds=seconds, reached=reached, best=best, final=residual, builds=0, setup=0.0,
                step_median=np.nan, step_long=np.nan, share_median=np.nan, cycle_seconds=np.nan)


def diagnose(W, q, mu, initial):
    """What the first coarse step of ``two-level`` is made of (module docstring): a dict per way
    of solving the truncated system."""
    import pyamg
    from scipy.sparse.linalg import splu

    from benchmarks.contact_solvers import as_matrix_problem, law, nlgs_sweeps
    from benchmarks.research import two_level

    n = mu.size
    r = initial.copy()
    u = (W @ r.reshape(-1) + q).reshape(n, 2)
    shift = mu * np.abs(u[:, 1])
    rn, rt = r[:, 0].copy(), r[:, 1].copy()
    nlgs_sweeps(as_matrix_problem(W, q, mu), rn, rt, 1)
    r = np.stack([rn, rt], -1)
    u = (W @ r.reshape(-1) + q).reshape(n, 2)
    classes = two_level.classify(r, mu)
    basis = two_level.face_basis(classes, mu)
    A, frozen = two_level.Face(W, 1e-8).matrix(basis)
    hierarchy = pyamg.smoothed_aggregation_solver(A, B=np.kron(np.ones((n, 1)), np.eye(2)), max_coarse=50)
    gradient = u + np.stack([shift, np.zeros(n)], -1)
    g = np.einsum("kji,kj->ki", basis, gradient).reshape(-1)
    ways = {"one V-cycle": hierarchy.aspreconditioner(cycle="V") @ (-g)}
    ways["solved exactly (sparse LU)"] = splu(A.tocsc()).solve(-g)
    out = dict(open=int(np.sum(classes == two_level.OPEN)), sticking=int(np.sum(classes == two_level.STICKING)),
               sliding=int(np.sum(np.abs(classes) == two_level.SLIDING)), before=law(W, q, mu, r), ways={})
    for name, d in ways.items():
        d = np.where(frozen, 0.0, d.reshape(n, 2))
        linear = float(np.linalg.norm(A @ d.reshape(-1) + g) / np.linalg.norm(g))
        step = np.einsum("kij,kj->ki", basis, d)
        projected = two_level.project_on_cones(r + step, mu)
        delta = projected - r
        w_delta = W @ delta.reshape(-1)
        slope, curvature = float(delta.reshape(-1) @ gradient.reshape(-1)), float(delta.reshape(-1) @ w_delta)
        t = min(max(-slope / curvature, 0.0), 1.0) if curvature > 0 else float(slope < 0)
        out["ways"][name] = dict(linear=linear, size=float(np.linalg.norm(step) / np.linalg.norm(r)),
                                 removed=float(np.linalg.norm(projected - r - step) / np.linalg.norm(step)),
                                 t=t, after=law(W, q, mu, r + t * delta))
    return out


def cell(row, target):
    hit = row["reached"].get(target)
    if hit is None:
        return f"not reached ({row['cycles']}; best {row['best']:.1e})"
    return f"{hit[0]}, {hit[1]:.3g} s" + (f" (setup {hit[2]:.3g})" if hit[2] else "")


def tables(rows):
    """The Markdown tables of the rows {problem, points, method, ...}."""
    header = ["problem", "points", "method", "to 1e-4: cycles, s", "to 1e-6: cycles, s", "end residual",
              "builds, setup s", "step t: median, share > 0.1", "coarse share of J's decrease (median)",
              "s per cycle (median)"]
    lines = []
    for r in rows:
        lines.append([r["problem"], r["points"], r["method"], cell(r, TARGETS[0]), cell(r, TARGETS[1]),
                      f"{r['final']:.2e}", "" if r["method"] in ("nlgs", "2 sweeps") else
                      f"{r['builds']}, {r['setup']:.3g}",
                      "" if not np.isfinite(r["step_median"]) else f"{r['step_median']:.2f}, {r['step_long']:.2f}",
                      "" if not np.isfinite(r["share_median"]) else f"{r['share_median']:.2f}",
                      "" if not np.isfinite(r["cycle_seconds"]) else f"{r['cycle_seconds']:.3g}"])
    return markdown_table(header, lines)


def diagnosis_table(found):
    header = ["problem", "open, sticking, sliding", "residual before", "coarse solve", "|A d + g| / |g|",
              "|T d| / |r|", "share of T d the projection removes", "t", "residual after"]
    lines = []
    for label, d in found:
        for name, w in d["ways"].items():
            lines.append([label, f"{d['open']}, {d['sticking']}, {d['sliding']}", f"{d['before']:.2e}", name,
                          f"{w['linear']:.2e}", f"{w['size']:.2e}", f"{w['removed']:.2f}", f"{w['t']:.3f}",
                          f"{w['after']:.2e}"])
    return markdown_table(header, lines)


def warm_up():
    """Compile or load every kernel the methods use, on a two-point problem, off the clock."""
    from scipy import sparse

    W = sparse.csr_matrix(np.array([[2.0, 0, 1, 0], [0, 2, 0, 0], [1, 0, 2, 0], [0, 0, 0, 2]]))
    q, mu = np.array([-3.0, 0.5, -3.0, -0.5]), np.full(2, 0.3)
    for options in VARIANTS.values():
        run_variant(W, q, mu, np.zeros((2, 2)), options)
    run_nlgs(W, q, mu, np.zeros((2, 2)))


def measure(chosen):
    warm_up()
    rows, diagnoses = [], []
    for label, W, q, mu, initial in chosen:
        print(f"{label}: {mu.size} points", flush=True)
        for name, options in VARIANTS.items():
            row = run_variant(W, q, mu, initial, options)
            rows.append(dict(row, problem=label, points=mu.size, method=name))
            print(f"  {name}: {cell(row, 1e-4)} | {cell(row, 1e-6)} | step {row['step_median']:.2f}", flush=True)
        row = run_nlgs(W, q, mu, initial)
        rows.append(dict(row, problem=label, points=mu.size, method="nlgs"))
        print(f"  nlgs: {cell(row, 1e-4)} | {cell(row, 1e-6)}", flush=True)
        if label.startswith("pentagons"):
            diagnoses.append((label, diagnose(W, q, mu, initial)))
    return rows, diagnoses


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--only", metavar="LABELS", help="the problems whose label starts with one of these "
                        "(comma-separated, e.g. 'pentagons 1000,Siconos')")
    parser.add_argument("--out", help="write the tables here (Markdown)")
    args = parser.parse_args()
    found = problems()
    if args.only:
        prefixes = tuple(p.strip() for p in args.only.split(","))
        found = [p for p in found if p[0].startswith(prefixes)]
        if not found:
            raise SystemExit(f"--only {args.only}: no problem's label starts with it")
    (rows, diagnoses), run_line = measured(lambda: measure(found))
    text = "\n\n".join([tables(rows), diagnosis_table(diagnoses)])
    print(text)
    if args.out:
        write_text_keeping_notes(args.out, results_text(TITLE, INTRO, [run_line, text]))
