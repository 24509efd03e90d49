"""Proximal-point steps around the semi-smooth Newton (benchmarks.research.proximal_newton, Siconos' PROX) on
the problems of benchmarks/contact_solvers.py, and two zero-code probes of other families on
the pentagon problems: ADMM (OSQP) and an interior point method (Clarabel) on the convex
problem of De Saxcé's fixed point. Written to results/proximal.md; the notes below its marker
(benchmarks.common.NOTES_MARKER) are by hand and kept when the file is rewritten.

    nice -n 10 python -m benchmarks.proximal --out benchmarks/results/proximal.md   # everything (~15 min)
    nice -n 10 python -m benchmarks.proximal --only "pentagons 1000" --no-probes    # some problems, printed
    nice -n 10 python -m benchmarks.proximal --replot --out FILE                    # tables of the last run's rows

The problems are those of benchmarks/contact_solvers.py (its docstring; benchmarks/_data/
contact_solvers/, ignored by git): Siconos' three 2D granular-flow problems from r = 0, the
stepper's captured pentagon problems at 1000, 4000 and 14,400 (three each) from the stepper's
warm start.

**PROX** (:func:`benchmarks.research.proximal_newton.solve_recorded`, its defaults: alpha from 1, x5 on an
inner failure, /10 on a success, inner tolerance e_k / 10), run once per problem to the
tighter target (1e-8, or the NLGS's best of contact-solvers.md's last run where the NLGS
stopped short of 1e-8: DATA/rows.pkl) with at most ``OUTER_CAP`` outer steps and no outer step
begun after ``LU_CAP`` sparse LU factorisations (``SICONOS_LU_CAP`` on Siconos' problems, whose
factorisations are cheap). From its history: the factorisations and seconds to the
first centre within 1e-4 and within the tighter target, the best residual after at most 30
factorisations (the success criterion of docs/solver-research.md, 5.2), and the residual of
every centre. On Siconos' problems the NLGS is timed to the same targets in the same run
(benchmarks.contact_solvers.nlgs_trajectory: sweeps in chunks, the residual off the clock).

**Probes** (pentagons only; ``pip install osqp clarabel``, not dependencies of grainview): with
s = mu |u_t| fixed, the convex problem

    min 1/2 r.W r + (q + s e_n).r   s.t.   mu r_n - r_t >= 0,  mu r_n + r_t >= 0   (r_n >= 0, r_t = 0 where mu = 0)

whose KKT conditions are the cone complementarity of De Saxcé's modified velocity with s held;
s is updated from the solution's u = W r + q (``PROBE_OUTER`` updates at most, from the warm
start's s; stop once the Coulomb problem's residual is within 1e-8). The problem is scaled first
(r = R r', objective over R^2 w, w the mean of diag W, R = rms(q) / w) so that both solvers'
tolerances apply to numbers of order one. OSQP: eps_abs = eps_rel = ``OSQP_EPS``, no polishing,
warm started from the previous outer solution; Clarabel: its default tolerances (1e-8), no
warm start (it has none). Per outer update: the solver's iterations, its seconds (setup
included), its status, and the local-law residual of the ORIGINAL Coulomb problem
(solver.contact_solution) of its r. Memory: the process's peak resident memory over the
solve (VmHWM, reset before it through /proc/self/clear_refs), minus the resident memory before.

One run per cell, the cores shared (nice); every time is wall time.
"""

from __future__ import annotations

import argparse
import os
import pickle
import time

import numpy as np
from scipy import sparse

from benchmarks import contact_solvers as bench
from benchmarks.common import markdown_table

DATA = bench.DATA
ROWS = os.path.join(DATA, "proximal_rows.pkl")
TARGETS = (1e-4, 1e-8)
OUTER_CAP = 200
LU_CAP = 100
SICONOS_LU_CAP = 300
CRITERION_LUS = 30
PROBE_OUTER = 4
PROBE_STOP = 1e-8
OSQP_EPS = 1e-6
OSQP_MAX_ITER = 100_000
PROBE_SECONDS = 240.0
PROBE_PARTICLES = (1000, 4000, 14400)


def nlgs_best(label):
    """The NLGS's best residual of contact-solvers.md's last run for ``label`` (x 1.05), where it
    stopped short of 1e-8; 1e-8 where it reached it or no row is found (DATA/rows.pkl)."""
    path = os.path.join(DATA, "rows.pkl")
    if os.path.exists(path):
        with open(path, "rb") as fh:
            for row in pickle.load(fh):
                if row["problem"] == label and row["method"] == "nlgs" and row["target"] == TARGETS[-1]:
                    return float(row["effective"])
    return TARGETS[-1]


