"""What a step needs against what the NLGS's stopping test tracks: on the stepper's pentagon
problems at 1000, 4000 and 14,400 particles (the body-space problems of benchmarks/body_admm.py),
the sweeps at which the body velocities, the impulses (split into the part that moves the bodies
and the self-stress part that does not), the contact laws' sign conditions, the local-law
residual and the NLGS's own stopping norm each first come within 1e-1, 1e-2, 1e-3 and 1e-4 of
their scale; where a stopping test would stop and what it would leave; and how far apart two
solutions of the same problem are.

    nice -n 10 python -m benchmarks.stopping_rule --only "pentagons 1000"      # 2 minutes
    nice -n 10 python -m benchmarks.stopping_rule --only "pentagons 1000 #1" --sweeps 4000   # seconds
    nice -n 10 python -m benchmarks.stopping_rule --out benchmarks/results/stopping-rule.md  # ~35 min

The problems: benchmarks/_data/body_space/pentagon_<N>.pkl (``python -m benchmarks.body_admm
--build-from ...`` captures them: H, M^-1, v_free, the Signorini shifts, mu, the warm start the
stepper gave its NLGS, W = H M^-1 H^T and q = H v_free + (bias, 0)), three problems per size.

Per problem, plain NLGS sweeps on the matrix form (solver.nlgs.solve_matrix, as
benchmarks.contact_solvers runs them) from the stored warm start, REFERENCE_SWEEPS (``--sweeps``)
in all, in one run (:func:`track`):

1. up to half of them (MEASURE_CAP), a record after every sweep up to 50, then every
   max(1, k / 50) sweeps (2% of the k sweeps done), the impulses kept;
2. the impulses at the end are the reference r_ref; every record's errors are then measured
   against it. The floor: the errors of the last record (half the sweeps) against r_ref; the
   reference is no better than that, so a level below the floor is not resolved;
3. the spread: the same number of sweeps from r = 0 instead of the warm start, its end measured
   against r_ref (with its own local-law residual): how far apart two near-solutions of the same
   problem are; an error below the spread is below what the contact laws determine.

The quantities, each over its scale:

* ``residual``: the local-law residual |F| / |r| (solver.contact_solution, the natural map);
* ``quadratic norm``: the NLGS's stopping norm of the last sweep, sqrt(sum_k dr_k W_k dr_k /
  sum_k r_k W_k r_k), W_k the points' 2x2 diagonal blocks (solver/nlgs.py), which the stepper
  compares with its tolerance 1.7e-4 (and the max norm with 1e-2);
* ``velocity``: |v - v_ref|_M / |v_ref - v_free|_M with v = v_free + M^-1 H^T r the bodies'
  end-of-step velocities (m s-1, rad s-1), |x|_M^2 = x . M x over the degrees of freedom that
  move (M^-1 > 0); equal to sqrt(dr . W dr / r_ref . W r_ref), dr = r - r_ref, since
  |M^-1 H^T dr|_M^2 = dr . H M^-1 H^T dr; the scale is the velocity change the step's impulses
  make;
* ``velocity / speed``: the same error over |v_ref|_M, the velocities themselves;
* ``impulse``: |r - r_ref| / |r_ref| (N s, Euclidean over all points);
* ``moving part``, ``self-stress part``: |P dr| / |r_ref| and |(I - P) dr| / |r_ref|, P the
  orthogonal projection onto range(W) = range(H M^-1/2) (:class:`Split`): (I - P) dr is the part
  of the impulse error that moves no body (null(M^-1 H^T): self-equilibrated, or on a wall held
  fixed); the two add up in squares to ``impulse``;
* ``penetration``: the largest approaching velocity max_k max(0, -u_n,k) over all points,
  u = W r + q (the Signorini shift b_k already in q_n), in units of U = the root mean square over
  the points of |W r_ref| (the relative velocity the reference impulses make);
* ``misdirected slip``: the largest |u_t| / U over the loaded points with friction (r_n > 0,
  mu > 0) whose friction does not oppose their slip (r_t u_t >= 0, u_t != 0);
* ``velocity change``: a stopping norm the stepper could compute, the change of the body
  velocities over the last sweep, |dv|_M / |v - v_free|_M = sqrt(d . W d / r . W r), d the
  impulse change over that sweep.

The stopping tests (table "where a test stops"): the stepper's (quadratic norm <= 1.7e-4 and max
norm <= 1e-2, plain sweeps; the stepper's default, Anderson sweeps, stops on the same norms) and
the velocity change <= 1.7e-4 and 1.7e-5, each at the first measured sweep that passes it (so to
within 2%), with the errors left there. One run, the cores shared (nice, one thread).
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, "results", "stopping-rule.md")
LEVELS = (1e-1, 1e-2, 1e-3, 1e-4)
REFERENCE_SWEEPS = 100_000
MEASURE_CAP = REFERENCE_SWEEPS // 2
STEPPER_TOLERANCE, STEPPER_MAX_TOLERANCE = 1.7e-4, 1e-2
CANDIDATE_TOLERANCES = (1.7e-4, 1.7e-5)
QUANTITIES = ("residual", "quadratic norm", "velocity", "velocity / speed", "impulse", "moving part",
              "self-stress part", "penetration", "misdirected slip", "velocity change")
"""The measured quantities (module docstring), each already divided by its scale."""
ERRORS = ("velocity", "velocity / speed", "impulse", "moving part", "self-stress part")
"""Those measured against the reference: their floor is the reference's own error."""
RELATIVE_REGULARISATION = 1e-12


