"""Why a large sheared packing needs more sweeps per step: the anatomy of its slow steps.

    python -m benchmarks.archive.sweep_bursts --sample benchmarks/_data/time_to_strain/sample_pentagon_14400_fast.pkl

A 14,400-pentagon shear needs three times the sweeps per step of a 4000-pentagon one, in bursts
of consecutive steps that end at the stall test (benchmarks/archive/solver-log.md, "At 14,400 pentagons"). This
script shears a saved sample (``benchmarks/compaction.py --save``) as archive/time_to_strain.py does
(Anderson sweeps extrapolated every 2 sweeps, stall test over 200 sweeps, one domain), captures
the contact problem of shear steps ``--steps A B`` with its warm start, and asks of each
*burst* step (at least ``--burst`` sweeps) and of the quiet steps:

1. **Where** its impulse changes are: the contact points binned in a 24 x 24 grid over the
   box, the share of cells that carry 90% of the sum of dV_k^2 = dp_k . W_k dp_k (the NLGS's
   own measure of a change, :mod:`solver.nlgs`) over sweeps 21 to the last. A local
   rearrangement would put it in a few cells.
2. **Cycling or drifting**: over plain sweeps 101-400, the net change of each point's impulse
   over the sum of its per-sweep changes (both in the point's W_k norm, so the ratio is <= 1 by
   the triangle inequality): near 0 for points that cycle (e.g. the two points of a double
   contact trading their load), 1 for a steady drift.
3. **Does the drift move the bodies**: the RMS change of the points' relative velocities over
   those sweeps against the RMS of W_k dp_k, the velocity change each point's impulse change
   would make alone. A small ratio means the impulses redistribute among the contacts (a
   self-stress-like change) without changing the motion.
4. The local-law residual (:mod:`solver.residuals`) after 20, 100 and 400 plain sweeps.
5. **Two remedies, re-solved offline** on the captured problems: Anderson memories 3, 8 and
   12, and the warm start extrapolated from the last two steps' impulses,
   p_k + f (p_k - p_(k-1)) projected onto the Coulomb cone, for f = 0, 0.5, 1 (each step
   re-solved from the captured trajectory; a real run's own trajectory responds to it, and
   benchmarks/archive/solver-log.md reports what that did).
6. **A lead**: on the steps of items 1-4, the iterations a Jacobi-scaled accelerated projected
   gradient (:func:`apgd_probe`, numpy) needs to reach the local-law residual that the default
   NLGS reached on the same step. ``--apgd-shear EPS_Q`` then shears the sample to that eps_q
   twice, with the default solve and with the probe as the step's solve (:func:`shear`), and
   adds a table of the two runs.

Writes benchmarks/archive/sweep-bursts-<N>.md.
"""
import argparse
import os
import time

import numpy as np

from benchmarks.common import load_sample, markdown_table, write_results
from benchmarks.shear import Done as _Done, capture, shear as _shear

HERE = os.path.dirname(os.path.abspath(__file__))
GRID = 24
"""Cells per side of the grid over the box in which the changes are binned."""


def _w_norm(dpn, dpt, wnn, wnt, wtt):
    return np.sqrt(np.maximum(dpn * (wnn * dpn + wnt * dpt) + dpt * (wnt * dpn + wtt * dpt), 0.0))


def _relative_velocity(problem, vx, vy, w):
    """Normal and tangential relative velocity (b minus a) at every point, m s-1."""
    P = problem
    ua_x, ua_y = vx[P.a] - w[P.a] * P.ray, vy[P.a] + w[P.a] * P.rax
    ub_x, ub_y = vx[P.b] - w[P.b] * P.rby, vy[P.b] + w[P.b] * P.rbx
    dx, dy = ub_x - ua_x, ub_y - ua_y
    return dx * P.nx + dy * P.ny, -dx * P.ny + dy * P.nx


