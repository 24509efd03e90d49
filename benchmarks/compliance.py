"""A regularised (compliant) contact law on the stepper's pentagon problems: how fast the NLGS
and the projected conjugate gradient solve u = (W + eps D) r + q, D = diag(W), and what the
compliance changes in the answer against the rigid one (eps = 0).

    nice -n 10 python -m benchmarks.compliance --out benchmarks/results/compliance.md
    nice -n 10 python -m benchmarks.compliance --only "pentagons 1000"   # a few problems, printed
    nice -n 10 python -m benchmarks.compliance --rigid-sinks   # eps W_nn r_n at the rigid answer's impulses

The problems: benchmarks/_data/body_space/pentagon_<particles>.pkl (1000, 4000, 14,400
pentagons, three steps each; captured by benchmarks/body_admm.py, its docstring), which hold
W, q, mu and the stepper's warm start with the body quantities H, M^-1 (diagonal) and v_free;
at 14,400 they are the problems of benchmarks/_data/contact_solvers/ (the same snapshot).

The compliant law adds eps D r to every point's velocity, u = W r + q + eps D r, on the
normal and the tangential rows (Box2D's soft contact, Chrono's compliance, LMGC90's
regularisation): W + eps D has no eigenvalue below eps min(D), so the nearly self-stressed
modes of W on the closed contacts (results/body-admm.md) become stiff. What is measured, per
problem and eps in EPSILONS:

* speed: sweeps (NLGS, from the stored warm start and from r = 0 (cap COLD_SECONDS s), as the
  rigid warm start holds the rigid answer's self-stress, which the compliant answer drops;
  sweeps in chunks of ~5% of those done, the residual off the clock:
  benchmarks.contact_solvers.nlgs_trajectory's scheme) and iterations
  (``solve_contact_problem(method='pcg')``, tolerance TARGET, cap 20,000, its own stall test)
  and seconds to the regularised problem's own local-law residual |F|/|r| of TARGET
  (solver.contact_solution with W + eps D: rho_k = 1 / ((1 + eps) W_nn,k));
* the regularised answer r_eps: the NLGS run on, to a residual of FAR_STOP or its best within
  NLGS_CAP sweeps or NLGS_SECONDS; the rigid answer r_0 likewise (the NLGS's best within the
  caps, the reference of every comparison);
* against r_0: the relative change of the body velocities |v_eps - v_0|_M / |v_0 - v_free|_M,
  v = v_free + M^-1 H^T r (|x|_M^2 = x^T M x, over the bodies' degrees of freedom of nonzero
  inverse mass, the walls' zero ones left out; checked against the same norm computed as
  (r_eps - r_0)^T W (r_eps - r_0)); the sink speed eps W_nn,k r_n,k of each closed point
  (r_n,k > 0), m/s, the interpenetration the law admits per step, and times the time step
  TIME_STEP the distance per step; the relative change of the total normal impulse; the mean
  normal impulse of the closed points, the fraction of them below it and the largest over it;
  the two-sample Kolmogorov-Smirnov distance of the closed points' normal impulses
  (scipy.stats.ks_2samp); and the rigid problem's local-law residual of r_eps;
* the same comparisons for the rigid problem's own NLGS answer at TARGET (the first chunk within
  it): the error the stepper's present tolerance already makes, the scale to read the others on.

One run per cell, the cores shared (nice, one thread).
"""

from __future__ import annotations

import argparse
import os
import pickle
import time

import numpy as np
from scipy import sparse, stats

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "_data", "body_space")
PARTICLES = (1000, 4000, 14400)
EPSILONS = (0.0, 1e-4, 1e-3, 1e-2, 1e-1)
TARGET = 1e-4
FAR_STOP = 1e-8
NLGS_CAP, NLGS_SECONDS = 20_000, 60.0
COLD_SECONDS = 30.0
PCG_CAP = 20_000
TIME_STEP = 5e-4  # s, the captured runs' (the default)
ALERT = 5e-4  # m, 2% of the smallest diameter 2.5 cm (docs/solver.md, "Defaults and why")
RECOVERY_SPEED = 1e-3  # m/s, the overlap recovery's largest speed (docs/solver.md)
FEW, FLAT = 30, 1.5


def regularised(W, eps):
    """W + eps D (CSR, sorted indices), D = diag(W): the Delassus matrix of the compliant law
    u = W r + q + eps D r (s kg-1)."""
    out = (W + eps * sparse.diags(W.diagonal())).tocsr()
    out.sort_indices()
    return out


