"""Solver benchmarks (issue 5 items 2, 3, 5, 6, 7; issue 3 speed targets).

Each ``section_*`` function runs one section and returns Markdown (text and tables) for
``benchmarks/RESULTS.md``; ``benchmarks/run.py`` calls them in turn. Sizes come from a
``Config`` so that ``--quick`` runs the same code on tiny problems.

Samples. A "dense sample" is :func:`solver.compaction_sample` (paper size mix, box h/l ~ 2,
sigma_0 = 10 kPa on the right and top walls, zero gravity, friction 0.4) compacted for a fixed
number of steps (the same in every run) with the pushed walls allowed to close at up to ``max_wall_speed`` (faster
than the library default, to fit the run in minutes); it is not always at full equilibrium,
so every table reports the contact points per particle actually reached. A "biaxial step" is
then a step with the top wall moved down at 1 cm/s and sigma_0 kept on the right wall.
"""

from __future__ import annotations

import copy
import os
import subprocess
import sys
import tempfile
import time
import warnings
from dataclasses import dataclass

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from common import in_fresh_process, markdown_table  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "_data")
PEER_PYTHON = os.environ.get("PEER_PYTHON", "/tmp/peervenv/bin/python")

TARGET_SWEEP_NS = 25.0
TARGET_STEP_US = 10.0
TARGET_DETECTION_SHARE = 0.20


@dataclass
class Config:
    quick: bool = False
    plot_dir: str = HERE  # where plots go: next to the RESULTS file that links them
    # scaling
    sizes: tuple = (500, 1000, 4000, 14400, 57600)
    compaction_steps: dict = None  # per (shape, N): a fixed count, so that every run measures the same state
    timed_steps: dict = None
    # work-precision
    wp_particles: int = 250
    wp_compaction_steps: int = 8000  # a fixed count, so that every run starts from the same state
    wp_duration: float = 0.04  # s of biaxial test
    wp_tolerances: tuple = (1e-2, 1e-3, 1.7e-4, 3e-5, 1e-5)
    wp_time_steps: tuple = (2.5e-4, 5e-4, 1e-3)
    wp_budgets: tuple = (20, 100, 500)  # fixed sweep counts (no tolerance) at dt = 5e-4
    # peers
    peer_particles: int = 1000
    peer_settle_steps: int = 3000
    peer_steps: int = 200
    peer_budgets: tuple = (10, 50)
    # skipping
    skip_particles: int = 1000
    skip_steps: int = 40
    # stress
    stress_scale: int = 1

    def __post_init__(self):
        if self.quick:
            self.sizes = (300, 1000)
            self.compaction_steps = {(shape, n): 200 for shape in ("disk", "pentagon") for n in self.sizes}
            self.timed_steps = {300: 10, 1000: 5}
            self.wp_particles = 80
            self.wp_compaction_steps = 500
            self.wp_duration = 0.004
            self.wp_tolerances = (1e-2, 1.7e-4)
            self.wp_time_steps = (5e-4, 1e-3)
            self.wp_budgets = (20,)
            self.peer_particles = 60
            self.peer_settle_steps = 100
            self.peer_steps = 20
            self.peer_budgets = (10,)
            self.skip_particles = 200
            self.skip_steps = 10
            self.stress_scale = 0
        else:
            # ~25-150 s of compaction each on the 2-core VM of RESULTS.md; the samples of 4000 and
            # more stay loose (contact points / particle in the table)
            self.compaction_steps = self.compaction_steps or {
                ("disk", 500): 30_000, ("disk", 1000): 19_000, ("disk", 4000): 350, ("disk", 14400): 135,
                ("disk", 57600): 60, ("pentagon", 500): 12_000, ("pentagon", 1000): 3400,
                ("pentagon", 4000): 1200, ("pentagon", 14400): 1200, ("pentagon", 57600): 1000}
            self.timed_steps = self.timed_steps or {500: 40, 1000: 30, 4000: 20, 14400: 6, 57600: 3}


# --------------------------------------------------------------------------------------------
# shared helpers
# --------------------------------------------------------------------------------------------
def dense_sample(n, shape, seconds, max_steps=100_000, seed=0, max_wall_speed=0.5, **parameters):
    """A compaction sample compacted for ``seconds`` of wall clock (or ``max_steps``); the
    wall speed cap is then lifted. Returns (sim, compaction steps taken)."""
    from solver import compaction_sample

    sim = compaction_sample(n, shape, seed=seed, max_wall_speed=max_wall_speed, **parameters)
    start = time.perf_counter()
    steps = 0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        while steps < max_steps and time.perf_counter() - start < seconds:
            sim.step()
            steps += 1
    sim.walls.max_speed[:] = np.inf
    return sim, steps


def start_biaxial(sim, velocity=0.01):
    """Top wall moved down at ``velocity`` (m s-1); right wall keeps sigma_0."""
    sim.walls.drive_velocity("top", (0.0, -velocity))


def reset_meters(sim):
    for key in sim.timings:
        sim.timings[key] = 0.0
    for key in sim.counters:
        sim.counters[key] = 0