def anatomy(case: dict, bounds, n_particles: int, sweeps: int = 400, drift_from: int = 100) -> dict:
    """Plain NLGS sweeps on one captured step (``case`` from :func:`capture`), from its warm
    start: the share of grid cells carrying 90% of the change over sweeps 21..``sweeps``, the
    net-over-gross ratio and the velocity ratio over sweeps ``drift_from``+1..``sweeps``
    (module docstring, items 1-3), and the quadratic norm and local-law residual after sweeps
    20, ``drift_from`` and ``sweeps``."""
    from solver import nlgs, residuals
    from solver.solve_records import Impulses, Velocities

    P = case["problem"]
    m = P.a.size
    pn, pt = case["pn"].copy(), case["pt"].copy()
    vx, vy, w = case["vx"].copy(), case["vy"].copy(), case["w"].copy()
    impulses, velocities = Impulses(pn, pt), Velocities(vx, vy, w)
    blocks = nlgs.delassus(P)
    wnn, wnt, wtt = blocks
    nlgs.velocities_from_impulses(P, impulses, velocities)
    lo, hi = bounds
    pos = case["position"]
    on_a = P.a < n_particles
    body = np.where(on_a, P.a, P.b)
    arm = np.where(on_a[:, None], np.stack([P.rax, P.ray], -1), np.stack([P.rbx, P.rby], -1))
    where = pos[np.minimum(body, n_particles - 1)] + arm
    cx = np.clip(((where[:, 0] - lo[0]) / (hi[0] - lo[0]) * GRID).astype(int), 0, GRID - 1)
    cy = np.clip(((where[:, 1] - lo[1]) / (hi[1] - lo[1]) * GRID).astype(int), 0, GRID - 1)
    cell = cx * GRID + cy
    order = np.arange(m)
    change = np.zeros(m)
    gross = np.zeros(m)
    checkpoints = {}
    for it in range(1, sweeps + 1):
        pn0, pt0 = pn.copy(), pt.copy()
        total, largest, _, _ = nlgs.sweep(order, P, impulses, velocities, blocks)
        dv = _w_norm(pn - pn0, pt - pt0, wnn, wnt, wtt)
        if it > 20:
            change += dv ** 2
        if it > drift_from:
            gross += dv
        if it == drift_from:
            start = (pn.copy(), pt.copy(), *_relative_velocity(P, vx, vy, w))
        if it in (20, drift_from, sweeps):
            quad, _ = nlgs.norms(total, largest, impulses, blocks)
            checkpoints[it] = (float(quad), residuals.local_law_residual(P, pn, pt, vx, vy, w))
    per_cell = np.sort(np.bincount(cell, change, GRID * GRID))[::-1]
    cells90 = (np.searchsorted(np.cumsum(per_cell) / per_cell.sum(), 0.9) + 1) / GRID ** 2
    dpn, dpt = pn - start[0], pt - start[1]
    net = _w_norm(dpn, dpt, wnn, wnt, wtt)
    un, ut = _relative_velocity(P, vx, vy, w)
    own = np.hypot(wnn * dpn + wnt * dpt, wnt * dpn + wtt * dpt)
    moved = np.sqrt(np.mean((un - start[2]) ** 2 + (ut - start[3]) ** 2))
    return dict(cells90=float(cells90), net_over_gross=float(net.sum() / gross.sum()),
                velocity_ratio=float(moved / np.sqrt(np.mean(own ** 2))), checkpoints=checkpoints)


def _velocities(problem, free, pn, pt):
    """Body velocities (vx, vy, w) = free + M^-1 H p (the NLGS's own kernel)."""
    from solver import nlgs
    from solver.solve_records import Impulses, Velocities

    velocities = Velocities(*(v.copy() for v in free))
    nlgs.velocities_from_impulses(problem, Impulses(np.ascontiguousarray(pn), np.ascontiguousarray(pt)), velocities)
    return tuple(velocities)