def problems(particles=PARTICLES):
    """[(label, entry)] of the body-space problems present in DATA (benchmarks.body_admm)."""
    found = []
    for n in particles:
        path = os.path.join(DATA, f"pentagon_{n}.pkl")
        if os.path.exists(path):
            with open(path, "rb") as fh:
                found += [(f"pentagons {n} #{i + 1}", e) for i, e in enumerate(pickle.load(fh))]
    return found


def nlgs_run(W, q, mu, initial, stop=FAR_STOP, cap=NLGS_CAP, seconds_cap=NLGS_SECONDS, target=TARGET):
    """NLGS sweeps on (W, q, mu) from ``initial`` (n, 2) in chunks of ~5% of the sweeps done
    (benchmarks.contact_solvers.nlgs_run), the local-law residual off the clock, until
    ``stop``, ``cap`` sweeps or ``seconds_cap`` s of sweeping. Returns (trajectory [(sweeps,
    seconds, residual)], best impulses (n, 2), impulses at the first point within ``target``
    or None)."""
    from benchmarks.contact_solvers import nlgs_run as chunked_nlgs

    return chunked_nlgs(W, q, mu, initial, stop, cap, seconds_cap, target)


def reached(trajectory, target=TARGET):
    """(iterations, seconds) of the first point of [(iterations, seconds, residual)] within
    ``target``; None if none."""
    return next(((it, sec) for it, sec, res in trajectory if res <= target), None)


def body_velocities(entry, impulse):
    """v = v_free + M^-1 H^T r (3B,) of the impulses ``impulse`` (n, 2): the bodies' (vx, vy, w)
    after the step, m s-1 and rad s-1."""
    return entry["v_free"] + entry["minv"] @ (entry["H"].T @ impulse.reshape(-1))


def m_norm(minv, x):
    """|x|_M = sqrt(sum_i x_i^2 / minv_ii) over the degrees of freedom of nonzero inverse mass
    (M^-1 diagonal; the fixed walls' zeros left out), kg^1/2 m s-1."""
    d = minv.diagonal()
    moving = d > 0
    return float(np.sqrt(np.sum(x[moving] ** 2 / d[moving])))


def closed_statistics(rn):
    """(mean, fraction below the mean, largest / mean) of the positive normal impulses ``rn``."""
    loaded = rn[rn > 0]
    mean = loaded.mean()
    return mean, float(np.mean(loaded < mean)), loaded.max() / mean


def compare(entry, impulse, reference, eps, time_step=TIME_STEP):
    """What the answer ``impulse`` (n, 2) of the law of compliance ``eps`` changes against the
    rigid answer ``reference`` (module docstring), a dict: dv (|v - v_0|_M / |v_0 - v_free|_M),
    dv_w (the same from W: sqrt(dr^T W dr / r_0^T W r_0)), sink (eps W_nn r_n of the closed points,
    m/s: median, max), sink_step (those times ``time_step``, m), over_recovery (fraction of
    closed points sinking faster than RECOVERY_SPEED), total (relative change of sum r_n), mean,
    below, largest (:func:`closed_statistics`, relative change of the mean; the fractions and
    ratios of both), ks (two-sample KS distance of the closed points' r_n) and rigid_law (the
    rigid problem's local-law residual of ``impulse``)."""
    from benchmarks.contact_solvers import law

    W, q, mu = entry["W"], entry["q"], entry["mu"]
    v0 = body_velocities(entry, reference)
    dv = m_norm(entry["minv"], body_velocities(entry, impulse) - v0) / m_norm(entry["minv"], v0 - entry["v_free"])
    dr, r0 = (impulse - reference).reshape(-1), reference.reshape(-1)
    dv_w = float(np.sqrt(max(dr @ (W @ dr), 0.0) / (r0 @ (W @ r0))))
    rn, rn0 = impulse[:, 0], reference[:, 0]
    closed = rn > 0
    sink = eps * W.diagonal()[0::2][closed] * rn[closed]
    mean, below, largest = closed_statistics(rn)
    mean0, below0, largest0 = closed_statistics(rn0)
    return dict(dv=dv, dv_w=dv_w, sink=(float(np.median(sink)), float(sink.max())),
                sink_step=(float(np.median(sink)) * time_step, float(sink.max()) * time_step),
                over_recovery=float(np.mean(sink > RECOVERY_SPEED)), total=rn.sum() / rn0.sum() - 1.0,
                mean=mean / mean0 - 1.0, below=(below, below0), largest=(largest, largest0),
                closed=(int(closed.sum()), int((rn0 > 0).sum())),
                ks=float(stats.ks_2samp(rn[closed], rn0[rn0 > 0]).statistic), rigid_law=law(W, q, mu, impulse))


