"""Every problem-level method of solver.contact_solvers on problems others use and on the
stepper's own: time and iterations to a natural-map residual of 1e-4 and of 1e-8 (or the best
each reaches), a table (results/contact-solvers.md) and a performance profile
(results/contact_solvers_profile.png).

    python -m benchmarks.contact_solvers --fetch-siconos MIRROR   # copy the 2D problems out of a siconos git mirror
    nice -n 10 python -m benchmarks.contact_solvers --build 1000  # capture the stepper's problems (~3 min)
    nice -n 10 python -m benchmarks.contact_solvers --build 4000  # (~10 min)
    cp /work/runs/paper_size/pentagons.nc /tmp/p14400.nc          # a copy of the paper-size study's shear
    nice -n 10 python -m benchmarks.contact_solvers --build-from /tmp/p14400.nc --index 2   # 14,400 (~1 min)
    nice -n 10 python -m benchmarks.contact_solvers               # solve them all, write the table and figure
    nice -n 10 python -m benchmarks.contact_solvers --only "pentagons 14400"   # these again, other rows kept
    nice -n 10 python -m benchmarks.contact_solvers --degeneracy  # rank and spectrum of the 2020-contact W
    nice -n 10 python -m benchmarks.contact_solvers --stepper /tmp/p14400.nc --index 2 --steps 100

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
* The stepper's problems at 14,400 pentagons (``--build-from``): not prepared here but read
  from a snapshot of a biaxial test's file, the paper-size study's (``grainview study
  --paper-size``: the 'paper' preparation, compacted by the study, sheared with the top wall
  at 6 cm/s, two domains), snapshot 2 (eps_1 = 0.0023); from there the same 3 steps, 20 apart,
  plain sweeps on one domain between them, the first from the snapshot's warm start.

The stepper itself (``--stepper FILE --index K``): ``--steps`` consecutive steps of the biaxial
test from the snapshot, once with each of nlgs, anderson and pcg, each from the same loaded
state on one domain (the file's other settings kept: its tolerance, caps, time step), recording
per step the iterations, seconds, local-law residual and converged flag
(``Simulation.watch``); rows in DATA/stepper_<file>_<index>.pkl, a table printed.

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
PARTICLES = (1000, 4000, 14400)
STRETCH_STEPS, STRETCH_METHODS = 100, ("nlgs", "anderson", "pcg")


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
    local = np.array([nlgs.relative_velocity(k, problem, velocities) for k in range(problem.a.size)])
    local[:, 0] += problem.bias
    assembled = (W @ np.stack([pn, pt], -1).reshape(-1) + q).reshape(-1, 2)
    error = np.abs(assembled - local).max() / np.abs(local).max()
    if not error < 1e-9:
        raise AssertionError(f"W r + q differs from the stepper's velocities by {error:.2e} (relative)")


def build(particles):
    """Capture the stepper's problems at ``particles`` pentagons of the 'fast' preparation
    (module docstring)."""
    import solver
    from solver.preparation import prepare_sample, preparation

    start = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sim = prepare_sample(preparation("fast", shape="pentagon", particles=particles), progress=False)
        print(f"compacted {particles} in {time.perf_counter() - start:.0f} s", flush=True)
        path = os.path.join(DATA, f"pentagon_{particles}_shear.nc")
        os.makedirs(DATA, exist_ok=True)
        solver.biaxial_test(sim, path, strain=SHEAR, velocity=0.01, every=10**9, overwrite=True, progress=False)
        os.remove(path)
    capture(sim, os.path.join(DATA, f"pentagon_{particles}.pkl"), start=start)


def build_from(source, index, captured=CAPTURED_STEPS, apart=STEPS_APART, out=None):
    """Capture the stepper's problems from snapshot ``index`` of a biaxial test's file ``source``
    (a copy: :func:`solver.load_sample` reads complete snapshots only), as :func:`build` does
    after its shear: ``captured`` problems ``apart`` steps apart, plain serial NLGS sweeps on
    one domain. Saved as ``pentagon_<particles>.pkl`` in DATA (or ``out``); returns its path."""
    from solver import load_sample

    start = time.perf_counter()
    sim = load_sample(source, index)
    print(f"{source}, snapshot {index}: step {sim.step_index}, {sim.mass.size} particles", flush=True)
    out = out or os.path.join(DATA, f"pentagon_{sim.mass.size}.pkl")
    capture(sim, out, captured, apart, start)
    return out


def captured_problems(sim, make_entry, captured=CAPTURED_STEPS, apart=STEPS_APART) -> list:
    """Step ``sim`` with plain serial NLGS sweeps (one domain) and return ``make_entry(problem,
    pn, pt, vx, vy, w)`` of the contact problems of ``captured`` steps, ``apart`` steps apart
    (the step's problem, its warm-start impulses and free velocities:
    :func:`benchmarks.common.capture_contact_problems`)."""
    sim.parameters = replace(sim.parameters, solver="nlgs", domains=1)  # plain sweeps, as first built
    found = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for k in range(captured):
            problem, pn, pt, vx, vy, w, _ = capture_contact_problems(sim, 1)[0]
            found.append(make_entry(problem, pn, pt, vx, vy, w))
            for _ in range(apart - 1 if k < captured - 1 else 0):
                sim.step()
    return found


def save_problems(path, found, points, start):
    """Pickle the captured problems ``found`` to ``path`` (written beside it, then renamed) and
    say so with their ``points`` and the seconds since ``start``."""
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path + ".part", "wb") as fh:
        pickle.dump(found, fh)
    os.replace(path + ".part", path)
    print(f"{path}: {len(found)} problems ({points} points) in {time.perf_counter() - start:.0f} s", flush=True)


def capture(sim, path, captured=CAPTURED_STEPS, apart=STEPS_APART, start=None):
    """Step ``sim`` (:func:`captured_problems`) and pickle the contact problems of ``captured``
    steps, ``apart`` steps apart, as (W, q, mu, warm start) to ``path``, each checked against the
    stepper's velocities (:func:`check_assembly`)."""
    start = time.perf_counter() if start is None else start

    def matrix_entry(problem, pn, pt, vx, vy, w):
        W, q, mu = matrix_problem(problem, vx, vy, w)
        check_assembly(problem, W, q, pn, pt, vx, vy, w)
        return W, q, mu, np.stack([pn, pt], -1)

    found = captured_problems(sim, matrix_entry, captured, apart)
    save_problems(path, found, [c[2].size for c in found], start)