class Split:
    """The orthogonal split of an impulse vector (2P,) into its part in range(W) (it moves the
    bodies) and its part in null(W) = null(M^-1 H^T) (it moves none), for W = H M^-1 H^T with M^-1
    diagonal (3B x 3B): with G = H M^-1/2 (the columns of held degrees of freedom, M^-1 = 0,
    dropped), P x = G (G^T G + delta I)^-1 G^T x, delta = RELATIVE_REGULARISATION times the
    largest diagonal entry of G^T G (so a body without contacts, or a direction of a body that no
    contact constrains, costs nothing: G^T x is zero there); range(G) = range(W)."""

    def __init__(self, H, minv):
        from scipy import sparse
        from scipy.sparse.linalg import splu

        diagonal = minv.diagonal()
        if abs(minv - sparse.diags(diagonal)).max() > 0:
            raise ValueError("M^-1 is not diagonal")
        free = np.nonzero(diagonal > 0)[0]
        self.G = (H[:, free] @ sparse.diags(np.sqrt(diagonal[free]))).tocsr()
        normal = (self.G.T @ self.G).tocsc()
        delta = RELATIVE_REGULARISATION * normal.diagonal().max()
        self._lu = splu((normal + delta * sparse.identity(free.size, format="csc")).tocsc())

    def moving(self, x):
        """P x: the part of ``x`` (2P,) in range(W)."""
        return self.G @ self._lu.solve(self.G.T @ x)


def energy(W, x):
    """x . W x for x (2P,)."""
    return float(x @ (W @ x))


def sign_violations(velocity, impulse, mu):
    """(penetration, misdirected slip) in m s-1 of impulses ``impulse`` (P, 2) N s with
    velocities ``velocity`` = W r + q (P, 2) m s-1, Signorini shift included: the largest
    max(0, -u_n) over all points, and the largest |u_t| over the loaded points with friction
    (r_n > 0, mu > 0) whose friction does not oppose their slip (r_t u_t >= 0 and u_t != 0); 0
    where none."""
    penetration = float(np.max(-velocity[:, 0], initial=0.0))
    wrong = (impulse[:, 0] > 0) & (mu > 0) & (impulse[:, 1] * velocity[:, 1] >= 0) & (velocity[:, 1] != 0)
    return penetration, float(np.max(np.abs(velocity[wrong, 1]), initial=0.0))


class Scales:
    """What every quantity of a problem is divided by, from its reference ``reference`` (P, 2):
    |r_ref| (N s), sqrt(r_ref . W r_ref) (= |v_ref - v_free|_M), |v_ref|_M over the degrees of
    freedom that move (M^-1 > 0; M^-1 diagonal) and U = RMS_k |(W r_ref)_k| (m s-1)."""

    def __init__(self, entry, reference):
        W, minv, r = entry["W"], entry["minv"].diagonal(), reference.reshape(-1)
        self.impulse = float(np.linalg.norm(r))
        self.change = np.sqrt(energy(W, r))
        v_ref = entry["v_free"] + entry["minv"] @ (entry["H"].T @ r)
        mass = np.divide(1.0, minv, out=np.zeros(minv.size), where=minv > 0)
        self.speed = float(np.sqrt(np.sum(mass * v_ref ** 2)))
        self.velocity = float(np.sqrt(np.mean(np.sum((W @ r).reshape(-1, 2) ** 2, axis=1))))


