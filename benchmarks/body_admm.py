"""Body-space ADMM (benchmarks.research.body_admm) against the NLGS on the stepper's own contact problems at
1000, 4000 and 14,400 pentagons: iterations and seconds to a local-law residual of 1e-4 and
1e-6 (or the best within a cap), the factorisations of M + rho H^T H and their time, and the
rho each used.

    grainview run biaxial --particles 1000 --preparation fast --velocity 0.016 --strain 0.003 --every 20 --out /tmp/admm_p1000.nc
    nice -n 10 python -m benchmarks.body_admm --build-from /tmp/admm_p1000.nc --index 2
    nice -n 10 python -m benchmarks.body_admm --build-from /tmp/p4000.nc --index 2   # --particles 4000 --velocity 0.032 --strain 0.004
    nice -n 10 python -m benchmarks.body_admm --build-from /work/runs/paper_size/pentagons.nc --index 2   # only read
    nice -n 10 python -m benchmarks.body_admm --out benchmarks/results/body-admm.md
    nice -n 10 python -m benchmarks.body_admm --spectrum   # W's spectrum on the closed face, 1000 #1
    nice -n 10 python -m benchmarks.body_admm --spectrum "pentagons 4000 #1"   # (a minute, 2 GiB)

The problems (benchmarks/_data/body_space/pentagon_<particles>.pkl, ignored by git): from
snapshot ``--index`` of a biaxial test's file (:func:`solver.load_sample`, the file only read),
three steps 20 apart with plain serial NLGS sweeps on one domain between them, as
benchmarks/contact_solvers.py's ``--build-from`` captures them, but each stored in body space: H
(the points' local map, :func:`solver.matrix_form.local_map`), M^-1
(:func:`solver.matrix_form.inverse_mass`), the free velocities v_free (3B,), the Signorini
shifts (P,), mu, the warm start the stepper gave its NLGS, and W, q of the matrix form. The
capture asserts that W r + q equals the stepper's own local velocities
(benchmarks.contact_solvers.check_assembly), that W = H M^-1 H^T and q = H v_free + (bias, 0)
(recomputed here), and, where benchmarks/_data/contact_solvers/ holds a problem of the same
points (the 14,400 ones come from the same snapshot), that W and q equal the stored ones.

Each method starts from the stored warm start (the impulses, and the velocities they imply).
ADMM: benchmarks.research.body_admm.solve with its defaults, the local-law residual computed every 5
iterations on the clock (it is the stopping test), cap ADMM_CAP iterations; time to a target is
the first check within it. NLGS: benchmarks.contact_solvers.nlgs_trajectory (the kernel of
solve_contact_problem(method='nlgs'), sweeps in chunks of ~5% of those done, the residual off
the clock), cap NLGS_CAP sweeps or NLGS_SECONDS. One run per cell, the cores shared (nice,
one thread).
"""

from __future__ import annotations

import argparse
import os
import pickle
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "_data", "body_space")
STORED = os.path.join(HERE, "_data", "contact_solvers")
RESULTS = os.path.join(HERE, "results", "body-admm.md")
PARTICLES = (1000, 4000, 14400)
TARGETS = (1e-4, 1e-6)
CAPTURED_STEPS, STEPS_APART = 3, 20
ADMM_CAP = 1000
NLGS_CAP, NLGS_SECONDS = 20_000, 60.0


def capture(source, index, captured=CAPTURED_STEPS, apart=STEPS_APART, out=None):
    """Capture ``captured`` problems ``apart`` steps apart from snapshot ``index`` of ``source``
    in body space (module docstring), checked; saved to DATA/pentagon_<particles>.pkl (or
    ``out``), written beside it then renamed. Returns the path."""
    from benchmarks.contact_solvers import captured_problems, check_assembly, save_problems
    from solver import load_sample
    from solver.matrix_form import inverse_mass, local_map, matrix_problem

    start = time.perf_counter()
    sim = load_sample(source, index)
    print(f"{source}, snapshot {index}: step {sim.step_index}, {sim.mass.size} particles", flush=True)

    def body_entry(problem, pn, pt, vx, vy, w):
        H, minv = local_map(problem), inverse_mass(problem)
        W, q, mu = matrix_problem(problem, vx, vy, w, H, minv)
        check_assembly(problem, W, q, pn, pt, vx, vy, w)
        entry = dict(H=H, minv=minv, v_free=np.stack([vx, vy, w], -1).reshape(-1), bias=problem.bias.copy(), mu=mu,
                     W=W, q=q, initial=np.stack([pn, pt], -1))
        check_body_form(entry)
        return entry

    found = captured_problems(sim, body_entry, captured, apart)  # plain sweeps, as contact_solvers captures
    compare_with_stored(found, sim.mass.size)
    out = out or os.path.join(DATA, f"pentagon_{sim.mass.size}.pkl")
    save_problems(out, found, [e["mu"].size for e in found], start)
    return out