def run_steps(sim, steps):
    """Step ``sim``; returns (wall time s, non-converged steps, largest overlap m, max iterations)."""
    bad, overlap, iters = 0, 0.0, 0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        start = time.perf_counter()
        for _ in range(steps):
            info = sim.step()
            bad += not info.converged
            overlap = max(overlap, info.max_interpenetration)
            iters = max(iters, info.iterations)
        elapsed = time.perf_counter() - start
    return elapsed, bad, overlap, iters


def largest_overlap(position, angle, radius, n_vertices, wall_point, wall_normal):
    """Largest interpenetration (m) of a configuration, by this project's narrow phase: one
    metric for every engine."""
    from solver import broadphase, narrowphase

    margin = 0.02 * 2 * float(np.min(radius))
    pi, pj = broadphase.candidate_pairs(position, radius, margin)
    wp, ww = broadphase.wall_candidates(position, radius, wall_point, wall_normal, margin)
    pts = narrowphase.detect(position, angle, radius, n_vertices, wall_point, wall_normal, margin, pi, pj, wp, ww)
    return float(max(0.0, -pts.gap.min())) if len(pts.gap) else 0.0


def fmt(x, digits=3):
    if x is None or (isinstance(x, float) and not np.isfinite(x)):
        return "-"
    return f"{x:.{digits}g}"


# --------------------------------------------------------------------------------------------
# a. scaling
# --------------------------------------------------------------------------------------------
def _scaling_case(n, shape, compaction, steps):
    sim, compaction_steps = dense_sample(n, shape, np.inf, max_steps=compaction)
    start_biaxial(sim)
    run_steps(sim, 2)  # warm-up (numba caches loaded)
    reset_meters(sim)
    elapsed, bad, overlap, iters = run_steps(sim, steps)
    t = dict(sim.timings)
    c = dict(sim.counters)
    return dict(n=n, shape=shape, compaction_steps=compaction_steps, steps=steps, elapsed=elapsed, timings=t,
                counters=c, points=sim.last.n_points, not_converged=bad, overlap=overlap / (2 * sim.radius.mean()),
                max_iterations=iters)


def section_scaling(cfg: Config, log=print):
    rows, results = [], []
    for shape in ("disk", "pentagon"):
        for n in cfg.sizes:
            try:
                r, peak = in_fresh_process(_scaling_case, n, shape, cfg.compaction_steps[shape, n], cfg.timed_steps[n])
            except RuntimeError as exc:
                rows.append([shape, n] + ["failed: " + str(exc)[:80]] + [""] * 10)
                continue
            r["peak"] = peak
            results.append(r)
            t, c = r["timings"], r["counters"]
            per_step = r["elapsed"] / r["steps"]
            detection = t["broad_phase"] + t["narrow_phase"]
            ns_sweep = 1e9 * t["solve"] / max(c["point_sweeps"], 1)
            rows.append([shape, f"{n:,}", r["compaction_steps"], f"{r['points'] / n:.2f}", r["steps"],
                         f"{1e3 * per_step:.2f}", f"{1e6 * per_step / n:.1f}",
                         f"{c['sweeps'] / r['steps']:.0f}", f"{c['recovery_sweeps'] / r['steps']:.0f}", f"{ns_sweep:.1f}",
                         f"{100 * detection / r['elapsed']:.0f}%",
                         f"{100 * t['solve'] / r['elapsed']:.0f}%", f"{100 * t['update'] / r['elapsed']:.0f}%",
                         f"{c['broad_phase_runs']}/{r['steps']}", r["not_converged"], f"{r['peak']:.0f}"])
            log(rows[-1])
    header = ["shape", "N", "compaction steps", "contact points / particle", "timed steps", "ms / step",
              "us / step / particle", "NLGS sweeps / step", "recovery sweeps / step", "ns / point / sweep", "detection share",
              "NLGS share", "update share (overlap recovery)",
              "broad-phase runs", "non-converged steps", "peak RSS (MiB)"]
    text = (f"Samples from compaction_sample compacted for a fixed number of steps (the 'compaction steps' "
            f"column; the same in every run), walls closing at <= 0.5 m/s, "
            "then biaxial steps (top wall 1 cm/s down, sigma_0 = 10 kPa on the right wall) at the default "
            "tolerance (1.7e-4 quadratic, 1e-2 max norm, <= 2000 sweeps) and dt = 5e-4 s. Each case in a "
            "fresh process; 'ns / point / sweep' = NLGS solve time / (sweeps x contact points), Delassus "
            "set-up included; 'detection share' = (broad + narrow phase) / step; 'update share' = the "
            "position update, most of it the split-impulse overlap-recovery NLGS (a second, frictionless "
            "solve of up to 50 sweeps at tolerance 1e-2, run only when an overlap exceeds 1e-4 of the smallest "
            "diameter; its sweeps are counted apart). The largest samples are far from the dense state after "
            "their compaction budget (see contact points / particle: ~2.5 when dense); they measure the cost per "
            "contact point and per particle at that state. Peak RSS includes the interpreter, numba and the "
            "compaction.\n\n")
    text += markdown_table(header, rows)
    text += "\n\n" + _targets(results)
    return text, results