def local_measures(W, q, mu, impulse, previous):
    """{residual, velocity change, penetration (m/s), misdirected slip (m/s)} of impulses
    ``impulse`` (P, 2), ``previous`` those one sweep before (module docstring): what needs no
    reference."""
    from solver.contact_solution import local_law_residual, natural_map_at

    r = impulse.reshape(-1)
    velocity = (W @ r + q).reshape(-1, 2)
    violation = natural_map_at(impulse, velocity, mu, 1.0 / W.diagonal()[0::2])
    penetration, slip = sign_violations(velocity, impulse, mu)
    spent = energy(W, r)  # |v - v_free|_M^2
    change = energy(W, r - previous.reshape(-1))
    return {"residual": local_law_residual(violation, impulse), "penetration": penetration,
            "misdirected slip": slip,
            "velocity change": np.sqrt(max(change, 0.0) / spent) if spent > 0 else float("inf")}


def _ratio(value, scale):
    """value / scale; at scale 0, 0 for a value 0 and infinite otherwise."""
    return value / scale if scale > 0 else (0.0 if value == 0 else float("inf"))


def errors(W, impulse, reference, scales, split):
    """{velocity, velocity / speed, impulse, moving part, self-stress part} of impulses
    ``impulse`` (P, 2) against ``reference`` (module docstring), each over its scale
    (:class:`Scales`)."""
    dr = (impulse - reference).reshape(-1)
    moving = split.moving(dr)
    velocity = float(np.sqrt(max(energy(W, dr), 0.0)))  # |v - v_ref|_M
    return {"velocity": _ratio(velocity, scales.change), "velocity / speed": _ratio(velocity, scales.speed),
            "impulse": _ratio(float(np.linalg.norm(dr)), scales.impulse),
            "moving part": _ratio(float(np.linalg.norm(moving)), scales.impulse),
            "self-stress part": _ratio(float(np.linalg.norm(dr - moving)), scales.impulse)}


def _sweeps(matrix, impulse, count):
    """Run ``count`` >= 1 NLGS sweeps on ``matrix`` from ``impulse`` (P, 2), updated in place;
    returns (quadratic norm, max norm) of the last sweep (solver.nlgs.solve_matrix)."""
    from solver import nlgs
    from solver.solve_records import Impulses, Limits

    rn, rt = np.ascontiguousarray(impulse[:, 0]), np.ascontiguousarray(impulse[:, 1])
    _, quad, worst = nlgs.solve_matrix(matrix, Impulses(rn, rt), Limits(1e-300, 1e-300, int(count), 0))
    impulse[:, 0], impulse[:, 1] = rn, rt
    return float(quad), float(worst)