def check_body_form(entry):
    """Raise unless W = H M^-1 H^T and q = H v_free + (bias, 0) of ``entry`` to rounding (the
    products recomputed here, W compared on its entries)."""
    H, minv = entry["H"], entry["minv"]
    W = (H @ minv @ H.T).tocsr()
    difference = abs(W - entry["W"]).max() / abs(entry["W"]).max()
    q = H @ entry["v_free"]
    q[0::2] += entry["bias"]
    q_difference = np.abs(q - entry["q"]).max() / max(np.abs(entry["q"]).max(), 1e-300)
    if not (difference < 1e-12 and q_difference < 1e-12):
        raise AssertionError(f"body form differs from the matrix form: W by {difference:.1e}, q by {q_difference:.1e}")


def compare_with_stored(found, particles):
    """Assert that the problems ``found`` equal those of benchmarks/_data/contact_solvers/
    pentagon_<particles>.pkl where that file holds problems of the same points (the same
    snapshot captured again); say so either way."""
    path = os.path.join(STORED, f"pentagon_{particles}.pkl")
    if not os.path.exists(path):
        print(f"no {path} to compare with", flush=True)
        return
    with open(path, "rb") as fh:
        stored = pickle.load(fh)
    for k, (entry, (W, q, mu, initial)) in enumerate(zip(found, stored)):
        if W.shape != entry["W"].shape:
            print(f"problem {k + 1}: {mu.size} stored points against {entry['mu'].size} captured: another source, "
                  "not compared", flush=True)
            continue
        dW = abs(W - entry["W"]).max() / abs(W).max()
        dq = np.abs(q - entry["q"]).max() / np.abs(q).max()
        dr = np.abs(initial - entry["initial"]).max() / max(np.abs(initial).max(), 1e-300)
        print(f"problem {k + 1}: W, q, warm start against the stored ones: {dW:.1e}, {dq:.1e}, {dr:.1e}", flush=True)
        assert dW < 1e-9 and dq < 1e-9 and dr < 1e-9, "captured problem differs from the stored one"


def problems(particles=PARTICLES):
    """[(label, entry)] of the body-space problems present in DATA."""
    found = []
    for n in particles:
        path = os.path.join(DATA, f"pentagon_{n}.pkl")
        if os.path.exists(path):
            with open(path, "rb") as fh:
                found += [(f"pentagons {n} #{i + 1}", e) for i, e in enumerate(pickle.load(fh))]
    return found


TITLE = "Body-space ADMM against the NLGS on the stepper's pentagon problems"
INTRO = ("Written by `python -m benchmarks.body_admm --out benchmarks/results/body-admm.md` (its docstring gives the "
         "problems, the caps and how each cell is timed): iterations (NLGS: sweeps) and seconds to a local-law "
         "residual |F|/|r| of 1e-4 and 1e-6 from the stored warm start, one run per cell; the ADMM's "
         "factorisations of D + rho A^T A (count, seconds) and the rho it used; then three probes of why.")
VARIANTS = {  # label -> options of benchmarks.research.body_admm.solve
    "admm": {},
    "admm wnn": dict(scaling="wnn"),
    "admm wnn grow": dict(scaling="wnn", balance_every=0, stall_growth=3.0),
}
RHO_FACTORS = (0.1, 1.0, 10.0, 100.0)
PROBE_CAP = 300


