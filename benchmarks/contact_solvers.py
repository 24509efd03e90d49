"""Every problem-level method of solver.contact_solvers on problems others use and on the
stepper's own: time and iterations to a natural-map residual of 1e-4 and of 1e-8 (or the best
each reaches), a table (results/contact-solvers.md) and a performance profile
(results/contact_solvers_profile.png).

    python -m benchmarks.contact_solvers --fetch-siconos MIRROR   # copy the 2D problems out of a siconos git mirror
    nice -n 10 python -m benchmarks.contact_solvers --build 1000  # capture the stepper's problems (~3 min)
    nice -n 10 python -m benchmarks.contact_solvers --build 4000  # (~10 min)
    nice -n 10 python -m benchmarks.contact_solvers               # solve them all, write the table and figure
    nice -n 10 python -m benchmarks.contact_solvers --degeneracy  # rank and spectrum of the 2020-contact W

The problems (benchmarks/_data/, ignored by git):

* Siconos' 2D frictional-contact problems of a granular flow on a wall
  (``numerics/src/FrictionContact/test/data/fc2d_granularflowonwall_*.dat`` in
  github.com/siconos/siconos; FCLIB's own collection, fclib-library, keeps its files in Git LFS
  and holds no 2D granular set that could be reached): 667, 2020 and 7002 contacts, W printed
  by CSparse (``cs_print``, six significant digits), then q and mu one line each.
* The stepper's problems: pentagons of the 'fast' preparation, compacted (Anderson sweeps)
  and sheared at 1 cm/s to eps_1 = 0.002, then the contact problems of 3 steps, 20 steps apart,
  captured as the NLGS received them (plain sweeps), assembled here into u = W r + q with
  W = H M^-1 H^T (H the points' local velocities from the bodies' (vx, vy, w)) and
  q = H v_free + (bias, 0).

Each method starts a Siconos problem from r = 0 and a captured problem from the warm start the
stepper gave its NLGS (last step's impulses, matched point by point). Time to a target: NLGS
sweeps are run in chunks of about 5% of the sweeps done so far, the natural-map residual computed between chunks, off the clock (the sweeps continue
from the impulses, as one longer run would); Newton and the projected conjugate gradient are
run with the target as their tolerance. A method that does not reach a target within its cap
(NLGS 20,000 sweeps or 120 s, Newton 200 steps, conjugate gradient 20,000 iterations) or stops
on its stall test (solver.nonsmooth_newton, solver.projected_cg) is reported with the residual
it ended at (the NLGS: the best it reached), and not run again for the tighter target. One
run per cell, the cores shared (nice).
"""

from __future__ import annotations

import argparse
import os
import pickle
import subprocess
import time
import warnings
from dataclasses import replace

import numpy as np
from scipy import sparse

HERE = os.path.dirname(os.path.abspath(__file__))
from benchmarks.common import capture_contact_problems, markdown_table

DATA = os.path.join(HERE, "_data", "contact_solvers")
RESULTS = os.path.join(HERE, "results", "contact-solvers.md")
FIGURE = os.path.join(HERE, "results", "contact_solvers_profile.png")
SICONOS = ["fc2d_granularflowonwall_00667_00000", "fc2d_granularflowonwall_02020_00213",
           "fc2d_granularflowonwall_07002_00801"]
SICONOS_PATH = "numerics/src/FrictionContact/test/data"
TARGETS = (1e-4, 1e-8)
CAPS = {"nlgs": 20_000, "newton": 200, "pcg": 20_000}
SECONDS = 120.0
SHEAR = 0.002
CAPTURED_STEPS, STEPS_APART = 3, 20


def fetch_siconos(mirror):
    """Copy the three 2D problems out of a git mirror of siconos/siconos into DATA."""
    os.makedirs(DATA, exist_ok=True)
    for name in SICONOS:
        found = subprocess.run(["git", "--git-dir", mirror, "show", f"HEAD:{SICONOS_PATH}/{name}.dat"],
                               capture_output=True)
        if found.returncode:
            raise SystemExit(f"--fetch-siconos {mirror}: no {SICONOS_PATH}/{name}.dat at HEAD of that git directory "
                             "(expected a git mirror of github.com/siconos/siconos)")
        path = os.path.join(DATA, name + ".dat")
        with open(path + ".part", "wb") as fh:
            fh.write(found.stdout)
        os.replace(path + ".part", path)