def problems():
    """[(label, W, q, mu, initial)]: the Siconos problems (from r = 0), then the captured ones
    (from the stepper's warm start), as far as present."""
    found = []
    for name in SICONOS:
        path = os.path.join(DATA, name + ".dat")
        if os.path.exists(path):
            W, q, mu = read_siconos_fc2d(path)
            found.append((f"Siconos {int(name.split('_')[2])}", W, q, mu, np.zeros((mu.size, 2))))
    for particles in PARTICLES:
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


def nlgs_run(W, q, mu, initial, stop, cap, seconds_cap, target=None):
    """NLGS sweeps on (W, q, mu) from ``initial`` (n, 2) in chunks of ~5% of the sweeps done
    (module docstring), the local-law residual computed off the clock, until the residual is
    within ``stop``, ``cap`` sweeps or ``seconds_cap`` s of sweeping. Returns (trajectory
    [(sweeps, seconds, residual)], best impulses (n, 2), impulses at the first point within
    ``target``, or None where ``target`` is None or not reached)."""
    matrix = as_matrix_problem(W, q, mu)
    rn, rt = initial[:, 0].copy(), initial[:, 1].copy()
    sweeps, seconds, points = 0, 0.0, [(0, 0.0, law(W, q, mu, initial))]
    best = (points[0][2], initial.copy())
    reached = target is not None and points[0][2] <= target
    at_target = initial.copy() if reached else None
    while points[-1][2] > stop and sweeps < cap and seconds < seconds_cap:
        chunk = max(2, sweeps // 20)
        start = time.perf_counter()
        nlgs_sweeps(matrix, rn, rt, chunk)
        seconds += time.perf_counter() - start
        sweeps += chunk
        impulse = np.stack([rn, rt], -1)
        points.append((sweeps, seconds, law(W, q, mu, impulse)))
        if points[-1][2] < best[0]:
            best = (points[-1][2], impulse.copy())
        if at_target is None and target is not None and points[-1][2] <= target:
            at_target = impulse.copy()
    return points, best[1], at_target


def nlgs_trajectory(W, q, mu, initial, stop=TARGETS[-1]):
    """[(sweeps, seconds, residual)] of NLGS sweeps from ``initial`` (:func:`nlgs_run`), until the
    residual is within ``stop``, CAPS['nlgs'] sweeps or SECONDS."""
    return nlgs_run(W, q, mu, initial, stop, CAPS["nlgs"], SECONDS)[0]


def first_reached(trajectory, target):
    """(sweeps, seconds) of the first point of ``trajectory`` within ``target``; None if none."""
    return next(((it, sec) for it, sec, res in trajectory if res <= target), None)


def timed(method, W, q, mu, initial, target):
    """(iterations, seconds, residual, converged) of ``method`` from ``initial`` to ``target``."""
    from solver.contact_solvers import solver

    start = time.perf_counter()
    s = solver(method)(W, q, mu, target, CAPS[method], initial.copy())
    return s.iterations, time.perf_counter() - start, s.local_law_residual, s.converged


def measure(found=None):
    """Rows {problem, points, method, target, iterations, seconds, residual, reached} for every
    problem of ``found`` ([(label, W, q, mu, initial)], default :func:`problems`), every method
    of the registry that solves a matrix problem and every target (module docstring)."""
    from solver.contact_solvers import matrix_methods

    methods = matrix_methods()
    rows = []
    coupled = sparse.csr_matrix(np.array([[2.0, 0, 1, 0], [0, 2, 0, 0], [1, 0, 2, 0], [0, 0, 0, 2]]))
    for method in methods:  # compile or load every kernel outside the timing, on a problem that iterates
        timed(method, coupled, np.array([-3.0, 0.5, -3.0, -0.5]), np.full(2, 0.3), np.zeros((2, 2)), 1e-12)
    for label, W, q, mu, initial in (problems() if found is None else found):
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
            for method in methods:
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
    return rows


def merge_rows(kept, fresh):
    """The rows of ``kept`` with those of every problem measured in ``fresh`` replaced by
    ``fresh``'s: in ``kept``'s order of problems, a problem new to it appended."""
    measured = {r["problem"] for r in fresh}
    order = list(dict.fromkeys([r["problem"] for r in kept] + [r["problem"] for r in fresh]))
    return [r for label in order for r in (fresh if label in measured else kept) if r["problem"] == label]


def save_rows(rows, path=None):
    """Pickle ``rows`` to ``path`` (default DATA/rows.pkl), written beside it, then renamed."""
    path = path or os.path.join(DATA, "rows.pkl")
    with open(path + ".part", "wb") as fh:
        pickle.dump(rows, fh)
    os.replace(path + ".part", path)


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


def stepper_stretch(source, index, steps=STRETCH_STEPS, methods=STRETCH_METHODS):
    """Rows {method, step, iterations, seconds, solve_seconds, residual, local_law_residual,
    converged} of ``steps`` consecutive steps of the biaxial test in ``source`` from its snapshot
    ``index``, once per stepper method of ``methods``, each from the same state (loaded again by
    :func:`solver.load_sample`) on one domain, the file's other settings kept; ``seconds`` the
    whole step's, ``solve_seconds`` its solve stage's (:data:`solver.stepper.STAGES`). One step
    of each method runs first on a copy loaded apart, to load its compiled kernels off the
    record."""
    from solver import load_sample

    rows = []
    for name in methods:
        for warm in (True, False):
            sim = load_sample(source, index)
            sim.parameters = replace(sim.parameters, solver=name, domains=1)
            clock = {}

            def before():
                clock.update(start=time.perf_counter(), solve=sim.timings["solve"])

            def after(info):
                rows.append(dict(method=name, step=sim.step_index, iterations=info.iterations,
                                 seconds=time.perf_counter() - clock["start"],
                                 solve_seconds=sim.timings["solve"] - clock["solve"], residual=info.residual,
                                 local_law_residual=info.local_law_residual, converged=bool(info.converged)))

            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                if warm:
                    sim.step()
                    continue
                with sim.watch(before=before, after=after):
                    for _ in range(steps):
                        sim.step()
        mine = stretch_summary([r for r in rows if r["method"] == name])[0]
        print(f"{name}: {steps} steps, iterations median {mine['median']:g}, mean {mine['mean']:.1f}, "
              f"p90 {mine['p90']:g}; {mine['seconds']:.2f} s a step", flush=True)
    return rows


def stretch_summary(rows):
    """Per method of ``rows`` (:func:`stepper_stretch`): {method, steps, median, mean, p90, max
    (iterations), seconds, solve_seconds (means per step), unconverged (steps), law_median,
    law_max (local-law residuals)}."""
    out = []
    for name in dict.fromkeys(r["method"] for r in rows):
        mine = [r for r in rows if r["method"] == name]
        it = np.array([r["iterations"] for r in mine], float)
        law = np.array([r["local_law_residual"] for r in mine])
        out.append(dict(method=name, steps=len(mine), median=float(np.median(it)), mean=float(it.mean()),
                        p90=float(np.percentile(it, 90)), max=int(it.max()),
                        seconds=float(np.mean([r["seconds"] for r in mine])),
                        solve_seconds=float(np.mean([r["solve_seconds"] for r in mine])),
                        unconverged=sum(not r["converged"] for r in mine),
                        law_median=float(np.median(law)), law_max=float(law.max())))
    return out


def stretch_table(rows):
    """The Markdown table of :func:`stretch_summary`."""
    header = ["solver", "steps", "iterations: median, mean, p90, max", "s per step (solve)", "unconverged steps",
              "local-law residual: median, max"]
    return markdown_table(header, [[s["method"], s["steps"], f"{s['median']:g}, {s['mean']:.1f}, {s['p90']:g}, "
                                    f"{s['max']}", f"{s['seconds']:.3g} ({s['solve_seconds']:.3g})",
                                    s["unconverged"], f"{s['law_median']:.2e}, {s['law_max']:.2e}"]
                                   for s in stretch_summary(rows)])


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
    parser.add_argument("--build-from", metavar="FILE", help="capture the problems from a biaxial test's file "
                        "(a copy of it) at snapshot --index")
    parser.add_argument("--stepper", metavar="FILE", help="run --steps steps of each of nlgs, anderson and pcg from "
                        "snapshot --index of a biaxial test's file (a copy of it)")
    parser.add_argument("--index", type=int, default=2, help="the snapshot of --build-from and --stepper (default 2)")
    parser.add_argument("--steps", type=int, default=STRETCH_STEPS, help="steps of --stepper (default %(default)s)")
    parser.add_argument("--only", metavar="LABELS", help="measure only the problems whose label starts with one of "
                        "these (comma-separated, e.g. 'pentagons 14400'); the other rows come from the last run's")
    parser.add_argument("--degeneracy", action="store_true")
    parser.add_argument("--replot", action="store_true", help="table and figure from the last run's rows")
    parser.add_argument("--out", help="write the table as a results file here (default: printed only)")
    args = parser.parse_args()
    if args.fetch_siconos:
        fetch_siconos(args.fetch_siconos)
    elif args.build:
        build(args.build)
    elif args.build_from:
        build_from(args.build_from, args.index)
    elif args.stepper:
        stretch = stepper_stretch(args.stepper, args.index, args.steps)
        path = os.path.join(DATA, f"stepper_{args.stepper.rsplit('/', 1)[-1].rsplit('.', 1)[0]}_{args.index}.pkl")
        save_rows(stretch, path)
        print(stretch_table(stretch))
    elif args.degeneracy:
        degeneracy()
    else:
        rows_path = os.path.join(DATA, "rows.pkl")
        if args.replot:
            with open(rows_path, "rb") as fh:
                found = pickle.load(fh)
        elif args.only:
            prefixes = tuple(p.strip() for p in args.only.split(","))
            chosen = [p for p in problems() if p[0].startswith(prefixes)]
            if not chosen:
                raise SystemExit(f"--only {args.only}: no problem's label starts with it (labels: "
                                 f"{', '.join(p[0] for p in problems())})")
            with open(rows_path, "rb") as fh:
                found = merge_rows(pickle.load(fh), measure(chosen))
            save_rows(found, rows_path)
        else:
            found = measure()
            save_rows(found, rows_path)
        profile(found)
        print(table(found))
        if args.out:
            from benchmarks.common import machine_description, write_text_keeping_notes

            write_text_keeping_notes(args.out, "\n".join([
                "# Problem-level methods: NLGS, semi-smooth Newton, projected conjugate gradient", "",
                "Written by `python -m benchmarks.contact_solvers` (its docstring gives the problems and the "
                "method). Time and iterations of each method to a natural-map residual of 1e-4 and 1e-8, or the "
                "best it reaches. Each cell: iterations (NLGS sweeps, Newton steps, CG iterations), seconds. \"not "
                "reached\": where the method stopped (its cap or its stall test), with the residual it ended at.", "",
                machine_description(), "", table(found), "",
                f"![performance profiles]({os.path.relpath(FIGURE, os.path.dirname(os.path.abspath(args.out)))})",
                ""]))