def _cone_projections(zn, zt, mu):
    """Projection of every (zn, zt) onto its Coulomb cone {|t| <= mu n} (as
    solver.residuals.cone_projection, point by point)."""
    at = np.abs(zt)
    inside = (zn >= 0.0) & (at <= mu * zn)
    polar = mu * at <= -zn
    edge = (zn + mu * at) / (1.0 + mu * mu)
    return (np.where(inside, zn, np.where(polar, 0.0, edge)),
            np.where(inside, zt, np.where(polar, 0.0, np.sign(zt) * mu * edge)))


def apgd_probe(case: dict, target: float, iterations: int = 400, check_every: int = 10, seed: int = 0,
               stop: bool = False):
    """Accelerated projected gradient on one captured step, from its warm start: the first
    iteration (a multiple of ``check_every``) at which the local-law residual is <= ``target``
    (None if none within ``iterations``), and the lowest residual met with its impulses
    (``stop``: return at that first iteration).

    The iteration (Nesterov's method with the gradient-restart test, as APGD in Project Chrono)
    on impulses p in the cones K_k = {|p_t| <= mu_k p_n}:
    g = u(y) + (b_k + mu_k |u_t(y)|, 0), the relative velocities u(y) of the bodies moved by the
    free velocities and the impulses y, shifted by the Signorini term and De Saxcé's mu |u_t|
    (so that a fixed point satisfies the Coulomb law, not its associated relaxation);
    p+ = proj_K(y - t D g), D = diag(1 / W_nn,k) (a Jacobi scaling), t = 1 / (1.05 L) with L the
    largest eigenvalue of D^(1/2) W D^(1/2) by 20 power iterations; y+ = p+ + beta (p+ - p),
    beta from theta_(k+1)^2 = (1 - theta_(k+1)) theta_k^2, reset to y+ = p+ when g . (p+ - p) > 0.
    A probe in numpy, not a solver: the De Saxcé shift taken at the current iterate makes the
    map non-monotone, and the residual can rise again after its minimum."""
    from solver import nlgs, residuals

    P = case["problem"]
    free = (case["vx"], case["vy"], case["w"])
    wnn = nlgs.delassus(P).nn
    scale = 1.0 / wnn
    root = np.sqrt(scale)
    rest = tuple(np.zeros_like(v) for v in free)
    xn, xt = np.random.default_rng(seed).standard_normal((2, P.a.size))
    for _ in range(20):
        un, ut = _relative_velocity(P, *_velocities(P, rest, root * xn, root * xt))
        yn, yt = root * un, root * ut
        norm = np.sqrt(np.sum(yn ** 2 + yt ** 2))
        largest = norm / np.sqrt(np.sum(xn ** 2 + xt ** 2))
        xn, xt = yn / norm, yt / norm
    t = 1.0 / (1.05 * largest)
    pn, pt = case["pn"].copy(), case["pt"].copy()
    yn, yt = pn.copy(), pt.copy()
    theta = 1.0
    best = (residuals.local_law_residual(P, pn, pt, *_velocities(P, free, pn, pt)), pn.copy(), pt.copy())
    reached = None
    for it in range(1, iterations + 1):
        un, ut = _relative_velocity(P, *_velocities(P, free, yn, yt))
        gn, gt = un + P.bias + P.mu * np.abs(ut), ut
        new_n, new_t = _cone_projections(yn - t * scale * gn, yt - t * scale * gt, P.mu)
        next_theta = 0.5 * (-theta ** 2 + theta * np.sqrt(theta ** 2 + 4.0))
        if np.sum(gn * (new_n - pn) + gt * (new_t - pt)) > 0.0:
            yn, yt, next_theta = new_n.copy(), new_t.copy(), 1.0
        else:
            beta = theta * (1.0 - theta) / (theta ** 2 + next_theta)
            yn, yt = new_n + beta * (new_n - pn), new_t + beta * (new_t - pt)
        pn, pt, theta = new_n, new_t, next_theta
        if it % check_every == 0:
            law = residuals.local_law_residual(P, pn, pt, *_velocities(P, free, pn, pt))
            if law < best[0]:
                best = (law, pn.copy(), pt.copy())
            if reached is None and law <= target:
                reached = it
                if stop:
                    break
    return reached, best