def read_siconos_fc2d(path):
    """(W CSR, q, mu) of a Siconos 2D frictional-contact problem file (module docstring):
    dimension, contacts, storage 2 (sparse), rows, columns, a CSparse print of W
    ("col j : locations ..." then "i : value" lines), q, mu."""
    with open(path) as fh:
        lines = fh.read().split("\n")
    dim, n, storage, rows, cols = (int(lines[i]) for i in range(5))
    if dim != 2 or storage != 2 or rows != cols or rows != 2 * n:
        raise ValueError(f"{path}: not a sparse 2D frictional-contact problem ({lines[:5]})")
    at = next(i for i, line in enumerate(lines) if line.startswith("CSparse")) + 2
    r, c, v, col = [], [], [], -1
    while True:
        line = lines[at].strip()
        if line.startswith("col "):
            col = int(line.split()[1])
        elif " : " in line:
            i, value = line.split(" : ")
            r.append(int(i))
            c.append(col)
            v.append(float(value))
        else:
            break
        at += 1
    q = np.array(lines[at].split(), float)
    mu = np.array(lines[at + 1].split(), float)
    return sparse.csc_matrix((v, (r, c)), shape=(rows, cols)).tocsr(), q, mu


def matrix_problem(problem, vx, vy, w):
    """(W CSR, q, mu) of a captured :class:`solver.nlgs.ContactProblem` with the free body
    velocities ``vx, vy, w``: :func:`solver.matrix_form.matrix_problem`, the stepper's own
    assembly (the one its ``pcg`` solver uses)."""
    from solver.matrix_form import matrix_problem as assemble

    return assemble(problem, vx, vy, w)


def check_assembly(problem, W, q, pn, pt, vx, vy, w):
    """Raise unless W r + q equals the stepper's own local velocities (its kernels, Signorini
    shift added) for the impulses of 20 NLGS sweeps from the warm start."""
    from solver import nlgs
    from solver.solve_records import Velocities

    pn, pt, vx, vy, w = pn.copy(), pt.copy(), vx.copy(), vy.copy(), w.copy()
    nlgs.solve_problem(problem, pn, pt, vx, vy, w, tolerance=1e-30, max_tolerance=1e-30, max_iterations=20)
    velocities = Velocities(vx, vy, w)
    local = np.array([nlgs._relative_velocity(k, problem, velocities) for k in range(problem.a.size)])
    local[:, 0] += problem.bias
    assembled = (W @ np.stack([pn, pt], -1).reshape(-1) + q).reshape(-1, 2)
    error = np.abs(assembled - local).max() / np.abs(local).max()
    if not error < 1e-9:
        raise AssertionError(f"W r + q differs from the stepper's velocities by {error:.2e} (relative)")


def build(particles):
    """Capture the stepper's problems at ``particles`` pentagons (module docstring)."""
    import solver
    from solver.preparation import prepare_sample, preparation

    os.makedirs(DATA, exist_ok=True)
    start = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sim = prepare_sample(preparation("fast", shape="pentagon", particles=particles), progress=False)
        print(f"compacted {particles} in {time.perf_counter() - start:.0f} s", flush=True)
        path = os.path.join(DATA, f"pentagon_{particles}_shear.nc")
        solver.biaxial_test(sim, path, strain=SHEAR, velocity=0.01, every=10**9, overwrite=True, progress=False)
        os.remove(path)
        sim.parameters = replace(sim.parameters, solver="nlgs")  # the steps between: plain sweeps, as first built
        captured = []
        for _ in range(CAPTURED_STEPS):
            problem, pn, pt, vx, vy, w, options = capture_contact_problems(sim, 1)[0]
            W, q, mu = matrix_problem(problem, vx, vy, w)
            check_assembly(problem, W, q, pn, pt, vx, vy, w)
            captured.append((W, q, mu, np.stack([pn, pt], -1)))
            for _ in range(STEPS_APART - 1):
                sim.step()
    path = os.path.join(DATA, f"pentagon_{particles}.pkl")
    with open(path + ".part", "wb") as fh:
        pickle.dump(captured, fh)
    os.replace(path + ".part", path)
    print(f"pentagon, {particles}: {len(captured)} problems ({[c[2].size for c in captured]} points) in "
          f"{time.perf_counter() - start:.0f} s", flush=True)