def first_within(history, target):
    """(factorisations, seconds, outer steps) to the first centre of ``history``
    (benchmarks.research.proximal_newton.ProximalHistory) within ``target``; None if none is."""
    lus = np.concatenate([[0], np.cumsum(history.factorisations)])
    for k, e in enumerate(history.residuals):
        if e <= target:
            return int(lus[k]), float(history.seconds[k]), k
    return None


def best_within_lus(history, lus):
    """The smallest residual of the centres reached with at most ``lus`` factorisations."""
    cumulative = np.concatenate([[0], np.cumsum(history.factorisations)])
    return float(min(e for e, c in zip(history.residuals, cumulative) if c <= lus))


def prox_row(label, W, q, mu, initial):
    """One PROX run on a problem (module docstring): a row dict."""
    from benchmarks.research.proximal_newton import solve_recorded

    tight = nlgs_best(label)
    cap = SICONOS_LU_CAP if label.startswith("Siconos") else LU_CAP
    solution, history = solve_recorded(W, q, mu, tight, OUTER_CAP, initial.copy(), max_factorisations=cap)
    row = dict(problem=label, points=mu.size, target=tight, start=history.residuals[0],
               final=solution.local_law_residual, outer=history.outer_steps, lus=history.total_factorisations,
               newton=int(sum(history.newton_steps)), seconds=history.seconds[-1],
               at_criterion=best_within_lus(history, CRITERION_LUS), history=history._asdict())
    for name, target in (("loose", TARGETS[0]), ("tight", tight)):
        row[name] = first_within(history, target)
    if label.startswith("Siconos"):
        trajectory = bench.nlgs_trajectory(W, q, mu, initial, stop=tight)
        row["nlgs"] = {name: bench.first_reached(trajectory, target)
                       for name, target in (("loose", TARGETS[0]), ("tight", tight))}
        row["nlgs_best"] = min(res for _, _, res in trajectory)
    print(f"{label}: PROX {row['outer']} outer steps, {row['lus']} LUs, {row['seconds']:.1f} s, "
          f"{row['start']:.2e} -> {row['final']:.2e} (to 1e-4: {row['loose']}; to {tight:.1e}: {row['tight']}; "
          f"best within {CRITERION_LUS} LUs {row['at_criterion']:.2e})", flush=True)
    return row


# -- the probes ----------------------------------------------------------------------------

def _memory():
    """(VmRSS, VmHWM) of this process in MiB; (nan, nan) where /proc is not there."""
    values = {}
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith(("VmRSS", "VmHWM")):
                    values[line.split(":")[0]] = int(line.split()[1]) / 1024
    except OSError:
        return float("nan"), float("nan")
    return values.get("VmRSS", float("nan")), values.get("VmHWM", float("nan"))


def _reset_peak():
    """Reset the process's peak resident memory to its current one (Linux >= 4.0); False if not."""
    try:
        with open("/proc/self/clear_refs", "w") as fh:
            fh.write("5")
        return True
    except OSError:
        return False


def cone_constraints(mu):
    """(A (m, 2n) CSC, zero rows, nonnegative rows): A r >= 0 row by row for the points with mu > 0
    (mu r_n - r_t, mu r_n + r_t), and r_t = 0 (zero rows, listed first), r_n >= 0 for mu = 0."""
    n = mu.size
    rough, smooth = np.flatnonzero(mu > 0), np.flatnonzero(mu <= 0)
    rows, cols, vals = [], [], []
    # zero rows: r_t = 0 at the frictionless points
    rows += list(range(smooth.size))
    cols += list(2 * smooth + 1)
    vals += [1.0] * smooth.size
    base = smooth.size
    for sign in (-1.0, 1.0):  # mu r_n + sign r_t >= 0
        at = base + np.arange(rough.size)
        rows += list(at) + list(at)
        cols += list(2 * rough) + list(2 * rough + 1)
        vals += list(mu[rough]) + [sign] * rough.size
        base += rough.size
    at = base + np.arange(smooth.size)  # r_n >= 0 at the frictionless points
    rows += list(at)
    cols += list(2 * smooth)
    vals += [1.0] * smooth.size
    A = sparse.csc_matrix((vals, (rows, cols)), shape=(base + smooth.size, 2 * n))
    return A, smooth.size, 2 * rough.size + smooth.size


def scaled(W, q):
    """(P, R w, R): the problem in numbers of order one (module docstring): P = W / w (CSC) and the
    scale R w (m s-1) that divides the linear term, c = (q + s e_n) / (R w), with w the mean of
    diag W (s kg-1) and R = rms(q) / w (N s), so that r = R r'."""
    w = float(np.mean(W.diagonal()))
    R = float(np.sqrt(np.mean(q * q))) / w
    return (W / w).tocsc(), R * w, R