def pcg_run(W, q, mu, initial, target=TARGET, cap=PCG_CAP):
    """(iterations, seconds, residual, converged) of solve_contact_problem(method='pcg') on
    (W, q, mu) from ``initial`` to the local-law residual ``target``."""
    from solver.contact_problem import solve_contact_problem

    start = time.perf_counter()
    s = solve_contact_problem(W, q, mu, method="pcg", tolerance=target, max_iterations=cap, initial=initial.copy())
    return s.iterations, time.perf_counter() - start, s.local_law_residual, s.converged


def warm_up():
    """Compile or load the NLGS and PCG kernels off the clock, on a coupled problem that iterates."""
    coupled = sparse.csr_matrix(np.array([[2.0, 0, 1, 0], [0, 2, 0, 0], [1, 0, 2, 0], [0, 0, 0, 2]]))
    q, mu = np.array([-3.0, 0.5, -3.0, -0.5]), np.full(2, 0.3)
    nlgs_run(coupled, q, mu, np.zeros((2, 2)), stop=1e-12, cap=20)
    pcg_run(coupled, q, mu, np.zeros((2, 2)), target=1e-12, cap=20)


def measure(found, epsilons=EPSILONS):
    """Rows {problem, points, eps, nlgs (reach or None), nlgs_end (sweeps, seconds, best
    residual), pcg (iterations, seconds, residual, converged), physics (:func:`compare`)} of every
    problem of ``found`` and eps; eps = 0 once more as 'rigid at TARGET' (physics of the rigid
    NLGS's answer at TARGET, speed blank)."""
    warm_up()
    rows = []
    for label, entry in found:
        W, q, mu, initial = entry["W"], entry["q"], entry["mu"], entry["initial"]
        reference = None
        for eps in epsilons:
            We = regularised(W, eps) if eps else W
            trajectory, best, at_target = nlgs_run(We, q, mu, initial)
            best_res = min(res for _, _, res in trajectory)
            if eps == 0:
                reference, reference_res = best, best_res
            cold, _, _ = nlgs_run(We, q, mu, np.zeros_like(initial), stop=TARGET, seconds_cap=COLD_SECONDS)
            pcg = pcg_run(We, q, mu, initial)
            physics = compare(entry, best, reference, eps)
            rows.append(dict(problem=label, points=mu.size, eps=eps, nlgs=reached(trajectory), cold=reached(cold),
                             cold_end=cold[-1][:2], nlgs_end=(trajectory[-1][0], trajectory[-1][1], best_res), pcg=pcg, physics=physics,
                             reference_residual=reference_res))
            print(f"{label} eps {eps:g}: nlgs {rows[-1]['nlgs']} (best {best_res:.1e} in {trajectory[-1][0]}), "
                  f"pcg {pcg[0]}, {pcg[1]:.2f} s, {pcg[2]:.1e}; dv {physics['dv']:.2e} (W form {physics['dv_w']:.2e}), "
                  f"sink max {physics['sink'][1]:.2e} m/s, total {physics['total']:+.2e}, ks {physics['ks']:.3f}, "
                  f"rigid law {physics['rigid_law']:.1e}; from 0: {rows[-1]['cold']}", flush=True)
            if not np.isclose(physics["dv"], physics["dv_w"], rtol=1e-6, atol=1e-12):
                raise AssertionError(f"|dv|_M from the bodies {physics['dv']} and from W {physics['dv_w']} differ")
            if eps == 0:
                rows.append(dict(problem=label, points=mu.size, eps="rigid at 1e-4", nlgs=None, nlgs_end=None,
                                 cold=None, cold_end=None,
                                 pcg=None, physics=compare(entry, at_target, reference, 0.0),
                                 reference_residual=reference_res))
    return rows


def _eps(e):
    return e if isinstance(e, str) else f"{e:g}"