def _targets(results):
    lines = ["**Against the issue-3 targets** (one core):", ""]
    for r in results:
        t, c = r["timings"], r["counters"]
        ns = 1e9 * t["solve"] / max(c["point_sweeps"], 1)
        us = 1e6 * r["elapsed"] / r["steps"] / r["n"]
        share = (t["broad_phase"] + t["narrow_phase"]) / r["elapsed"]
        recovery = t["update"] / r["elapsed"]
        lines.append(f"- {r['shape']} N = {r['n']:,}: NLGS {ns:.1f} ns/point/sweep "
                     f"({'met' if ns <= TARGET_SWEEP_NS else 'MISSED'}, target <= 25); step {us:.1f} us/particle "
                     f"({'met' if us <= TARGET_STEP_US else 'MISSED'}, target <= 10, LMGC90 700); detection "
                     f"{100 * share:.0f}% ({'met' if share <= TARGET_DETECTION_SHARE else 'MISSED'}, target <= 20%); "
                     f"{r['points'] / r['n']:.2f} contact points/particle, {c['sweeps'] / r['steps']:.0f} sweeps/step, "
                     f"overlap recovery {100 * recovery:.0f}% of the step.")
    return "\n".join(lines)


# --------------------------------------------------------------------------------------------
# b. work-precision
# --------------------------------------------------------------------------------------------
def _macro(sim):
    """(q/p, eps_p) from the walls: sigma_1 on the top wall, sigma_2 on the right wall,
    p = (s1 + s2)/2, q = (s1 - s2)/2; eps_p = ln(V/V0) from the box (here the current box)."""
    s = sim.wall_stresses()
    s1, s2 = s[sim.walls.index("top")], s[sim.walls.index("right")]
    lo, hi = sim.walls.box_bounds()
    return s1, s2, float(np.prod(hi - lo))


def _pair_forces(sim):
    from solver.output import pair_contacts

    c = pair_contacts(sim)
    t = np.stack([-c["normal"][:, 1], c["normal"][:, 0]], -1)
    f = c["fn"][:, None] * c["normal"] + c["ft"][:, None] * t
    return {(int(i), int(j)): v for i, j, v in zip(c["i"], c["j"], f)}


def _wp_run(base, time_step, tolerance, duration, record_every, max_iterations=5000):
    """One short biaxial run from ``base``; returns (wall time, macro series, pair forces, bad steps)."""
    sim = copy.deepcopy(base)
    p = sim.parameters
    ratio = time_step / p.time_step
    p.time_step, p.tolerance = time_step, tolerance
    p.max_tolerance = tolerance * (1e-2 / 1.7e-4)  # keep the defaults' ratio of the two norms
    p.max_iterations = max_iterations
    sim.scale_warm_start(ratio)  # warm start: same forces, impulses over the new step
    reset_meters(sim)
    steps = int(round(duration / time_step))
    per_record = int(round(record_every / time_step))
    lo, hi = sim.walls.box_bounds()
    v0 = float(np.prod(hi - lo))
    series, acc = [], []
    bad = 0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        start = time.perf_counter()
        elapsed_measure = 0.0
        for k in range(1, steps + 1):
            info = sim.step()
            bad += not info.converged
            if k == 1:
                first = sim.impulse / time_step  # forces of the first step, N
            m0 = time.perf_counter()
            acc.append(_macro(sim))
            if k % per_record == 0:
                a = np.array(acc)
                s1, s2 = a[:, 0].mean(), a[:, 1].mean()
                series.append(((s1 - s2) / (s1 + s2), np.log(a[-1, 2] / v0)))
                acc = []
            elapsed_measure += time.perf_counter() - m0
        elapsed = time.perf_counter() - start - elapsed_measure
    return elapsed, np.array(series), _pair_forces(sim), bad, sim.counters["sweeps"] / steps, first


def _force_error(forces, reference):
    keys = set(forces) | set(reference)
    zero = np.zeros(2)
    num = sum(float(np.sum((forces.get(k, zero) - reference.get(k, zero)) ** 2)) for k in keys)
    den = sum(float(np.sum(v ** 2)) for v in reference.values())
    return np.sqrt(num / den) if den > 0 else np.nan