def nlgs_run(W, q, mu, initial, stop=TARGETS[-1]):
    """(trajectory [(sweeps, seconds, residual)], best impulses) of NLGS sweeps from ``initial``
    (benchmarks.contact_solvers.nlgs_run's chunks and clock), until ``stop``, NLGS_CAP sweeps or
    NLGS_SECONDS."""
    from benchmarks.contact_solvers import nlgs_run as chunked_nlgs

    return chunked_nlgs(W, q, mu, initial, stop, NLGS_CAP, NLGS_SECONDS)[:2]


def admm_run(entry, cap=ADMM_CAP, **options):
    """(record, solution) of benchmarks.research.body_admm.solve on ``entry`` from its warm start."""
    from benchmarks.research import body_admm

    record = {}
    solution = body_admm.solve(entry["H"], entry["minv"], entry["v_free"], entry["bias"], entry["mu"], TARGETS[-1], cap,
                               entry["initial"], record=record, **options)
    return record, solution


def reached(trajectory, target):
    """(iterations, seconds) of the first point of [(iterations, seconds, residual)] within
    ``target``; None if none."""
    return next(((it, sec) for it, sec, res in trajectory if res <= target), None)


def factor_fill(entry, rho=None):
    """(seconds, nnz of L + U, unknowns) of one factorisation of D + rho A^T A for ``entry``
    (rho: benchmarks.research.body_admm's default)."""
    from benchmarks.research import body_admm

    problem = body_admm.body_problem(entry["H"], entry["minv"], entry["v_free"], entry["bias"], entry["mu"])
    rho = float(np.median(1.0 / problem.wnn)) if rho is None else rho
    start = time.perf_counter()
    lu = body_admm.factorise(problem.D, problem.A, rho)
    return time.perf_counter() - start, lu.L.nnz + lu.U.nnz, problem.D.size


def measure(found):
    """Rows {problem, points, method, reach (target -> (iterations, seconds) or None), best,
    best_at, iterations, seconds, factorisations, factor_seconds, rho, per_iteration} of the NLGS
    and every ADMM variant on every problem of ``found``; probes {problem, kind, setting, reach,
    best} on the first problem of each size."""
    rows, probes = [], []
    admm_run(found[0][1], cap=5)  # compile or load the projection's kernel off the record
    for label, entry in found:
        W, q, mu = entry["W"], entry["q"], entry["mu"]
        trajectory, best_impulse = nlgs_run(W, q, mu, entry["initial"])
        best = min(trajectory, key=lambda p: p[2])
        rows.append(dict(problem=label, points=mu.size, method="nlgs", reach={t: reached(trajectory, t) for t in TARGETS},
                         best=best[2], best_at=best[0], iterations=trajectory[-1][0], seconds=trajectory[-1][1],
                         per_iteration=trajectory[-1][1] / max(trajectory[-1][0], 1)))
        print(f"{label}: nlgs {rows[-1]['reach']}, best {best[2]:.2e} at {best[0]}", flush=True)
        for name, options in VARIANTS.items():
            record, solution = admm_run(entry, **options)
            checks = [(it, sec, res) for it, res, rho, sec in record["checks"]]
            best_check = min(checks, key=lambda p: p[2])
            rows.append(dict(problem=label, points=mu.size, method=name, reach={t: reached(checks, t) for t in TARGETS},
                             best=best_check[2], best_at=best_check[0], iterations=solution.iterations,
                             seconds=record["seconds"], factorisations=record["factorisations"],
                             factor_seconds=record["factor_seconds"], rho=record["rho"],
                             per_iteration=(record["seconds"] - record["factor_seconds"]) / max(solution.iterations, 1),
                             admm=record["admm"]))
            print(f"  {name}: {rows[-1]['reach']}, best {best_check[2]:.2e} at {best_check[0]}, "
                  f"{record['factorisations']} factorisations, {record['seconds']:.2f} s", flush=True)
        if label.endswith("#1"):
            probes += probe(label, entry, best_impulse)
    return rows, probes