def probe(name, W, q, mu, initial):
    """De Saxcé's fixed point on s with ``name`` ('osqp' or 'clarabel') solving each convex
    problem (module docstring): a row dict with one entry per outer update."""
    from solver.contact_solution import local_law_residual, natural_map

    try:
        module = __import__(name)
    except ImportError:
        raise SystemExit(f"the {name} probe needs the package {name} (pip install osqp clarabel; a benchmark's "
                         "extra, not a dependency of grainview)") from None
    n = mu.size
    P, scale_q, R = scaled(W, q)
    P_upper = sparse.triu(P, format="csc")
    A, zeros, nonnegative = cone_constraints(mu)
    velocity = (W @ initial.reshape(-1) + q).reshape(n, 2)
    s = mu * np.abs(velocity[:, 1])
    x = initial.reshape(-1) / R
    steps, solver_ = [], None
    rss0 = _memory()[0]
    peak_ok = _reset_peak()
    for outer in range(PROBE_OUTER):
        shifted = q.copy()
        shifted[0::2] += s
        c = shifted / scale_q
        start = time.perf_counter()
        if name == "osqp":
            if solver_ is None:
                solver_ = module.OSQP()
                solver_.setup(P_upper, c, A, np.zeros(A.shape[0]), np.r_[np.zeros(zeros), np.full(nonnegative, np.inf)],
                              eps_abs=OSQP_EPS, eps_rel=OSQP_EPS, max_iter=OSQP_MAX_ITER, polishing=False,
                              warm_starting=True, verbose=False, time_limit=PROBE_SECONDS)
                solver_.warm_start(x=x)
            else:
                solver_.update(q=c)
            result = solver_.solve(raise_error=False)  # a time limit reached is a status, not an error
            x, iterations, status = np.asarray(result.x), int(result.info.iter), str(result.info.status)
        else:
            settings = module.DefaultSettings()
            settings.verbose = False
            settings.time_limit = PROBE_SECONDS
            cones = ([module.ZeroConeT(zeros)] if zeros else []) + [module.NonnegativeConeT(nonnegative)]
            solution = module.DefaultSolver(P_upper, c, -A, np.zeros(A.shape[0]), cones, settings).solve()
            x, iterations, status = np.asarray(solution.x), int(solution.iterations), str(solution.status)
        seconds = time.perf_counter() - start
        impulse = (R * x).reshape(n, 2)
        violation, velocity = natural_map(W, q, mu, impulse)
        residual = local_law_residual(violation, impulse)
        s = mu * np.abs(velocity[:, 1])
        steps.append(dict(iterations=iterations, seconds=seconds, status=status, residual=residual))
        print(f"  {name} outer {outer + 1}: {iterations} iterations, {seconds:.2f} s, {status}, "
              f"Coulomb residual {residual:.2e}", flush=True)
        if residual <= PROBE_STOP or status.lower() != "solved":
            break
    rss, hwm = _memory()
    return dict(steps=steps, rss_before=rss0, peak_rise=(hwm - rss0) if peak_ok else float("nan"), peak=hwm)


def probe_rows(found, names=("osqp", "clarabel")):
    """The probes on the first pentagon problem at each of PROBE_PARTICLES present in ``found``."""
    rows = []
    for particles in PROBE_PARTICLES:
        chosen = [p for p in found if p[0] == f"pentagons {particles} #1"]
        for label, W, q, mu, initial in chosen:
            from solver.contact_solution import local_law_residual, natural_map

            start = local_law_residual(natural_map(W, q, mu, initial)[0], initial)
            for name in names:
                print(f"{label}: {name}", flush=True)
                rows.append(dict(problem=label, points=mu.size, solver=name, start=start,
                                 **probe(name, W, q, mu, initial)))
    return rows


# -- tables --------------------------------------------------------------------------------

def _reach(hit):
    return f"{hit[0]} LUs, {hit[1]:.3g} s ({hit[2]} outer)" if hit else "not reached"


def prox_table(rows):
    header = ["problem", "points", "start", "to 1e-4", "tighter target", "to it", f"best in {CRITERION_LUS} LUs",
              "end: residual, outer steps, LUs, Newton steps, s"]
    return markdown_table(header, [[r["problem"], r["points"], f"{r['start']:.1e}", _reach(r["loose"]),
                                    f"{r['target']:.1e}", _reach(r["tight"]), f"{r['at_criterion']:.1e}",
                                    f"{r['final']:.1e}, {r['outer']}, {r['lus']}, {r['newton']}, "
                                    f"{r['seconds']:.3g}"] for r in rows])