def _wp_shape(cfg, shape, log):
    base, compaction_steps = dense_sample(cfg.wp_particles, shape, np.inf, max_steps=cfg.wp_compaction_steps, seed=3)
    start_biaxial(base)
    record = max(cfg.wp_time_steps)
    ref_tol = 1.7e-4 / 100  # 100x tighter than the default
    ref_dt = min(cfg.wp_time_steps)
    t_ref, ref_series, ref_forces, ref_bad, ref_sweeps, _ = _wp_run(base, ref_dt, ref_tol, cfg.wp_duration, record,
                                                                    max_iterations=20_000)
    log(f"work-precision {shape}: reference {t_ref:.1f} s, {ref_sweeps:.0f} sweeps/step, {ref_bad} non-converged")
    # same-state reference per time step: the first step from the base state solved to 1e-10
    first_ref = {dt: _wp_run(base, dt, 1e-10, dt, record, max_iterations=200_000)[5] for dt in cfg.wp_time_steps}

    def errors(series, forces, first, dt):
        """Same-state force, end-of-run force, q/p and eps_p errors against the references."""
        m = min(len(series), len(ref_series))
        e_q = float(np.max(np.abs(series[:m, 0] - ref_series[:m, 0])))
        e_v = float(np.max(np.abs(series[:m, 1] - ref_series[:m, 1])))
        e_1 = float(np.linalg.norm(first - first_ref[dt]) / np.linalg.norm(first_ref[dt]))
        return e_1, _force_error(forces, ref_forces), e_q, e_v

    rows, points = [], []
    for dt in cfg.wp_time_steps:
        for tol in cfg.wp_tolerances:
            elapsed, series, forces, bad, sweeps, first = _wp_run(base, dt, tol, cfg.wp_duration, record)
            e_1, e_f, e_q, e_v = errors(series, forces, first, dt)
            default = dt == 5e-4 and tol == 1.7e-4
            points.append(dict(dt=dt, tol=tol, budget=None, time=elapsed, e_f=e_f, e_q=e_q, e_v=e_v, e_1=e_1, default=default))
            rows.append([f"{dt:g}", f"{tol:g}" + (" (default)" if default else ""), f"{elapsed:.2f}", f"{sweeps:.0f}",
                         bad, fmt(e_1), fmt(e_f), fmt(e_q), fmt(e_v)])
            log(rows[-1])
    # fixed budgets: no tolerance (1e-30), every step spends exactly `budget` sweeps
    dt = 5e-4
    for budget in cfg.wp_budgets if dt in cfg.wp_time_steps else ():
        elapsed, series, forces, _, sweeps, first = _wp_run(base, dt, 1e-30, cfg.wp_duration, record,
                                                            max_iterations=budget)
        e_1, e_f, e_q, e_v = errors(series, forces, first, dt)
        points.append(dict(dt=dt, tol=None, budget=budget, time=elapsed, e_f=e_f, e_q=e_q, e_v=e_v, e_1=e_1,
                           default=False))
        rows.append([f"{dt:g}", f"none: {budget} sweeps", f"{elapsed:.2f}", f"{sweeps:.0f}", "-", fmt(e_1), fmt(e_f),
                     fmt(e_q), fmt(e_v)])
        log(rows[-1])
    header = ["dt (s)", "tolerance", "run time (s)", "sweeps / step", "non-converged steps",
              "force error, same state (rel. L2)", "force error, end of run (rel. L2)", "max |q/p - ref|",
              "max |eps_p - ref|"]
    n = base.n_particles
    text = (f"**{shape}s**, N = {n}, {compaction_steps} compaction steps, {base.last.n_points / n:.2f} contact "
            f"points/particle at the start; biaxial run of {cfg.wp_duration:g} s (top wall 1 cm/s), at most 5000 sweeps per step ('none: k sweeps' rows: "
            f"no tolerance, exactly k sweeps every step); reference: "
            f"dt = {ref_dt:g} s, tolerance {ref_tol:g} (100x tighter than the default; max norm {ref_tol * 1e-2 / 1.7e-4:.2g}), "
            f"{t_ref:.1f} s, {ref_sweeps:.0f} sweeps/step, {ref_bad} steps at the 20,000-sweep cap. "
            f"'Same state': the forces of the first step from the common starting state against the same step "
            f"solved to tolerance 1e-10 (the solver's own error, free of trajectory divergence). 'End of run': per "
            f"pair forces after {cfg.wp_duration:g} s against the reference run's. q/p averaged over "
            f"{record * 1e3:g} ms windows (wall stresses chatter from step to step), compared every {record * 1e3:g} ms.\n\n")
    return text + markdown_table(header, rows), points