def speed_table(rows):
    """Markdown: per problem and eps, sweeps and seconds to TARGET (NLGS, PCG)."""
    from benchmarks.common import markdown_table

    lines = []
    for r in rows:
        if isinstance(r["eps"], str):
            continue
        sweeps, seconds, best = r["nlgs_end"]
        nlgs = (f"{r['nlgs'][0]}, {r['nlgs'][1]:.3g} s" if r["nlgs"] else
                f"not reached ({sweeps} in {seconds:.3g} s)")
        cold = (f"{r['cold'][0]}, {r['cold'][1]:.3g} s" if r["cold"] else
                f"not reached ({r['cold_end'][0]} in {r['cold_end'][1]:.3g} s)")
        it, sec, res, ok = r["pcg"]
        stalled = "stalled" if it < PCG_CAP else "cap"
        pcg = f"{it}, {sec:.3g} s" if ok else f"not reached ({stalled}: {it} in {sec:.3g} s; {res:.1e})"
        lines.append([r["problem"], r["points"], _eps(r["eps"]), nlgs, cold, pcg, f"{best:.1e} ({sweeps})"])
    return markdown_table(["problem", "points", "eps", "nlgs to 1e-4: sweeps, s", "nlgs from r = 0: sweeps, s",
                           "pcg to 1e-4: iterations, s", "nlgs best (sweeps)"], lines)


def physics_table(rows):
    """Markdown: per problem and eps, what the compliance changes against the rigid answer."""
    from benchmarks.common import markdown_table

    lines = []
    for r in rows:
        p = r["physics"]
        lines.append([r["problem"], _eps(r["eps"]), f"{p['dv']:.2e}",
                      f"{p['sink'][0]:.2e} / {p['sink'][1]:.2e}", f"{p['sink_step'][0]:.1e} / {p['sink_step'][1]:.1e}",
                      f"{p['over_recovery']:.3f}", f"{p['total']:+.2e}", f"{p['mean']:+.2e}",
                      f"{p['below'][0]:.3f} ({p['below'][1]:.3f})", f"{p['largest'][0]:.2f} ({p['largest'][1]:.2f})",
                      f"{p['closed'][0]} ({p['closed'][1]})", f"{p['ks']:.3f}", f"{p['rigid_law']:.1e}"])
    return markdown_table(["problem", "eps", "|dv|_M / |v_0 - v_free|_M", "sink eps W_nn r_n, m/s: median / max",
                           f"per step of {TIME_STEP:g} s, m: median / max", "fraction sinking > 1 mm/s",
                           "total r_n", "mean r_n", "fraction below mean (rigid)", "largest / mean (rigid)",
                           "closed points (rigid)", "KS distance", "rigid law residual"], lines)


def per_size(rows, key):
    """{eps: {particles: [count or None per problem]}} of the method ``key`` ('nlgs', 'cold': the
    NLGS from r = 0, or 'pcg')."""
    out = {}
    for r in rows:
        if isinstance(r["eps"], str):
            continue
        n = int(r["problem"].split()[1])
        if key in ("nlgs", "cold"):
            count = r[key][0] if r[key] else None
        else:
            count = r["pcg"][0] if r["pcg"][3] else None
        out.setdefault(r["eps"], {}).setdefault(n, []).append(count)
    return out


def verdict(rows):
    """The plain statement: per method and eps, the counts to TARGET per size, whether they are
    flat in N (the largest size's worst within FLAT x the smallest size's worst) and few (all
    <= FEW); then the physics at the smallest eps that is both, on the largest size."""
    words, chosen = [], {}
    for key, unit in (("nlgs", "sweeps"), ("cold", "sweeps from r = 0"), ("pcg", "iterations")):
        for eps, sizes in per_size(rows, key).items():
            shown = "; ".join(f"{n}: {', '.join('-' if c is None else str(c) for c in v)}" for n, v in sizes.items())
            counts = [c for v in sizes.values() for c in v]
            small, large = sizes.get(min(sizes)), sizes.get(max(sizes))
            ok = None not in counts and len(sizes) > 1
            flat = ok and max(large) <= FLAT * max(small)
            few = ok and max(counts) <= FEW
            if flat and few and key not in chosen:
                chosen[key] = eps
            words.append(f"{key}, eps {eps:g}: {unit} to 1e-4 per problem ({shown}; '-': not reached); flat in N "
                         f"(worst at {max(sizes)} within {FLAT}x the worst at {min(sizes)}): "
                         f"{'yes' if flat else 'no'}; all <= {FEW}: {'yes' if few else 'no'}.")
    for key, eps in chosen.items():
        mine = [r["physics"] for r in rows if r["eps"] == eps and r["problem"].startswith(f"pentagons {PARTICLES[-1]} ")]
        floor = [r["physics"] for r in rows if r["eps"] == "rigid at 1e-4"
                 and r["problem"].startswith(f"pentagons {PARTICLES[-1]} ")]
        if mine:
            def listed(values, fmt):
                return ", ".join(format(v, fmt) for v in values)

            words.append(f"{key}: the smallest eps with flat and few: {eps:g}; there, at {PARTICLES[-1]}: |dv|_M "
                         f"{listed([p['dv'] for p in mine], '.1e')} (the rigid answer at 1e-4: "
                         f"{listed([p['dv'] for p in floor], '.1e')}), largest sink "
                         f"{listed([p['sink'][1] for p in mine], '.1e')} m/s, total r_n "
                         f"{listed([p['total'] for p in mine], '+.1e')}, KS {listed([p['ks'] for p in mine], '.3f')}, "
                         f"rigid law residual {listed([p['rigid_law'] for p in mine], '.1e')}.")
    if not chosen:
        words.append(f"No eps gives flat and few (<= {FEW}) counts with either method.")
    return "\n".join(f"* {w}" for w in words)