def shear(sim, until: float, apgd_target: float = 0.0, apgd_iterations: int = 300) -> dict:
    """Shear ``sim`` to eps_q = ``until`` as :func:`_shear` does; with ``apgd_target`` > 0 each
    step's main solve is :func:`apgd_probe` stopping at that local-law residual, finished by the
    default NLGS from its best iterate when it does not get there within ``apgd_iterations``.
    Returns the per-step work (APGD iterations plus sweeps), local-law residual, unbalanced
    force and the top wall's q/p = (sigma_top - sigma_0) / (sigma_top + sigma_0) (sigma_0 the
    confining stress), the fallbacks and the wall-clock seconds."""
    from solver import acceleration
    from solver.nlgs import NLGSResult

    tolerance = sim.parameters.tolerance
    lo, hi = sim.walls.box_bounds()
    h0, l0 = float(hi[1] - lo[1]), float(hi[0] - lo[0])
    record = {"work": [], "law": [], "unbalanced": [], "q_over_p": [], "fallbacks": 0}
    top = sim.walls.index("top")
    solve = acceleration.solve_problem_anderson

    def probed(problem, pn, pt, vx, vy, w, **options):
        if options["tolerance"] != tolerance:  # the overlap recovery keeps its sweeps
            return solve(problem, pn, pt, vx, vy, w, **options)
        free = (vx.copy(), vy.copy(), w.copy())
        case = dict(problem=problem, pn=pn, pt=pt, vx=free[0], vy=free[1], w=free[2])
        reached, (_, best_n, best_t) = apgd_probe(case, apgd_target, iterations=apgd_iterations, stop=True)
        pn[:], pt[:] = best_n, best_t
        if reached is not None:
            vx[:], vy[:], w[:] = _velocities(problem, free, best_n, best_t)
            return NLGSResult(reached, 0.0, 0.0)
        record["fallbacks"] += 1  # vx, vy, w still hold the free velocities the NLGS starts from
        result = solve(problem, pn, pt, vx, vy, w, **options)
        return NLGSResult(apgd_iterations + result.iterations, result.residual, result.max_residual)

    def record_step(info):
        record["work"].append(info.iterations)
        record["law"].append(info.local_law_residual)
        record["unbalanced"].append(info.unbalanced_force)
        sigma = float(sim.wall_stresses()[top])
        record["q_over_p"].append((sigma - sim.sigma0) / (sigma + sim.sigma0))
        lo, hi = sim.walls.box_bounds()
        if np.log(h0 / float(hi[1] - lo[1])) - np.log(l0 / float(hi[0] - lo[0])) >= until:
            raise _Done

    if apgd_target <= 0:
        record["seconds"] = _shear(sim, record_step)
    else:  # the probe is no solver of the registry: it takes the place of the Anderson sweeps' function here only
        acceleration.solve_problem_anderson = probed
        try:
            record["seconds"] = _shear(sim, record_step)
        finally:
            acceleration.solve_problem_anderson = solve
    return {k: (np.array(v) if isinstance(v, list) else v) for k, v in record.items()}


def point_keys_of(problem) -> np.ndarray:
    """A key per point, the same for the same point in two steps: the stepper's
    :func:`solver.contact_points.point_keys` (body pair and rank in it), the pairs read from the
    problem's arrays, whose points of a pair are consecutive."""
    from solver.contact_points import PairIndex, point_keys

    a, b = problem.a, problem.b
    pair = np.cumsum(np.r_[0, (a[1:] != a[:-1]) | (b[1:] != b[:-1])])
    return point_keys(PairIndex(pair=pair, body_i=a, body_j=b), problem.iinv.size)