def _wp_plot(all_points, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    fig, axes = plt.subplots(1, 4, figsize=(17, 4))
    for (shape, points), colour in zip(all_points.items(), ("C0", "C1")):
        for dt, marker in zip(sorted({p["dt"] for p in points}), ("o", "s", "^", "v")):
            sel = [p for p in points if p["dt"] == dt and p["budget"] is None]
            for ax, key in zip(axes, ("e_1", "e_f", "e_q", "e_v")):
                ax.loglog([max(p[key], 1e-12) for p in sel], [p["time"] for p in sel], marker=marker, color=colour,
                          label=f"{shape}, dt={dt:g}")
                for p in sel:
                    if p["default"]:
                        ax.plot(max(p[key], 1e-12), p["time"], "*", ms=18, color="red", mfc="none")
        fixed = [p for p in points if p["budget"] is not None]
        if fixed:
            for ax, key in zip(axes, ("e_1", "e_f", "e_q", "e_v")):
                ax.loglog([max(p[key], 1e-12) for p in fixed], [p["time"] for p in fixed], "x--", color=colour,
                          label=f"{shape}, dt=5e-4, fixed sweeps {fixed[0]['budget']}..{fixed[-1]['budget']}")
    for ax, title in zip(axes, ("forces, same state (rel. L2)", "forces, end of run (rel. L2)", "max |q/p - ref|",
                                "max |eps_p - ref|")):
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())  # decades only: minor labels collide
        ax.set_xlabel(f"error: {title}")
        ax.set_ylabel("run time (s)")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.suptitle("Work-precision (tolerance varied along each solid line, fixed sweep count along each dashed one; "
                 "red star: defaults dt = 5e-4, tol = 1.7e-4)")
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def section_work_precision(cfg: Config, log=print):
    parts, all_points = [], {}
    for shape in ("pentagon", "disk"):
        text, points = _wp_shape(cfg, shape, log)
        parts.append(text)
        all_points[shape] = points
    _wp_plot(all_points, os.path.join(cfg.plot_dir, "work_precision.png"))
    verdict = []
    for shape, points in all_points.items():
        d = [p for p in points if p["default"]]
        if not d:
            continue
        d = d[0]
        same_dt = sorted([p for p in points if p["dt"] == 5e-4 and p["budget"] is None], key=lambda p: p["tol"])
        verdict.append(f"- {shape}s: defaults cost {d['time']:.2f} s for a same-state force error {fmt(d['e_1'])}, "
                       f"end-of-run force error {fmt(d['e_f'])}, q/p error {fmt(d['e_q'])}, eps_p error {fmt(d['e_v'])}; "
                       f"at dt = 5e-4 the tolerances from {same_dt[-1]['tol']:g} to {same_dt[0]['tol']:g} cost "
                       f"{same_dt[-1]['time']:.2f} .. {same_dt[0]['time']:.2f} s for same-state force errors "
                       f"{fmt(same_dt[-1]['e_1'])} .. {fmt(same_dt[0]['e_1'])}"
                       + "".join(f"; {p['budget']} fixed sweeps: {p['time']:.2f} s, same-state force error "
                                 f"{fmt(p['e_1'])}, q/p error {fmt(p['e_q'])}" for p in points if p["budget"])
                       + ".")
    return ("\n\n".join(parts) + "\n\n![work-precision](work_precision.png)\n\n" + "\n".join(verdict)), all_points


# --------------------------------------------------------------------------------------------
# c. peers
# --------------------------------------------------------------------------------------------
def settle_pile(n, shape, steps, seed=0):
    """Deposit ``n`` particles (paper size mix) between side walls and settle them under
    gravity with this solver; returns the pile as a dict in the format benchmarks/peers.py reads."""
    from solver import gravity_scene
    from solver.packing import box_width_for, deposit
    from solver.scenes import n_vertices_of

    width = box_width_for(n, aspect_ratio=1.0)
    pos, ang, rad, nv, height = deposit(n, nvert=n_vertices_of(shape), width=width, seed=seed)
    sim = gravity_scene(pos, ang, rad, nv, sides=(0.0, width))
    weight_scale = float(sim.mass.sum()) * 9.81 * 2 * float(rad.mean())  # J
    for k in range(0, steps, 50):  # settle until E_kin < 1e-6 m g d (or ``steps``)
        run_steps(sim, 50)
        if sim.kinetic_energy() < 1e-6 * weight_scale:
            break
    p = sim.parameters
    return dict(position=sim.position.copy(), angle=sim.angle.copy(), radius=rad, n_vertices=nv.astype(np.int64),
                density=p.density, box=np.array([0.0, 0.0, width, height]), gravity=np.array(p.gravity),
                dt=p.time_step, friction=p.friction, kinetic_energy=sim.kinetic_energy())