def nlgs_table(rows):
    def cell(hit):
        return f"{hit[0]} sweeps, {hit[1]:.3g} s" if hit else "not reached"

    header = ["problem", "NLGS to 1e-4", "NLGS to the tighter target", "PROX to 1e-4", "PROX to the tighter target",
              "PROX / NLGS time, tighter target"]
    out = []
    for r in rows:
        if "nlgs" not in r:
            continue
        ratio = (f"{r['tight'][1] / r['nlgs']['tight'][1]:.2g}" if r["tight"] and r["nlgs"]["tight"] else "-")
        out.append([r["problem"], cell(r["nlgs"]["loose"]), cell(r["nlgs"]["tight"]), _reach(r["loose"]),
                    _reach(r["tight"]), ratio])
    return markdown_table(header, out)


def histories(rows):
    """One line per problem: the residual of every centre, with alpha and the inner outcome."""
    lines = []
    for r in rows:
        h = r["history"]
        steps = [f"{h['residuals'][0]:.1e}"] + [
            f"{e:.1e}{'' if ok else '*'}" for e, ok in zip(h["residuals"][1:], h["inner_converged"])]
        lines.append(f"* {r['problem']} ({r['lus']} LUs; alpha {h['alphas'][0]:.0e} to "
                     f"{min(h['alphas']) if h['alphas'] else float('nan'):.0e} at its smallest): " + " ".join(steps))
    return "\n".join(lines)


def probe_table(rows):
    header = ["problem", "points", "solver", "outer updates", "iterations per update", "seconds per update",
              "statuses", "Coulomb residual per update", "peak memory rise, MiB"]
    out = []
    for r in rows:
        steps = r["steps"]
        out.append([r["problem"], r["points"], r["solver"], len(steps), ", ".join(str(s["iterations"]) for s in steps),
                    ", ".join(f"{s['seconds']:.3g}" for s in steps),
                    ", ".join(sorted({s["status"] for s in steps})),
                    ", ".join(f"{s['residual']:.1e}" for s in steps), f"{r['peak_rise']:.0f}"])
    return markdown_table(header, out)


def write(rows, path):
    """The results file of ``rows`` at ``path``, the notes below its marker kept
    (benchmarks.common.NOTES_MARKER)."""
    from benchmarks.common import machine_description, write_text_keeping_notes

    prox = [r for r in rows if r.get("kind") == "prox"]
    probes = [r for r in rows if r.get("kind") == "probe"]
    text = ["# Proximal-point Newton (PROX) and ADMM / interior-point probes", "",
            "Written by `python -m benchmarks.proximal` (its docstring: the problems, the method, how each cell is "
            "measured).", "", machine_description(), "", "## PROX", "", prox_table(prox), "", nlgs_table(prox), "",
            "Residual of every centre (`*`: the inner Newton did not converge):", "", histories(prox), "",
            "## Probes", "", probe_table(probes), ""]
    write_text_keeping_notes(path, "\n".join(text))


def warm_up():
    """Compile or load the kernels the runs use, off the record."""
    from benchmarks.research.proximal_newton import solve_recorded

    W = sparse.csr_matrix(np.array([[2.0, 0, 1, 0], [0, 2, 0, 0], [1, 0, 2, 0], [0, 0, 0, 2]]))
    q, mu = np.array([-3.0, 0.5, -3.0, -0.5]), np.full(2, 0.3)
    solve_recorded(W, q, mu, 1e-12, 10, np.zeros((2, 2)))
    bench.nlgs_trajectory(W, q, mu, np.zeros((2, 2)), stop=1e-12)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--only", metavar="LABELS", help="only the problems whose label starts with one of these "
                        "(comma-separated, e.g. 'pentagons 1000,Siconos')")
    parser.add_argument("--no-probes", action="store_true", help="PROX only")
    parser.add_argument("--no-prox", action="store_true", help="the probes only")
    parser.add_argument("--replot", action="store_true", help="the tables of the last run's rows (DATA)")
    parser.add_argument("--out", help="write the results file here (default: printed only)")
    args = parser.parse_args()
    if args.replot:
        with open(ROWS, "rb") as fh:
            rows = pickle.load(fh)
    else:
        found = bench.problems()
        if args.only:
            prefixes = tuple(p.strip() for p in args.only.split(","))
            found = [p for p in found if p[0].startswith(prefixes)]
            if not found:
                raise SystemExit(f"--only {args.only}: no problem's label starts with it (labels: "
                                 f"{', '.join(p[0] for p in bench.problems())})")
        warm_up()
        rows = []
        if not args.no_prox:
            rows += [dict(prox_row(*p), kind="prox") for p in found]
        if not args.no_probes:
            rows += [dict(r, kind="probe") for r in probe_rows(found)]
        if not args.only:
            with open(ROWS + ".part", "wb") as fh:
                pickle.dump(rows, fh)
            os.replace(ROWS + ".part", ROWS)
    print(prox_table([r for r in rows if r.get("kind") == "prox"]))
    print(probe_table([r for r in rows if r.get("kind") == "probe"]))
    if args.out:
        write(rows, args.out)
