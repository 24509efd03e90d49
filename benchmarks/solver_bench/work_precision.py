"""Section b: work against precision: time step, NLGS tolerance and sweep budget against the error of
the macroscopic and contact-force results."""

from __future__ import annotations

import copy
import os
import time
import warnings

import numpy as np

from benchmarks.common import markdown_table

from .config import Config
from .helpers import dense_sample, fmt, reset_meters, start_biaxial


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
    series, acc, law, unbalanced = [], [], [], []
    bad = 0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        start = time.perf_counter()
        elapsed_measure = 0.0
        for k in range(1, steps + 1):
            info = sim.step()
            bad += not info.converged
            law.append(info.local_law_residual)
            unbalanced.append(info.unbalanced_force)
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
    measures = dict(law=float(np.median(law)), law90=float(np.percentile(law, 90)),
                    unbalanced=float(np.median(unbalanced)))
    return elapsed, np.array(series), _pair_forces(sim), bad, sim.counters["sweeps"] / steps, first, measures


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
    t_ref, ref_series, ref_forces, ref_bad, ref_sweeps, _, _ = _wp_run(base, ref_dt, ref_tol, cfg.wp_duration, record,
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
            elapsed, series, forces, bad, sweeps, first, m = _wp_run(base, dt, tol, cfg.wp_duration, record)
            e_1, e_f, e_q, e_v = errors(series, forces, first, dt)
            default = dt == 5e-4 and tol == 1.7e-4
            points.append(dict(dt=dt, tol=tol, budget=None, time=elapsed, e_f=e_f, e_q=e_q, e_v=e_v, e_1=e_1,
                               e_law=m["law"], default=default))
            rows.append([f"{dt:g}", f"{tol:g}" + (" (default)" if default else ""), f"{elapsed:.2f}", f"{sweeps:.0f}",
                         bad, fmt(m["law"]), fmt(m["law90"]), fmt(m["unbalanced"]), fmt(e_1), fmt(e_f), fmt(e_q),
                         fmt(e_v)])
            log(rows[-1])
    # fixed budgets: no tolerance (1e-30), every step spends exactly `budget` sweeps
    dt = 5e-4
    for budget in cfg.wp_budgets if dt in cfg.wp_time_steps else ():
        elapsed, series, forces, _, sweeps, first, m = _wp_run(base, dt, 1e-30, cfg.wp_duration, record,
                                                               max_iterations=budget)
        e_1, e_f, e_q, e_v = errors(series, forces, first, dt)
        points.append(dict(dt=dt, tol=None, budget=budget, time=elapsed, e_f=e_f, e_q=e_q, e_v=e_v, e_1=e_1,
                           e_law=m["law"], default=False))
        rows.append([f"{dt:g}", f"none: {budget} sweeps", f"{elapsed:.2f}", f"{sweeps:.0f}", "-", fmt(m["law"]),
                     fmt(m["law90"]), fmt(m["unbalanced"]), fmt(e_1), fmt(e_f), fmt(e_q), fmt(e_v)])
        log(rows[-1])
    header = ["dt (s)", "tolerance", "run time (s)", "sweeps / step", "non-converged steps",
              "local-law residual (median)", "local-law residual (90th pct.)", "unbalanced force (median)",
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
            f"{record * 1e3:g} ms windows (wall stresses chatter from step to step), compared every {record * 1e3:g} ms. "
            f"Local-law residual: |F|/|r| of the natural map over each step's points, zero for every admissible "
            f"solution (solver.residuals); unbalanced force: the largest net force on a particle over the mean "
            f"force of a loaded point (zero in static equilibrium whatever network carries the load).\n\n")
    return text + markdown_table(header, rows), points


def _wp_plot(all_points, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    fig, axes = plt.subplots(1, 5, figsize=(21, 4))
    for (shape, points), colour in zip(all_points.items(), ("C0", "C1")):
        for dt, marker in zip(sorted({p["dt"] for p in points}), ("o", "s", "^", "v")):
            sel = [p for p in points if p["dt"] == dt and p["budget"] is None]
            for ax, key in zip(axes, ("e_law", "e_1", "e_f", "e_q", "e_v")):
                ax.loglog([max(p[key], 1e-12) for p in sel], [p["time"] for p in sel], marker=marker, color=colour,
                          label=f"{shape}, dt={dt:g}")
                for p in sel:
                    if p["default"]:
                        ax.plot(max(p[key], 1e-12), p["time"], "*", ms=18, color="red", mfc="none")
        fixed = [p for p in points if p["budget"] is not None]
        if fixed:
            for ax, key in zip(axes, ("e_law", "e_1", "e_f", "e_q", "e_v")):
                ax.loglog([max(p[key], 1e-12) for p in fixed], [p["time"] for p in fixed], "x--", color=colour,
                          label=f"{shape}, dt=5e-4, fixed sweeps {fixed[0]['budget']}..{fixed[-1]['budget']}")
    for ax, title in zip(axes, ("local-law residual |F|/|r| (median)", "forces, same state (rel. L2)",
                                "forces, end of run (rel. L2)", "max |q/p - ref|",
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
        verdict.append(f"- {shape}s: defaults cost {d['time']:.2f} s for a local-law residual {fmt(d['e_law'])} "
                       f"and a same-state force error {fmt(d['e_1'])}, "
                       f"end-of-run force error {fmt(d['e_f'])}, q/p error {fmt(d['e_q'])}, eps_p error {fmt(d['e_v'])}; "
                       f"at dt = 5e-4 the tolerances from {same_dt[-1]['tol']:g} to {same_dt[0]['tol']:g} cost "
                       f"{same_dt[-1]['time']:.2f} .. {same_dt[0]['time']:.2f} s for same-state force errors "
                       f"{fmt(same_dt[-1]['e_1'])} .. {fmt(same_dt[0]['e_1'])}"
                       + "".join(f"; {p['budget']} fixed sweeps: {p['time']:.2f} s, same-state force error "
                                 f"{fmt(p['e_1'])}, q/p error {fmt(p['e_q'])}" for p in points if p["budget"])
                       + ".")
    return ("\n\n".join(parts) + "\n\n![work-precision](work_precision.png)\n\n" + "\n".join(verdict)), all_points