def probe(label, entry, reference):
    """The probes of why (module docstring of the results): rho held at factors of the default
    (no balancing); the shift held at s* = mu |u_t| of the NLGS's best impulses ``reference``,
    at the default rho and 100 times it; one factorisation's seconds and fill."""
    from solver.contact_solution import natural_map

    out = []
    _, velocity = natural_map(entry["W"], entry["q"], entry["mu"], reference)
    s_star = entry["mu"] * np.abs(velocity[:, 1])
    rho0 = float(np.median(1.0 / entry["W"].diagonal()[0::2]))
    settings = [("rho held", f"{f:g} x default", dict(rho=f * rho0, balance_every=0)) for f in RHO_FACTORS]
    settings += [("shift held at s*", f"rho {f:g} x default", dict(rho=f * rho0, balance_every=0, fixed_shift=s_star))
                 for f in (1.0, 100.0)]
    for kind, setting, options in settings:
        record, _ = admm_run(entry, cap=PROBE_CAP, **options)
        checks = [(it, sec, res) for it, res, rho, sec in record["checks"]]
        best = min(checks, key=lambda p: p[2])
        out.append(dict(problem=label, kind=kind, setting=setting, reach=reached(checks, TARGETS[0]), best=best[2],
                        best_at=best[0]))
        print(f"  probe {kind}, {setting}: {out[-1]['reach']}, best {best[2]:.2e}", flush=True)
    seconds, fill, unknowns = factor_fill(entry)
    out.append(dict(problem=label, kind="factorisation", setting=f"{unknowns} unknowns, nnz(L + U) {fill}",
                    reach=None, best=seconds, best_at=None))
    return out


def spectrum(label="pentagons 1000 #1"):
    """Print the eigenvalues sigma of W on the closed face of the NLGS's best solution of the
    problem ``label`` (the normal rows of its loaded points, the tangential rows of its sticking
    ones; dense, so for the 1000-particle problems), as rho sigma with rho the ADMM's default:
    near a solution the ADMM's multipliers on that face contract by 1 / (1 + rho sigma) per
    iteration (on a face of equalities the ADMM is the augmented-Lagrangian, proximal-point
    iteration on the impulses, and A (D + rho A^T A)^-1 rho A^T = rho W (I + rho W)^-1)."""
    entry = dict(problems())[label]
    W, q, mu = entry["W"], entry["q"], entry["mu"]
    _, reference = nlgs_run(W, q, mu, entry["initial"])
    loaded = reference[:, 0] > 0
    sticking = loaded & (np.abs(reference[:, 1]) < mu * reference[:, 0] * (1 - 1e-9))
    rows = np.sort(np.concatenate([2 * np.nonzero(loaded)[0], 2 * np.nonzero(sticking)[0] + 1]))
    sigma = np.linalg.eigvalsh(W[rows][:, rows].toarray())
    rho = float(np.median(1.0 / W.diagonal()[0::2]))
    print(f"{label}: {mu.size} points, {loaded.sum()} loaded ({sticking.sum()} sticking), "
          f"{entry['H'].shape[1] // 3} bodies; face rows {rows.size}; rho {rho:.3g} kg; rho sigma_max "
          f"{rho * sigma[-1]:.3g}; smallest rho sigma above 1e-12: {rho * sigma[rho * sigma > 1e-12][:3]}")
    for bound in (1e-12, 1e-6, 1e-4, 1e-3, 1e-2, 1e-1):
        print(f"  rho sigma < {bound:g}: {int(np.sum(rho * sigma < bound))} eigenvalues "
              f"(a mode at {bound:g} loses a decade in {np.log(10) / np.log1p(bound):.3g} iterations)")


def _cell(reach, cap_words):
    return f"{reach[0]}, {reach[1]:.3g} s" if reach else f"not reached ({cap_words})"


def tables(rows, probes):
    """The Markdown tables of :func:`measure`'s rows and probes."""
    from benchmarks.common import markdown_table

    header = ["problem", "points", "method", "to 1e-4: iterations, s", "to 1e-6: iterations, s", "best (at)",
              "s per iteration", "factorisations, s", "rho (kg)"]
    lines = []
    for r in rows:
        cap = f"{r['iterations']} in {r['seconds']:.3g} s"
        lines.append([r["problem"], r["points"], r["method"], _cell(r["reach"][TARGETS[0]], cap),
                      _cell(r["reach"][TARGETS[1]], cap), f"{r['best']:.2e} ({r['best_at']})",
                      f"{r['per_iteration']:.3g}",
                      f"{r['factorisations']}, {r['factor_seconds']:.3g}" if "factorisations" in r else "",
                      " -> ".join(f"{x:.3g}" for x in r["rho"][:8]) + (" ..." if len(r.get("rho", [])) > 8 else "")
                      if "rho" in r else ""])
    first = markdown_table(header, lines)
    probe_lines = [[p["problem"], p["kind"], p["setting"],
                    (f"{p['best']:.3g} s" if p["kind"] == "factorisation" else _cell(p["reach"], f"{PROBE_CAP} cap")),
                    "" if p["kind"] == "factorisation" else f"{p['best']:.2e} ({p['best_at']})"] for p in probes]
    second = markdown_table(["problem", "probe", "setting", f"to 1e-4 (cap {PROBE_CAP}) / one factorisation",
                             "best (at)"], probe_lines)
    return first + "\n\n" + second