def energy_share(W, impulse):
    """r^T W r / r^T D r of the impulses ``impulse`` (n, 2), D = diag(W): the share of W's
    energy an answer has against the compliance energy per unit eps; an answer whose share is
    below eps is mostly a self-stress that the law of compliance eps drains."""
    r = impulse.reshape(-1)
    return float((r @ (W @ r)) / (r @ (W.diagonal() * r)))


def rigid_sinks(found, epsilons=EPSILONS[1:]):
    """Print, per problem of ``found``, the sink speeds eps W_nn r_n the compliant law would admit
    at the rigid answer's normal impulses (the NLGS from the warm start to TARGET): the
    interpenetration per step once the walls have brought the load back (median, 99th
    percentile and largest over the closed points, m/s, and times TIME_STEP, m), and the rigid
    answer's share of W's energy r^T W r / r^T D r (D = diag W; a share below eps is a
    self-stress the compliant law drains)."""
    warm_up()
    for label, entry in found:
        W, q, mu = entry["W"], entry["q"], entry["mu"]
        _, _, rigid = nlgs_run(W, q, mu, entry["initial"], stop=TARGET)
        share = energy_share(W, rigid)
        rn = rigid[:, 0]
        speed = W.diagonal()[0::2][rn > 0] * rn[rn > 0]
        quantiles = np.quantile(speed, [0.5, 0.99, 1.0])
        print(f"{label}: r^T W r / r^T D r = {share:.2e}; W_nn r_n over {speed.size} closed points: median, 99%, max "
              f"{', '.join(f'{x:.3g}' for x in quantiles)} m/s", flush=True)
        for eps in epsilons:
            print(f"  eps {eps:g}: sink {', '.join(f'{eps * x:.2e}' for x in quantiles)} m/s, per step "
                  f"{', '.join(f'{eps * x * TIME_STEP:.2e}' for x in quantiles)} m", flush=True)


TITLE = "A compliant contact law (W + eps diag W) on the stepper's pentagon problems: speed and what it changes"
INTRO = ("Written by `python -m benchmarks.compliance --out benchmarks/results/compliance.md` (its docstring gives "
         "the problems, the caps and every measure): for each eps, the NLGS (sweeps) and the projected conjugate "
         "gradient (iterations) to the regularised problem's own local-law residual |F|/|r| of 1e-4 from the stored "
         "warm start; then what the regularised answer (NLGS run far) changes against the rigid one (the NLGS's best "
         "on eps = 0), beside the same for the rigid NLGS's answer at 1e-4 (row 'rigid at 1e-4': the error the "
         "present tolerance already makes). One run per cell.")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--only", metavar="LABELS", help="the problems whose label starts with one of these "
                        "(comma-separated, e.g. 'pentagons 1000')")
    parser.add_argument("--out", help="write the tables here (Markdown)")
    parser.add_argument("--rigid-sinks", action="store_true", help="print the sink speeds at the rigid answer's "
                        "impulses (rigid_sinks()) and stop")
    args = parser.parse_args()
    from benchmarks.common import measured, results_text, write_text_keeping_notes

    found = problems()
    if args.only:
        prefixes = tuple(p.strip() for p in args.only.split(","))
        found = [p for p in found if p[0].startswith(prefixes)]
    if not found:
        raise SystemExit(f"no problem in {DATA} (capture them first: python -m benchmarks.body_admm --build-from FILE)"
                         + (f" whose label starts with {args.only}" if args.only else ""))
    if args.rigid_sinks:
        rigid_sinks(found)
        raise SystemExit(0)
    rows, run_line = measured(lambda: measure(found), "one thread (nice)")
    text = "\n\n".join([verdict(rows), speed_table(rows), physics_table(rows)])
    print(text)
    with open(os.path.join(DATA, "compliance_rows.pkl"), "wb") as fh:
        pickle.dump(rows, fh)
    if args.out:
        write_text_keeping_notes(args.out, results_text(TITLE, INTRO, [run_line, text]))