def schedule(done, cap):
    """The sweeps to run before the next record, ``done`` sweeps done: 1 up to 50, then 2% of
    ``done``, never past ``cap``."""
    return min(max(1, done // 50), cap - done)


def track(entry, sweeps=REFERENCE_SWEEPS, cap=MEASURE_CAP, split=None):
    """(records [(sweeps, values)], reference (P, 2), [(sweeps, residual)] of the reference's
    run): NLGS sweeps from the warm start of ``entry``, ``sweeps`` in all, their end the
    reference; up to ``cap`` (<= ``sweeps``) each record (:func:`schedule`) holds every quantity
    of the module docstring, the errors against the reference computed once it is reached."""
    from benchmarks.contact_solvers import as_matrix_problem

    W, q, mu = entry["W"], entry["q"], entry["mu"]
    matrix = as_matrix_problem(W, q, mu)
    impulse = entry["initial"].astype(float).copy()
    records, kept, done = [], [], 0
    while done < cap:
        step = schedule(done, cap)
        if step > 1:
            _sweeps(matrix, impulse, step - 1)
        previous = impulse.copy()
        quad, worst = _sweeps(matrix, impulse, 1)
        done += step
        values = local_measures(W, q, mu, impulse, previous)
        values.update({"quadratic norm": quad, "max norm": worst})
        records.append((done, values))
        kept.append(impulse.copy())
    trajectory = [(done, records[-1][1]["residual"] if records else local_measures(W, q, mu, impulse,
                                                                                   impulse)["residual"])]
    while done < sweeps:
        step = min(max(2, done // 20), sweeps - done)
        _sweeps(matrix, impulse, step)
        done += step
        trajectory.append((done, local_measures(W, q, mu, impulse, impulse)["residual"]))
    reference = impulse
    split = split or Split(entry["H"], entry["minv"])
    scales = Scales(entry, reference)
    for (_, values), kept_impulse in zip(records, kept):
        values.update(errors(W, kept_impulse, reference, scales, split))
        values["penetration"] /= scales.velocity
        values["misdirected slip"] /= scales.velocity
    return records, reference, trajectory


def first_within(records, quantity, level):
    """The sweeps of the first record of [(sweeps, values)] whose ``quantity`` is within
    ``level``; None if none."""
    return next((k for k, values in records if values[quantity] <= level), None)


def stops(records):
    """[(test, record (sweeps, values) or None)] of the stopping tests (module docstring)."""
    tests = [(f"stepper: quadratic <= {STEPPER_TOLERANCE:g}, max <= {STEPPER_MAX_TOLERANCE:g}",
              lambda v: v["quadratic norm"] <= STEPPER_TOLERANCE and v["max norm"] <= STEPPER_MAX_TOLERANCE)]
    tests += [(f"velocity change <= {t:g}", lambda v, t=t: v["velocity change"] <= t) for t in CANDIDATE_TOLERANCES]
    return [(name, next(((k, v) for k, v in records if test(v)), None)) for name, test in tests]


def study(label, entry, sweeps=REFERENCE_SWEEPS, cap=MEASURE_CAP, spread=True):
    """One problem: its tracked records, reference, floor and (``spread``) the spread between
    solutions, as a dict (module docstring)."""
    start = time.perf_counter()
    split = Split(entry["H"], entry["minv"])
    records, reference, trajectory = track(entry, sweeps, cap, split)
    scales = Scales(entry, reference)
    r = reference.reshape(-1)
    out = dict(problem=label, points=entry["mu"].size, bodies=entry["H"].shape[1] // 3,
               loaded=int(np.sum(reference[:, 0] > 0)), reference_sweeps=sweeps,
               reference_residual=trajectory[-1][1], best_residual=min(x for _, x in trajectory),
               floor=records[-1][1], self_stress=float(np.linalg.norm(r - split.moving(r))) / scales.impulse,
               speed_ratio=scales.speed / scales.change, U=scales.velocity, records=records, spread=None)
    if spread:
        _, other, other_trajectory = track(dict(entry, initial=np.zeros_like(entry["initial"])), sweeps, 0, split)
        out["spread"] = dict(errors(entry["W"], other, reference, scales, split), residual=other_trajectory[-1][1])
    out["seconds"] = time.perf_counter() - start
    print(f"{label}: reference residual {out['reference_residual']:.2e}; floor: " +
          ", ".join(f"{x} {out['floor'][x]:.1e}" for x in ERRORS) + ("; spread: " + ", ".join(
              f"{x} {out['spread'][x]:.1e}" for x in ERRORS + ('residual',)) if spread else "") + "; to 1e-4: " +
          ", ".join(f"{x} {first_within(records, x, LEVELS[-1])}" for x in QUANTITIES) + f" ({out['seconds']:.0f} s)",
          flush=True)
    return out


def _size(row):
    return int(row["problem"].split()[1])


def tables(rows):
    """The Markdown tables of the rows of :func:`study`: the references, the sweeps to each level
    per size, and where each stopping test stops."""
    from benchmarks.common import markdown_table

    def errors_cell(values):
        return "-" if values is None else ", ".join(f"{values[q]:.1e}" for q in ERRORS)

    first = markdown_table(
        ["problem", "points (loaded)", "bodies", "reference: sweeps, residual (best)", "floor: velocity, velocity / "
         "speed, impulse, moving, self-stress", "spread (from r = 0): the same; its residual",
         "self-stress share of r_ref", "|v_ref|_M / |v_ref - v_free|_M", "U (m/s)"],
        [[r["problem"], f"{r['points']} ({r['loaded']})", r["bodies"],
          f"{r['reference_sweeps']}, {r['reference_residual']:.2e} ({r['best_residual']:.2e})",
          errors_cell(r["floor"]), errors_cell(r["spread"]) + ("" if r["spread"] is None else
                                                              f"; {r['spread']['residual']:.1e}"),
          f"{r['self_stress']:.2f}", f"{r['speed_ratio']:.3g}", f"{r['U']:.3g}"] for r in rows])
    out = [first]
    for n in sorted({_size(r) for r in rows}):
        mine = [r for r in rows if _size(r) == n]
        body = []
        for quantity in QUANTITIES:
            cells = []
            for r in mine:
                found = [first_within(r["records"], quantity, level) for level in LEVELS]
                cells.append(" / ".join("-" if k is None else str(k) for k in found))
            body.append([quantity] + cells)
        out.append(f"Sweeps to {' / '.join(f'{x:g}' for x in LEVELS)} of the scale, {n} pentagons ('-': not within "
                   f"{mine[0]['records'][-1][0]} sweeps):\n\n" +
                   markdown_table(["quantity"] + [r["problem"].split()[-1] for r in mine], body))
    shown = ("velocity", "velocity / speed", "impulse", "moving part", "self-stress part", "residual", "penetration",
             "misdirected slip")
    lines = []
    for r in rows:
        for name, record in stops(r["records"]):
            if record is None:
                lines.append([r["problem"], name, f"not within {r['records'][-1][0]}"] + [""] * len(shown))
            else:
                lines.append([r["problem"], name, record[0]] + [f"{record[1][q]:.1e}" for q in shown])
    out.append("Where a test stops, and the errors it leaves:\n\n" + markdown_table(
        ["problem", "test", "sweeps"] + list(shown), lines))
    return "\n\n".join(out)


def verdict(rows):
    """Per size, the medians over its problems of: the sweeps of the stepper's stop and the
    velocity error left there, the sweeps to 1e-4 of the residual and to 1e-1 and 1e-2 of the
    velocity ('-' where a problem does not get there); the growth of each from the smallest size
    to the largest."""
    def median(values):
        return None if not values or None in values else float(np.median(values))

    def show(x, digits="g"):
        return "-" if x is None else format(x, digits)

    sizes = sorted({_size(r) for r in rows})
    table = {}
    for n in sizes:
        mine = [r for r in rows if _size(r) == n]
        stopped = [stops(r["records"])[0][1] for r in mine]
        table[n] = dict(stepper=median([None if s is None else s[0] for s in stopped]),
                        left=median([None if s is None else s[1]["velocity"] for s in stopped]),
                        residual=median([first_within(r["records"], "residual", 1e-4) for r in mine]),
                        velocity=median([first_within(r["records"], "velocity", 1e-1) for r in mine]),
                        velocity2=median([first_within(r["records"], "velocity", 1e-2) for r in mine]))
    words = [f"{n} pentagons, medians of {len([r for r in rows if _size(r) == n])}: the stepper's test stops at "
             f"{show(t['stepper'])} sweeps with a velocity error of {show(t['left'], '.2g')}; the residual is within "
             f"1e-4 at {show(t['residual'])} sweeps; the velocity error within 1e-1 at {show(t['velocity'])} and "
             f"within 1e-2 at {show(t['velocity2'])}." for n, t in table.items()]
    if len(sizes) > 1:
        small, large = table[sizes[0]], table[sizes[-1]]
        grow = [f"{name} {large[key] / small[key]:.2g}x" for name, key in
                (("stepper's stop", "stepper"), ("residual to 1e-4", "residual"), ("velocity to 1e-1", "velocity"))
                if small[key] and large[key]]
        words.append(f"from {sizes[0]} to {sizes[-1]} pentagons the sweeps grow: " + ", ".join(grow) + ".")
    return "\n".join(f"* {w}" for w in words)


TITLE = "Stopping rules: what a step needs against what the NLGS's test tracks"
INTRO = ("Written by `python -m benchmarks.stopping_rule --out benchmarks/results/stopping-rule.md` (its docstring "
         "defines every quantity, its scale, the reference, the floor and the spread): on the stepper's pentagon "
         "problems, the sweeps of plain NLGS from the stored warm start at which each quantity first comes within "
         "1e-1, 1e-2, 1e-3 and 1e-4 of its scale, and where the stepper's stopping test and a test on the body "
         "velocities' change over a sweep would stop, with the errors they leave. Errors are against the same "
         "sweeps run to {sweeps:,} (the reference); the floor is the error of {half:,} sweeps against it; the spread "
         "is the difference between the reference and {sweeps:,} sweeps from r = 0.")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--only", metavar="LABELS", help="the problems whose label starts with one of these "
                        "(comma-separated, e.g. 'pentagons 1000')")
    parser.add_argument("--sweeps", type=int, default=REFERENCE_SWEEPS, help="the reference's sweeps (default "
                        "%(default)s; the records go to half of them)")
    parser.add_argument("--out", help="write the tables here (Markdown)")
    args = parser.parse_args()
    from benchmarks.body_admm import DATA, problems
    from benchmarks.common import measured, results_text, write_text_keeping_notes

    found = problems()
    if args.only:
        found = [p for p in found if p[0].startswith(tuple(s.strip() for s in args.only.split(",")))]
    if not found:
        raise SystemExit(f"no problem in {DATA} (benchmarks/body_admm.py --build-from FILE captures them)" +
                         (f" whose label starts with {args.only}" if args.only else ""))
    rows, run_line = measured(lambda: [study(label, entry, args.sweeps, args.sweeps // 2) for label, entry in found],
                             "one thread (nice)")
    text = "\n\n".join([verdict(rows), tables(rows)])
    print(text)
    if args.out:
        intro = INTRO.format(sweeps=args.sweeps, half=args.sweeps // 2)
        write_text_keeping_notes(args.out, results_text(TITLE, intro, [run_line, text]))