def problems():
    """[(label, W, q, mu, initial)]: the Siconos problems (from r = 0), then the captured ones
    (from the stepper's warm start), as far as present."""
    found = []
    for name in SICONOS:
        path = os.path.join(DATA, name + ".dat")
        if os.path.exists(path):
            W, q, mu = read_siconos_fc2d(path)
            found.append((f"Siconos {int(name.split('_')[2])}", W, q, mu, np.zeros((mu.size, 2))))
    for particles in (1000, 4000):
        path = os.path.join(DATA, f"pentagon_{particles}.pkl")
        if os.path.exists(path):
            with open(path, "rb") as fh:
                for i, (W, q, mu, initial) in enumerate(pickle.load(fh)):
                    found.append((f"pentagons {particles} #{i + 1}", W, q, mu, initial))
    return found


def law(W, q, mu, impulse):
    """The natural-map residual of ``impulse`` (solver.contact_solution)."""
    from solver.contact_solution import local_law_residual, natural_map

    return local_law_residual(natural_map(W, q, mu, impulse)[0], impulse)


def nlgs_sweeps(matrix, rn, rt, sweeps):
    """Run ``sweeps`` NLGS sweeps (no tolerance) on ``matrix`` (:func:`as_matrix_problem`) from the
    impulses ``rn, rt`` (n,), updated in place (:func:`solver.nlgs.solve_matrix`)."""
    from solver import nlgs
    from solver.solve_records import Impulses, Limits

    nlgs.solve_matrix(matrix, Impulses(rn, rt), Limits(1e-300, 1e-300, int(sweeps), 0))


def as_matrix_problem(W, q, mu):
    """The :class:`solver.solve_records.MatrixProblem` of W (CSR), q and mu."""
    from solver.solve_records import MatrixProblem

    return MatrixProblem(W.indptr.astype(np.int64), W.indices.astype(np.int64), W.data, q, mu)