def verdict(rows):
    """The plain statement: ADMM's (default) iterations to 1e-4 at 1000 and at 14,400, flat within
    1.5x and at most 100?, and its time against the NLGS's."""
    words = []
    for method in VARIANTS:
        per_size = {}
        for n in PARTICLES:
            mine = [r for r in rows if r["method"] == method and r["problem"].startswith(f"pentagons {n} ")]
            if mine:
                per_size[n] = [r["reach"][TARGETS[0]][0] if r["reach"][TARGETS[0]] else None for r in mine]
        shown = "; ".join(f"{n}: {', '.join('-' if x is None else str(x) for x in v)}" for n, v in per_size.items())
        small, large = per_size.get(PARTICLES[0]), per_size.get(PARTICLES[-1])
        if small and large and None not in small + large:
            flat = max(large) <= 1.5 * max(small) and max(large) <= 100
            words.append(f"{method}: iterations to 1e-4 per problem ({shown}); flat within 1.5x and <= 100: "
                         f"{'yes' if flat else 'no'}.")
        else:
            words.append(f"{method}: iterations to 1e-4 per problem ({shown}; '-': not within {ADMM_CAP}); "
                         "flat within 1.5x and <= 100: no.")
    ratios = []
    for r in rows:
        if r["method"] == "admm":
            nlgs = next(x for x in rows if x["problem"] == r["problem"] and x["method"] == "nlgs")
            a, b = r["reach"][TARGETS[0]], nlgs["reach"][TARGETS[0]]
            ratios.append(f"{r['problem'].replace('pentagons ', '')}: " + (f"{a[1] / b[1]:.2g}x" if a and b else
                                                                           "ADMM not reached" if b else "-"))
    words.append("ADMM's seconds to 1e-4 over the NLGS's: " + "; ".join(ratios) + ".")
    return "\n".join(f"* {w}" for w in words)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build-from", metavar="FILE", help="capture the problems from a biaxial test's file "
                        "(only read) at snapshot --index")
    parser.add_argument("--index", type=int, default=2, help="the snapshot of --build-from (default 2)")
    parser.add_argument("--only", metavar="LABELS", help="the problems whose label starts with one of these "
                        "(comma-separated, e.g. 'pentagons 1000')")
    parser.add_argument("--out", help="write the tables here (Markdown)")
    parser.add_argument("--spectrum", nargs="?", const="pentagons 1000 #1", metavar="LABEL",
                        help="print W's spectrum on the closed face of one problem (spectrum(); default "
                        "%(const)s; dense: 4000 takes a minute and 2 GiB)")
    args = parser.parse_args()
    if args.build_from:
        capture(args.build_from, args.index)
        raise SystemExit(0)
    if args.spectrum:
        spectrum(args.spectrum)
        raise SystemExit(0)
    from benchmarks.common import measured, results_text, write_text_keeping_notes

    found = problems()
    if args.only:
        prefixes = tuple(p.strip() for p in args.only.split(","))
        found = [p for p in found if p[0].startswith(prefixes)]
    if not found:
        raise SystemExit(f"no problem in {DATA} (build them first: --build-from FILE)" +
                         (f" whose label starts with {args.only}" if args.only else ""))
    (rows, probes), run_line = measured(lambda: measure(found), "one thread (nice)")
    text = "\n\n".join([verdict(rows), tables(rows, probes)])
    print(text)
    with open(os.path.join(DATA, "rows.pkl"), "wb") as fh:
        pickle.dump((rows, probes), fh)
    if args.out:
        write_text_keeping_notes(args.out, results_text(TITLE, INTRO, [run_line, text]))