def _ours_on_pile(path, steps, iterations, default_tolerance):
    from solver import gravity_scene

    pile = dict(np.load(path))
    x0, _, x1, _ = pile["box"]
    kwargs = dict(max_iterations=iterations, tolerance=1e-30, max_tolerance=1e-30)
    if default_tolerance:
        kwargs = {}
    sim = gravity_scene(pile["position"], pile["angle"], pile["radius"], pile["n_vertices"], sides=(x0, x1),
                        gravity=float(-pile["gravity"][1]), time_step=float(pile["dt"]), **kwargs)
    run_steps(sim, 2)  # numba caches loaded
    reset_meters(sim)
    elapsed, bad, _, _ = run_steps(sim, steps)
    sweeps = sim.counters["sweeps"] / steps
    recovery_sweeps = sim.counters["recovery_sweeps"] / steps
    point_sweeps = sim.counters["point_sweeps"]
    floor = []
    for _ in range(max(steps // 10, 1)):
        sim.step()
        floor.append(-sim.wall_forces()[0, 1])
    ratio = float(np.mean(floor)) / (sim.mass.sum() * abs(pile["gravity"][1]))
    parts = {k: 1e3 * v / steps for k, v in sim.timings.items()}
    return dict(position=sim.position, angle=sim.angle, per_step=elapsed / steps, floor=ratio, sweeps=sweeps, parts=parts,
                recovery_sweeps=recovery_sweeps, ns=1e9 * sim.timings["solve"] / max(point_sweeps, 1), points=sim.last.n_points,
                pairs=sim.points.n_pairs)


def section_peers(cfg: Config, log=print):
    from solver import Walls

    os.makedirs(DATA, exist_ok=True)
    have_peers = os.path.exists(PEER_PYTHON)
    rows, settled_note = [], []
    for shape in ("pentagon", "disk"):
        pile = settle_pile(cfg.peer_particles, shape, cfg.peer_settle_steps)
        path = os.path.join(DATA, f"pile_{shape}_{cfg.peer_particles}.npz")
        np.savez(path, **{k: v for k, v in pile.items() if k != "kinetic_energy"})
        n = len(pile["radius"])
        diameter = 2 * float(pile["radius"].mean())
        x0, _, x1, _ = pile["box"]
        walls = Walls.floor(sides=(x0, x1))
        log(f"pile {shape}: N = {n}, kinetic energy after settling {pile['kinetic_energy']:.3g} J")
        settled_note.append(f"{shape} pile: E_kin {pile['kinetic_energy']:.2g} J after settling")
        cases = [("this solver", b, False) for b in cfg.peer_budgets] + [("this solver (default tol.)", None, True)]
        cases += [(e, b, None) for e in ("pymunk", "box2d") for b in cfg.peer_budgets]
        for engine, budget, default in cases:
            try:
                if engine.startswith("this solver"):
                    r, _ = in_fresh_process(_ours_on_pile, path, cfg.peer_steps, budget or 2000, default)
                    q = r["parts"]
                    extra = (f"{r['sweeps']:.0f} sweeps/step, {r['ns']:.0f} ns/point/sweep, "
                             f"{r['points']} points / {r['pairs']} pairs; ms/step: NLGS {q['solve']:.2f}, "
                             f"overlap recovery {q['update']:.2f} ({r['recovery_sweeps']:.0f} sweeps), detection {q['broad_phase'] + q['narrow_phase']:.2f}")
                    budget_text = "tol. 1.7e-4 (<= 2000)" if default else f"{budget} sweeps"
                else:
                    if not have_peers:
                        rows.append([shape, engine, f"{budget}", "-", "-", "-", "-", "peer venv missing"])
                        continue
                    out = os.path.join(DATA, f"peer_{engine}_{shape}_{budget}.npz")
                    subprocess.run([PEER_PYTHON, os.path.join(HERE, "peers.py"), path, out, "--engine", engine,
                                    "--steps", str(cfg.peer_steps), "--iterations", str(budget)], check=True,
                                   capture_output=True, text=True, timeout=900)
                    res = dict(np.load(out))
                    r = dict(position=res["position"], angle=res["angle"], per_step=float(res["time_per_step"]),
                             floor=float(res["floor_over_weight"]))
                    extra = ("velocity = position iterations" if engine == "box2d" else "") + "; fixed budget"
                    budget_text = f"{budget} iterations"
                overlap = largest_overlap(r["position"], r["angle"], pile["radius"], pile["n_vertices"], walls.point,
                                          walls.normal)
                rows.append([shape, engine, budget_text, f"{1e3 * r['per_step']:.2f}", f"{1e6 * r['per_step'] / n:.1f}",
                             fmt(abs(r["floor"] - 1)), fmt(overlap / diameter), extra])
            except Exception as exc:  # a peer failing must not stop the run
                rows.append([shape, engine, f"{budget}", "-", "-", "-", "-", f"failed: {str(exc)[:100]}"])
            log(rows[-1])
    header = ["pile", "engine", "budget", "ms / step", "us / step / particle", "|floor force / weight - 1|",
              "largest overlap / mean d", "notes"]
    text = (f"Piles of {cfg.peer_particles} particles (paper size mix, box width for h/l ~ 1, side walls, friction "
            f"0.4 between grains, 0 with walls) deposited geometrically and settled by this solver for "
            f"up to {cfg.peer_settle_steps} steps (until E_kin < 1e-6 m g d; {'; '.join(settled_note)}), saved to .npz and reloaded into every engine in a fresh process "
            f"(PEERS.md). Each engine then runs {cfg.peer_steps} timed steps at dt = 5e-4 s with the stated "
            f"budget; floor force averaged over {max(cfg.peer_steps // 10, 1)} further steps (not timed); overlap "
            f"measured on each engine's final positions with this project's narrow phase (same metric for all). "
            f"This solver at a fixed budget: tolerance 1e-30 so it always spends max_iterations sweeps; its "
            f"overlap-recovery pass keeps its own settings (tolerance 1e-2, at most 50 sweeps, run only where an "
            f"overlap exceeds 1e-4 d); where a settled pile keeps overlaps of ~1% d (pentagons), which recovery "
            f"removes at <= 1 mm/s, it runs every step (its ms/step and sweeps in the notes). Box2D "
            f"runs in units of 2.5 cm; pymunk collision_slop 1e-5 m (benchmarks/peers.py).\n\n")
    if not have_peers:
        text += (f"**Peer engines not run**: {PEER_PYTHON} not found; create it with `python3 -m venv /tmp/peervenv && "
                 "/tmp/peervenv/bin/pip install -r benchmarks/requirements-peers.txt`.\n\n")
    return text + markdown_table(header, rows), rows


# --------------------------------------------------------------------------------------------
# d. skipping what a scene does not need
# --------------------------------------------------------------------------------------------
def _per_step(sim, steps):
    reset_meters(sim)
    elapsed, _, _, _ = run_steps(sim, steps)
    return elapsed / steps, {k: v / steps for k, v in sim.timings.items()}, dict(sim.counters)


def section_skipping(cfg: Config, series_path=None, log=print):
    from solver.output import OPTIONAL, Recorder

    n, steps = cfg.skip_particles, cfg.skip_steps
    seconds = 5.0 if cfg.quick else 20.0
    rows = []
    samples = {}
    for shape in ("pentagon", "disk"):
        sim, _ = dense_sample(n, shape, seconds, seed=5)
        start_biaxial(sim)
        run_steps(sim, 2)
        samples[shape] = sim
    pent = samples["pentagon"]
    # detection reuse
    for reuse in (True, False):
        sim = copy.deepcopy(pent)
        sim.reuse_detection = reuse
        t, parts, c = _per_step(sim, steps)
        rows.append([f"detection reuse {'on' if reuse else 'off'} (pentagons)", f"{1e3 * t:.2f}",
                     f"broad phase {1e3 * parts['broad_phase']:.3f} ms/step, {c['broad_phase_runs']}/{steps} runs; "
                     f"narrow phase {1e3 * parts['narrow_phase']:.3f} ms/step; NLGS {1e3 * parts['solve']:.2f} ms/step"])
        log(rows[-1])
    # disks vs pentagons narrow phase
    for shape, sim0 in samples.items():
        sim = copy.deepcopy(sim0)
        t, parts, c = _per_step(sim, steps)
        npts = sim.last.n_points
        rows.append([f"{shape} scene: narrow phase", f"{1e3 * t:.2f}",
                     f"narrow phase {1e3 * parts['narrow_phase']:.3f} ms/step = {1e9 * parts['narrow_phase'] / max(npts, 1):.0f} "
                     f"ns/point ({npts} points); " + ("polygon kernels never entered (all n_vertices = 0)"
                                                      if shape == "disk" else "polygon kernels")])
        log(rows[-1])
    # gravity
    for g in ((0.0, 0.0), (0.0, -9.81)):
        sim = copy.deepcopy(pent)
        sim.parameters.gravity = g
        t, parts, c = _per_step(sim, steps)
        rows.append([f"gravity {'zero' if g == (0.0, 0.0) else '9.81 m/s2'} (pentagons)", f"{1e3 * t:.2f}",
                     f"{c['sweeps'] / steps:.0f} NLGS sweeps/step; gravity itself is one vectorised add to the free "
                     "velocities, skipped by an `if` when zero: a step-time difference is the different contact problem"])
        log(rows[-1])
    # optional variables
    for optional, label in ((OPTIONAL, "all optional variables"), ((), "required variables only")):
        sim = copy.deepcopy(pent)
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "run.nc")
            writes = 20 if not cfg.quick else 5
            write_time = 0.0
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                with Recorder(path, sim, optional=optional) as rec:
                    for _ in range(writes):
                        sim.step()
                        s = time.perf_counter()
                        rec.write()
                        write_time += time.perf_counter() - s
            size = os.path.getsize(path)
        rows.append([f"output: {label}", "-", f"{1e3 * write_time / writes:.2f} ms/snapshot, "
                     f"{size / writes / 1024:.0f} KiB/snapshot ({writes} snapshots of {n} pentagons)"])
        log(rows[-1])
    # lazy accessor
    if series_path and os.path.exists(series_path):
        import grainview
        ds = grainview.open_dataset(series_path, chunks=25)
        s = time.perf_counter()
        lazy = ds.grain.stress_invariants()
        build = time.perf_counter() - s
        s = time.perf_counter()
        for v in (lazy.values() if hasattr(lazy, "values") and callable(lazy.values) else [lazy]):
            if hasattr(v, "compute"):
                v.compute()
        compute = time.perf_counter() - s
        rows.append(["lazy accessor: stress_invariants on " + os.path.basename(series_path), f"-",
                     f"graph built in {1e3 * build:.1f} ms (nothing computed, nothing read); computing it: {compute:.2f} s"])
        log(rows[-1])
    header = ["case", "ms / step", "what is skipped / measured"]
    text = (f"Dense samples of {n} particles ({seconds:.0f} s of compaction), biaxial steps, {steps} steps per row, "
            "each row from a copy of the same state.\n\n")
    return text + markdown_table(header, rows), rows


# --------------------------------------------------------------------------------------------
# f. stress tests
# --------------------------------------------------------------------------------------------
def _stress_run(sim, steps, source):
    from grainview.errors import ConvergenceWarning

    d = 2 * float(sim.radius.mean())
    overlap, energy, finite, iters, bad = 0.0, [], True, 0, 0
    start = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ConvergenceWarning)
        for _ in range(steps):
            info = sim.step()
            overlap = max(overlap, info.max_interpenetration)
            energy.append(sim.kinetic_energy())
            iters = max(iters, info.iterations)
            bad += not info.converged
            if not (np.all(np.isfinite(sim.position)) and np.all(np.isfinite(sim.velocity))
                    and np.all(np.isfinite(sim.impulse))):
                finite = False
                break
    warned = sum(issubclass(w.category, ConvergenceWarning) for w in caught)
    energy = np.array(energy)
    return ["yes" if finite else "NO", fmt(overlap / d), fmt(sim.last.max_interpenetration / d),
            f"{bad} / {steps} ({warned} warned)", iters, fmt(energy.max()), fmt(energy[-1]), source,
            f"{time.perf_counter() - start:.1f}"]