def nlgs_trajectory(W, q, mu, initial, stop=TARGETS[-1]):
    """[(sweeps, seconds, residual)] of NLGS sweeps from ``initial`` (module docstring), until the
    residual is within ``stop``, CAPS['nlgs'] sweeps or SECONDS."""
    matrix = as_matrix_problem(W, q, mu)
    rn, rt = initial[:, 0].copy(), initial[:, 1].copy()
    sweeps, seconds, points = 0, 0.0, [(0, 0.0, law(W, q, mu, initial))]
    while points[-1][2] > stop and sweeps < CAPS["nlgs"] and seconds < SECONDS:
        chunk = max(2, sweeps // 20)
        start = time.perf_counter()
        nlgs_sweeps(matrix, rn, rt, chunk)
        seconds += time.perf_counter() - start
        sweeps += chunk
        points.append((sweeps, seconds, law(W, q, mu, np.stack([rn, rt], -1))))
    return points


def first_reached(trajectory, target):
    """(sweeps, seconds) of the first point of ``trajectory`` within ``target``; None if none."""
    return next(((it, sec) for it, sec, res in trajectory if res <= target), None)


def timed(method, W, q, mu, initial, target):
    """(iterations, seconds, residual, converged) of ``method`` from ``initial`` to ``target``."""
    from solver.contact_solvers import solver

    start = time.perf_counter()
    s = solver(method)(W, q, mu, target, CAPS[method], initial.copy())
    return s.iterations, time.perf_counter() - start, s.local_law_residual, s.converged


def measure():
    """Rows {problem, points, method, target, iterations, seconds, residual, reached} for every
    problem, method and target (module docstring)."""
    from solver.contact_solvers import SOLVERS

    rows = []
    coupled = sparse.csr_matrix(np.array([[2.0, 0, 1, 0], [0, 2, 0, 0], [1, 0, 2, 0], [0, 0, 0, 2]]))
    for method in SOLVERS:  # compile or load every kernel outside the timing, on a problem that iterates
        timed(method, coupled, np.array([-3.0, 0.5, -3.0, -0.5]), np.full(2, 0.3), np.zeros((2, 2)), 1e-12)
    for label, W, q, mu, initial in problems():
        trajectory = nlgs_trajectory(W, q, mu, initial)
        best = min(res for _, _, res in trajectory)
        print(f"{label}: {mu.size} points, NLGS best {best:.2e} after {trajectory[-1][0]} sweeps, "
              f"{trajectory[-1][1]:.1f} s", flush=True)
        for target in TARGETS:
            effective = max(target, 1.05 * best) if target == TARGETS[-1] else target
            hit = first_reached(trajectory, effective)
            rows.append(dict(problem=label, points=mu.size, method="nlgs", target=target, effective=effective,
                             iterations=hit[0] if hit else trajectory[-1][0],
                             seconds=hit[1] if hit else trajectory[-1][1],
                             residual=effective if hit else best, reached=hit is not None))
            for method in SOLVERS:
                if method == "nlgs":
                    continue
                earlier = [r for r in rows if r["problem"] == label and r["method"] == method]
                if earlier and not earlier[-1]["reached"]:  # missed the looser target: the same run again
                    rows.append(dict(earlier[-1], target=target, effective=effective))
                    continue
                iterations, seconds, residual, reached = timed(method, W, q, mu, initial, effective)
                rows.append(dict(problem=label, points=mu.size, method=method, target=target, effective=effective,
                                 iterations=iterations, seconds=seconds, residual=residual, reached=reached))
                print(f"  {method} to {effective:.1e}: {iterations} iterations, {seconds:.2f} s, "
                      f"residual {residual:.2e}", flush=True)
    with open(os.path.join(DATA, "rows.pkl"), "wb") as fh:
        pickle.dump(rows, fh)
    return rows


def profile(rows, path=FIGURE):
    """Dolan–Moré performance profiles of the seconds to each target: for every method, the
    fraction of problems it solves within tau times the fastest method's time. A problem that
    its starting impulses solve already (no method iterates) is left out."""
    import matplotlib.pyplot as plt

    trivial = {label for label in {r["problem"] for r in rows}
               if all(r["iterations"] == 0 for r in rows if r["problem"] == label)}
    rows = [r for r in rows if r["problem"] not in trivial]
    methods = sorted({r["method"] for r in rows})
    fig, axes = plt.subplots(1, len(TARGETS), figsize=(10, 4), sharey=True)
    for ax, target in zip(axes, TARGETS):
        cells = [r for r in rows if r["target"] == target]
        labels = sorted({r["problem"] for r in cells})
        times = {(r["problem"], r["method"]): (r["seconds"] if r["reached"] else np.inf) for r in cells}
        ratios = {m: [] for m in methods}
        for label in labels:
            best = min(times.get((label, m), np.inf) for m in methods)
            for m in methods:
                t = times.get((label, m), np.inf)
                ratios[m].append(t / best if np.isfinite(best) and best > 0 else (1.0 if t == best else np.inf))
        top = max([x for m in methods for x in ratios[m] if np.isfinite(x)] + [2.0]) * 2
        taus = np.logspace(0, np.log10(top), 400)
        for m in methods:
            x = np.array(ratios[m])
            ax.step(taus, [(x <= tau).mean() for tau in taus], where="post", label=m)
        ax.set_xscale("log")
        ax.set_xlabel("tau (time over the fastest method's)")
        ax.set_title(f"to a natural-map residual of {target:.0e}" + (" (or the NLGS's best)" if target == TARGETS[-1]
                                                                    else ""))
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("fraction of problems solved within tau")
    axes[0].legend(loc="lower right")
    fig.suptitle(f"{len({r['problem'] for r in rows})} problems: Siconos 2D granular flow and the stepper's pentagons")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def table(rows):
    """The Markdown table: one row per problem and target, a column per method."""
    methods = sorted({r["method"] for r in rows})
    header = ["problem", "points", "target"] + [f"{m}: iterations, s" for m in methods] + ["fastest"]
    lines = []
    for label in dict.fromkeys(r["problem"] for r in rows):
        for target in TARGETS:
            cells = {r["method"]: r for r in rows if r["problem"] == label and r["target"] == target}
            any_row = next(iter(cells.values()))
            shown = f"{any_row['effective']:.1e}" + ("" if any_row["effective"] == target else " (NLGS's best)")
            row = [label, any_row["points"], shown]
            for m in methods:
                r = cells[m]
                row.append(f"{r['iterations']}, {r['seconds']:.3g}" if r["reached"] else
                           f"not reached ({r['iterations']}, {r['seconds']:.3g} s; {r['residual']:.1e})")
            reached = [m for m in methods if cells[m]["reached"]]
            row.append(min(reached, key=lambda m: cells[m]["seconds"]) if reached else "none")
            lines.append(row)
    return markdown_table(header, lines)


def degeneracy(name=SICONOS[1]):
    """Print what makes the 2020-contact problem stall: the spectrum of its stored W (symmetric,
    but printed to six significant digits), the points its negative modes live on, where the
    NLGS's natural-map residual sits after CAPS['nlgs'] sweeps, and how far 3000 sweeps get on
    the stored W and on W with its negative modes removed (entries below 1e-12 of the largest
    dropped)."""
    from solver.contact_solution import natural_map

    W, q, mu = read_siconos_fc2d(os.path.join(DATA, name + ".dat"))
    dense = W.toarray()
    print(f"{name}: {mu.size} points, |W - W^T| max {np.abs(dense - dense.T).max():.1e}")
    values, vectors = np.linalg.eigh(dense)
    largest = values[-1]
    negative = np.where(values < 0)[0]
    print(f"eigenvalues: largest {largest:.4g}; {negative.size} negative, down to {values[0]:.3g} "
          f"({values[0] / largest:.1e} of the largest); |lambda| < 1e-6 of the largest: "
          f"{int(np.sum(np.abs(values) < 1e-6 * largest))}; "
          f"numerical rank (1e-9) {int(np.sum(values > 1e-9 * largest))}")
    modes = set()
    for j in negative:
        weight = vectors[0::2, j] ** 2 + vectors[1::2, j] ** 2
        top = np.argsort(weight)[::-1][:5]
        modes.update(top.tolist())
        print(f"  mode {values[j]:.3g}: points {top.tolist()} carry {weight[top].sum():.2f} of it")
    rn, rt = np.zeros(mu.size), np.zeros(mu.size)
    nlgs_sweeps(as_matrix_problem(W, q, mu), rn, rt, CAPS["nlgs"])
    impulse = np.stack([rn, rt], -1)
    violation = natural_map(W, q, mu, impulse)[0]
    share = np.sum(violation ** 2, axis=1) / np.sum(violation ** 2)
    worst = np.argsort(share)[::-1][:10]
    print(f"NLGS after {CAPS['nlgs']} sweeps: residual {np.linalg.norm(violation) / np.linalg.norm(impulse):.2e}; "
          f"its 10 worst points {worst.tolist()} hold {share[worst].sum():.2f} of |F|^2, "
          f"{len(set(worst.tolist()) & modes)} of them among the negative modes' points; "
          f"the modes' {len(modes)} points hold {share[sorted(modes)].sum():.2f}")
    repaired = dense - (vectors[:, negative] * values[negative]) @ vectors[:, negative].T
    repaired = 0.5 * (repaired + repaired.T)
    repaired = sparse.csr_matrix(np.where(np.abs(repaired) > 1e-12 * np.abs(repaired).max(), repaired, 0.0))
    for label, matrix in (("stored W", W), ("W without its negative modes", repaired)):
        rn, rt = np.zeros(mu.size), np.zeros(mu.size)
        nlgs_sweeps(as_matrix_problem(matrix, q, mu), rn, rt, 3000)
        print(f"NLGS, 3000 sweeps, {label}: residual {law(matrix, q, mu, np.stack([rn, rt], -1)):.2e}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--fetch-siconos", metavar="MIRROR")
    parser.add_argument("--build", type=int, metavar="PARTICLES")
    parser.add_argument("--degeneracy", action="store_true")
    parser.add_argument("--replot", action="store_true", help="table and figure from the last run's rows")
    parser.add_argument("--out", help="write the table as a results file here (default: printed only)")
    args = parser.parse_args()
    if args.fetch_siconos:
        fetch_siconos(args.fetch_siconos)
    elif args.build:
        build(args.build)
    elif args.degeneracy:
        degeneracy()
    else:
        if args.replot:
            with open(os.path.join(DATA, "rows.pkl"), "rb") as fh:
                found = pickle.load(fh)
        else:
            found = measure()
        profile(found)
        print(table(found))
        if args.out:
            from benchmarks.common import machine_description

            with open(args.out, "w") as fh:
                fh.write("\n".join([
                    "# Problem-level methods: NLGS, semi-smooth Newton, projected conjugate gradient", "",
                    "Written by `python -m benchmarks.contact_solvers` (its docstring gives the problems and the "
                    "method). Time and iterations of each method to a natural-map residual of 1e-4 and 1e-8, or the "
                    "best it reaches.", "", machine_description(), "", table(found), "",
                    f"![performance profiles]({os.path.relpath(FIGURE, os.path.dirname(os.path.abspath(args.out)))})",
                    ""]))