def extrapolated(previous: dict, case: dict, factor: float):
    """The warm start p_k + f (p_k - p_(k-1)) of ``case`` from its own warm start p_k and the
    previous captured step's, p_(k-1), at the points of both, projected onto the Coulomb cone."""
    keys, old_keys = point_keys_of(case["problem"]), point_keys_of(previous["problem"])
    order = np.argsort(old_keys)
    where = np.minimum(np.searchsorted(old_keys[order], keys), len(old_keys) - 1)
    hit = old_keys[order][where] == keys
    pn, pt = case["pn"].copy(), case["pt"].copy()
    pn[hit] += factor * (pn[hit] - previous["pn"][order[where[hit]]])
    pt[hit] += factor * (pt[hit] - previous["pt"][order[where[hit]]])
    pn = np.maximum(pn, 0.0)
    mu = case["problem"].mu
    return pn, np.clip(pt, -mu * pn, mu * pn)


def resolve(caught: list, memory: int = 3, factor: float = 0.0) -> np.ndarray:
    """Re-solve the captured steps (all but the first) with Anderson memory ``memory`` from a
    warm start extrapolated by ``factor``: rows (sweeps, seconds, local-law residual)."""
    from solver import acceleration, residuals

    rows = []
    for previous, case in zip(caught[:-1], caught[1:]):
        pn, pt = extrapolated(previous, case, factor) if factor else (case["pn"].copy(), case["pt"].copy())
        vx, vy, w = case["vx"].copy(), case["vy"].copy(), case["w"].copy()
        o = case["options"]
        start = time.perf_counter()
        result = acceleration.solve_problem_anderson(
            case["problem"], pn, pt, vx, vy, w, tolerance=o["tolerance"], max_tolerance=o["max_tolerance"],
            max_iterations=o["max_iterations"], memory=memory, period=2, stall=200, domains=1)
        seconds = time.perf_counter() - start
        rows.append((result.iterations, seconds, residuals.local_law_residual(case["problem"], pn, pt, vx, vy, w)))
    return np.array(rows)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sample", required=True, help="a pickled compacted sample (compaction.py --save)")
    parser.add_argument("--steps", type=int, nargs=2, default=(10, 60), metavar=("A", "B"),
                        help="the shear steps captured (default 10 60)")
    parser.add_argument("--burst", type=int, default=200, help="sweeps that make a step a burst step (default 200)")
    parser.add_argument("--sweeps", type=int, default=400, help="plain sweeps of the anatomy (default 400)")
    parser.add_argument("--apgd-shear", type=float, default=0.0, metavar="EPS_Q",
                        help="also shear to this eps_q with the default solve and with the APGD probe (item 6)")
    parser.add_argument("--apgd-target", type=float, default=1.3e-4,
                        help="the local-law residual at which the probe stops in --apgd-shear (default 1.3e-4)")
    parser.add_argument("--out", help="the results file (default benchmarks/archive/sweep-bursts-<N>.md)")
    args = parser.parse_args(argv)
    sim, _ = load_sample(args.sample)
    n = sim.n_particles
    out = args.out or os.path.join(HERE, f"sweep-bursts-{n}.md")
    bounds = sim.walls.box_bounds()
    caught = capture(sim, *args.steps)
    sweeps = [c["sweeps"] for c in caught]
    print(f"captured steps {args.steps[0]}-{args.steps[1]}: sweeps {sweeps}", flush=True)
    burst = [c for c in caught if c["sweeps"] >= args.burst]
    quiet = [c for c in caught if c["sweeps"] < min(60, args.burst)]
    rows, leads = [], []
    for kind, cases in (("burst", burst[:6]), ("quiet", quiet[:3])):
        for case in cases:
            a = anatomy(case, bounds, n, sweeps=args.sweeps)
            c = a["checkpoints"]
            rows.append([case["step"], kind, case["sweeps"], case["problem"].a.size, f"{a['cells90']:.2f}",
                         f"{a['net_over_gross']:.3f}", f"{a['velocity_ratio']:.4f}",
                         *(f"{c[k][0]:.2e} / {c[k][1]:.2e}" for k in sorted(c))])
            reached, best = apgd_probe(case, case["law"])
            leads.append([case["step"], kind, case["sweeps"], f"{case['law']:.2e}", reached or "not within 400",
                          f"{best[0]:.2e}"])
            print(rows[-1], leads[-1], flush=True)
    anatomy_table = markdown_table(
        ["step", "kind", "sweeps (Anderson)", "points", "cells with 90% of the change", "net / gross change",
         "relative-velocity change / W dp", "quad / law after 20", "after 100", f"after {args.sweeps}"], rows)
    lead_table = markdown_table(["step", "kind", "default: sweeps", "its local-law residual",
                                 "APGD iterations to the same residual", "lowest APGD residual in 400"], leads)
    remedies = []
    for label, memory, factor in (("Anderson memory 3 (default)", 3, 0.0), ("memory 8", 8, 0.0),
                                  ("memory 12", 12, 0.0), ("warm start extrapolated, f = 0.5", 3, 0.5),
                                  ("warm start extrapolated, f = 1", 3, 1.0)):
        r = resolve(caught, memory, factor)
        remedies.append([label, f"{np.median(r[:, 0]):.0f}", f"{r[:, 0].mean():.0f}", f"{np.percentile(r[:, 0], 90):.0f}",
                         f"{r[:, 1].sum():.1f}", f"{np.median(r[:, 2]):.2e}", f"{np.percentile(r[:, 2], 90):.2e}"])
        print(remedies[-1], flush=True)
    remedy_table = markdown_table(["re-solved with", "sweeps median", "mean", "p90", "seconds", "local-law residual median",
                                   "p90"], remedies)
    shears = []
    if args.apgd_shear > 0:
        for label, target in (("default (Anderson every 2 sweeps, stall 200)", 0.0),
                              (f"APGD probe to a local-law residual of {args.apgd_target:g}, else the default", args.apgd_target)):
            run = shear(load_sample(args.sample)[0], args.apgd_shear, target)
            w, late = run["work"], run["q_over_p"][len(run["work"]) // 2:]
            shears.append([label, len(w), f"{np.median(w):.0f}", f"{w.mean():.0f}", f"{np.percentile(w, 90):.0f}",
                           run["fallbacks"] if target else "-", f"{np.median(run['law']):.2e}",
                           f"{np.percentile(run['law'], 90):.2e}", f"{np.median(run['unbalanced']):.3f}",
                           f"{late.mean():.3f}, {late.std():.3f}", f"{run['seconds']:.0f}"])
            print(shears[-1], flush=True)
    sections = []
    if shears:
        sections = [f"## A real shear to eps_q = {args.apgd_shear:g}, default against the probe (one core each, one after the other)",
                    markdown_table(["solve", "steps", "work per step (APGD iterations + sweeps): median", "mean", "p90",
                                    "fallbacks to the NLGS", "local-law residual median", "p90",
                                    "unbalanced force median", "top wall's q/p over the second half of the steps: mean, sd",
                                    "seconds (the probe is numpy)"], shears)]
    intro = (f"Written by `python -m benchmarks.archive.sweep_bursts --sample {os.path.relpath(args.sample, os.path.dirname(os.path.dirname(HERE)))} "
             f"--steps {args.steps[0]} {args.steps[1]}"
             + (f" --apgd-shear {args.apgd_shear:g}" if args.apgd_shear else "") + f"`: {n} particles, shear steps {args.steps[0]}-{args.steps[1]} "
             f"(sweeps per step: {sweeps}). The script's docstring defines each column; benchmarks/archive/solver-log.md "
             "(\"At 14,400 pentagons\") reads them.")
    write_results(out, "The anatomy of slow shear steps", intro,
                  ["## Where the changes are, and what they are (plain NLGS sweeps from the step's warm start)",
                   anatomy_table, "## Remedies, re-solved on the captured steps (one domain)", remedy_table,
                   "## A lead: an accelerated projected gradient (numpy probe, `apgd_probe`)", lead_table] + sections)


if __name__ == "__main__":
    main()