def section_stress(cfg: Config, log=print):
    from solver import Parameters, Simulation, Walls, gravity_scene
    from solver.packing import box_width_for, deposit

    R = 0.0125
    big = cfg.stress_scale
    rows = []

    def add(name, sim, steps, source):
        rows.append([name, sim.n_particles, steps] + _stress_run(sim, steps, source))
        log(rows[-1])

    # tall column of 50 pentagons in a frictionless channel
    n = 50
    rng = np.random.default_rng(0)
    y = R + 2 * R * np.arange(n) * 1.001
    x = rng.uniform(-0.1, 0.1, n) * R
    sim = gravity_scene(np.stack([x, y], -1), rng.uniform(0, 2 * np.pi, n), np.full(n, R), np.full(n, 5),
                        sides=(-1.3 * R, 1.3 * R))
    add("tall column, 50 pentagons", sim, 2000 if big else 200, "gravity (landing)")
    # mass ratio 1:1000 between neighbours: a pile of disks, every other one 1000x heavier
    m = 400 if big else 40
    width = box_width_for(m, aspect_ratio=1.0)
    pos, ang, rad, nv, _ = deposit(m, nvert=0, width=width, seed=1)
    sim = gravity_scene(pos, ang, rad, nv, sides=(0.0, width))
    sim.mass[::2] *= 1000.0
    sim.inertia[::2] *= 1000.0
    add("mass ratio 1:1000 (disk pile)", sim, 600 if big else 60, "gravity")
    # friction 0 and 1 in a compaction
    for mu in (0.0, 1.0):
        from solver import compaction_sample
        sim = compaction_sample(1000 if big else 60, "pentagon", seed=4, friction=mu, max_wall_speed=0.5)
        add(f"friction {mu:g} (pentagon compaction)", sim, 1000 if big else 60, "wall work")
    # time step 10x default
    for shape in ("disk", "pentagon"):
        pos, ang, rad, nv, _ = deposit(m, nvert=0 if shape == "disk" else 5, width=width, seed=2)
        sim = gravity_scene(pos, ang, rad, nv, sides=(0.0, width), time_step=5e-3)
        add(f"time step 5e-3 s (10x), {shape} pile", sim, 300 if big else 30, "gravity")
    # exactly parallel and aligned edges, created with zero gap: a stack of squares and of
    # pentagons resting edge to edge in rows
    k = 20 if big else 5
    side = 2 * R * np.sin(np.pi / 4)  # square of circumscribed radius R
    ii, jj = np.meshgrid(np.arange(k), np.arange(k))
    pos = np.stack([(ii.ravel() + 0.5) * side, (jj.ravel() + 0.5) * side], -1)
    sim = gravity_scene(pos, np.full(k * k, np.pi / 4), np.full(k * k, R), np.full(k * k, 4), sides=(0.0, k * side))
    add(f"{k}x{k} squares, aligned edges, zero gap", sim, 300 if big else 30, "gravity (at rest)")
    inradius = R * np.cos(np.pi / 5)
    edge = 2 * R * np.sin(np.pi / 5)
    xs = np.arange(k) * 2 * R
    pos = np.stack([xs, np.full(k, inradius)], -1)
    sim = gravity_scene(pos, np.full(k, np.radians(-54.0)), np.full(k, R), np.full(k, 5))
    add(f"row of {k} pentagons on a floor, parallel edges, zero gap", sim, 300 if big else 30, "gravity (at rest)")
    # hexagonal lattice of touching disks
    rows_h = k
    pts = [((c + 0.5 * (r % 2)) * 2 * R + R, R + r * np.sqrt(3) * R) for r in range(rows_h) for c in range(k)]
    pts = np.array(pts)
    sim = gravity_scene(pts, np.zeros(len(pts)), np.full(len(pts), R), np.zeros(len(pts)),
                        sides=(0.0, (k + 0.5) * 2 * R))
    add(f"{k}x{k} hexagonal disks, created touching (gap 0)", sim, 300 if big else 30, "gravity (at rest)")
    # wall pushed at 100 x sigma_0 on a dense sample
    sim, _ = dense_sample(1000 if big else 60, "pentagon", 20.0 if big else 2.0, seed=6)
    stress = sim.walls.mode == 2
    sim.walls.stress[stress] *= 100.0
    add("walls pushed at 100 x sigma_0 (dense pentagons)", sim, 400 if big else 40, "wall work")
    header = ["case", "N", "steps", "finite", "largest overlap / d (run)", "overlap / d (end)",
              "non-converged steps", "max sweeps", "peak E_kin (J)", "final E_kin (J)", "energy source", "time (s)"]
    text = ("Larger versions of tests/solver/test_stress_cases.py. 'non-converged' counts steps that ran out of "
            "NLGS sweeps (each raised a ConvergenceWarning: the 'warned' count); E_kin grows only where a source is "
            "named (gravity, wall work).\n\n")
    return text + markdown_table(header, rows), rows
