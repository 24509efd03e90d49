"""Section a: time per step and per contact sweep against the number of particles."""

from __future__ import annotations

import numpy as np

from common import in_fresh_process, markdown_table

from .config import Config, TARGET_DETECTION_SHARE, TARGET_STEP_US, TARGET_SWEEP_NS
from .helpers import dense_sample, reset_meters, run_steps, start_biaxial


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
