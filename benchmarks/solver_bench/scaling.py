"""Section a: time per biaxial step against the number of particles, on dense samples, on one
core and on two.

Dense rows. Each sample is a compacted, equilibrated packing (the paper's preparation along
benchmarks/compaction.py's ``fast`` route, cached in ``benchmarks/_data/samples/`` and built
here when missing). It is sheared as the shear benchmarks shear it (``solver.biaxial_test``,
top wall at 1 cm/s, sigma_0 kept on the right wall; Anderson sweeps extrapolated every 2
sweeps, the stall test over 200; ``benchmarks.shear.shear``), serially and on 2 domains, each in
a fresh process, three times in turns (a case's turns take the same steps; the row is the turn
of median time). The first ``skip`` steps (the shear's start) are left out and the next
``steps`` timed: a window of the shear, not the whole of it (benchmarks/archive/time-to-strain.md
has whole shears).

Loose rows. At 57,600 particles a dense sample is out of reach of a benchmark run; a sample
compacted for a fixed number of steps measures the cost per contact point there.
"""

from __future__ import annotations

import os
import time

import numpy as np

from benchmarks.common import in_fresh_process, markdown_table

from .config import DATA, Config, TARGET_SWEEP_NS
from .helpers import dense_sample, reset_meters, run_steps, start_biaxial

SAMPLES = os.path.join(DATA, "samples")
"""The cached dense samples, ``<shape>_<N>_fast.pkl`` (benchmarks/compaction.py ``--save``)."""
SHEAR = dict(solver="anderson", anderson_period=2, stall_sweeps=200)
"""How the shear benchmarks solve (``benchmarks.shear.shear``), so the rows compare with them."""


def sample_path(shape: str, n: int) -> str:
    """The cached dense sample of ``n`` particles of ``shape``."""
    return os.path.join(SAMPLES, f"{shape}_{n}_fast.pkl")


def build_sample(shape: str, n: int, domains: int = 2) -> dict:
    """Compact a dense sample along the ``fast`` route with the shear's settings on
    ``domains`` domains and cache it (benchmarks/compaction.py); returns compaction.py's row."""
    from benchmarks import compaction

    os.makedirs(SAMPLES, exist_ok=True)
    return compaction.compact(shape, n, 0, "fast", acceleration="anderson", period=SHEAR["anderson_period"],
                              stall=SHEAR["stall_sweeps"], domains=domains, save=sample_path(shape, n))


def dense_case(path: str, domains: int, skip: int, steps: int) -> dict:
    """Shear the sample at ``path`` (module docstring) on ``domains`` domains; time steps
    ``skip + 1 .. skip + steps``. Returns the per-step sweeps, seconds, contact points and
    local-law residuals of the timed steps, and the simulation's timings and counters over them."""
    from benchmarks.common import load_sample
    from benchmarks.shear import Done, shear

    sim, _ = load_sample(path)
    record = dict(sweeps=[], seconds=[], points=[], law=[], converged=[])
    done = [0]
    started = [0.0]

    def before_step():
        sim.parameters.domains = domains  # shear() sets one domain: the shear's settings on ``domains``
        if done[0] == skip:
            reset_meters(sim)
        started[0] = time.perf_counter()

    def after_step(info):
        if done[0] >= skip:
            record["seconds"].append(time.perf_counter() - started[0])
            record["sweeps"].append(info.iterations)
            record["points"].append(info.n_points)
            record["law"].append(info.local_law_residual)
            record["converged"].append(info.converged)
        done[0] += 1
        if done[0] == skip + steps:
            raise Done

    shear(sim, after_step, before_step=before_step)
    return dict(n=sim.n_particles, domains=domains, timings=dict(sim.timings), counters=dict(sim.counters),
                **{k: np.asarray(v) for k, v in record.items()})


def _loose_case(n, shape, compaction, steps, domains):
    """A loose sample (``compaction`` steps of :func:`solver.compaction_sample`), then ``steps``
    timed biaxial steps on ``domains`` domains: the timings and counters of those steps."""
    sim, compaction_steps = dense_sample(n, shape, np.inf, max_steps=compaction)
    start_biaxial(sim)
    sim.parameters.domains = domains
    run_steps(sim, 2)  # warm-up (numba caches loaded)
    reset_meters(sim)
    elapsed, bad, _, _ = run_steps(sim, steps)
    return dict(n=n, shape=shape, domains=domains, compaction_steps=compaction_steps, steps=steps, elapsed=elapsed,
                timings=dict(sim.timings), counters=dict(sim.counters), points=sim.last.n_points, not_converged=bad)


def _median_turn(turns):
    """The turn whose timed steps took the median time (the turns of one case follow the same
    trajectory, step for step: they differ only by what else the machine did)."""
    return sorted(turns, key=lambda r: float(r["seconds"].sum()))[len(turns) // 2]


def _dense_row(shape, turns, serial, planned):
    """The table's row of one case: its median turn (:func:`_median_turn`) with the turns'
    range, and the speed-ups over the ``serial`` case's median turn (None: no speed-up).
    ``planned``: the turns asked for; a row from fewer (some failed) says so."""
    r = _median_turn(turns)
    t, c = r["timings"], r["counters"]
    steps = len(r["seconds"])
    per_step = float(r["seconds"].sum()) / steps
    n = r["n"]
    spread = [1e3 * float(x["seconds"].sum()) / steps for x in turns]
    solve_per_sweep = t["solve"] / max(c["sweeps"], 1)
    row = [shape, f"{n:,}", r["domains"], f"{r['points'].mean() / n:.2f}", steps, f"{1e3 * per_step:.2f}",
           f"{min(spread):.2f}-{max(spread):.2f}" + ("" if len(turns) == planned else f" ({len(turns)}/{planned} turns)"),
           f"{1e6 * per_step / n:.2f}",
           f"{np.median(r['sweeps']):.0f} ({np.percentile(r['sweeps'], 90):.0f})",
           f"{c['recovery_sweeps'] / steps:.1f}", f"{1e9 * t['solve'] / max(c['point_sweeps'], 1):.1f}",
           f"{100 * (t['broad_phase'] + t['narrow_phase']) / r['seconds'].sum():.0f}%",
           f"{100 * t['solve'] / r['seconds'].sum():.0f}%", f"{int((~r['converged']).sum())}",
           f"{np.median(r['law']):.2g}", f"{max(x['peak'] for x in turns):.0f}"]
    if serial is None:
        row += ["-", "-"]
    else:
        base = _median_turn(serial)
        base_step = float(base["seconds"].sum()) / len(base["seconds"])
        base_sweep = base["timings"]["solve"] / max(base["counters"]["sweeps"], 1)
        row += [f"{base_step / per_step:.2f}x", f"{base_sweep / solve_per_sweep:.2f}x"]
    return row


def section_scaling(cfg: Config, log=print):
    """Section a (module docstring): the dense table, then the loose one."""
    rows, results = [], []
    for shape in ("pentagon", "disk"):
        for n in cfg.dense_sizes:
            path = sample_path(shape, n)
            if not os.path.exists(path):
                log(f"building the dense sample {os.path.basename(path)} (benchmarks/compaction.py, fast route)")
                try:
                    in_fresh_process(build_sample, shape, n)
                except RuntimeError as exc:
                    rows += [[shape, f"{n:,}", d, "sample not built: " + str(exc)[:80]] + [""] * 14
                             for d in cfg.domain_counts]
                    continue
            turns = {d: [] for d in cfg.domain_counts}
            failed = {}
            for turn in range(cfg.dense_turns):  # the order reversed every other turn: drift falls on each alike
                for domains in (cfg.domain_counts if turn % 2 == 0 else cfg.domain_counts[::-1]):
                    try:
                        r, peak = in_fresh_process(dense_case, path, domains, cfg.dense_skip[n], cfg.dense_timed[n])
                    except RuntimeError as exc:
                        failed[domains] = str(exc)[:80]
                        continue
                    r.update(peak=peak, shape=shape)
                    turns[domains].append(r)
                    log(f"{shape} {n} turn {turn}, {domains} domain(s): "
                        f"{1e3 * r['seconds'].sum() / len(r['seconds']):.2f} ms per step")
            for domains in cfg.domain_counts:
                if not turns[domains]:
                    rows.append([shape, f"{n:,}", domains, "failed: " + failed.get(domains, "")] + [""] * 14)
                    continue
                serial = turns.get(1) if domains != 1 else None
                rows.append(_dense_row(shape, turns[domains], serial or None, cfg.dense_turns))
                results.extend(turns[domains])
                log(rows[-1])
    header = ["shape", "N", "domains", "contact points / particle", "timed steps", "ms / step",
              "ms / step: turns' range", "us / step / particle", "NLGS sweeps / step: median (90th pct.)",
              "recovery sweeps / step", "ns / point / sweep", "detection share", "NLGS share", "steps stopped early",
              "local-law residual (median)", "peak RSS (MiB)", "speed-up: step", "speed-up: sweep"]
    skips = ", ".join(f"{cfg.dense_skip[n]} at {n:,}" for n in cfg.dense_sizes)
    timed = ", ".join(f"{cfg.dense_timed[n]} at {n:,}" for n in cfg.dense_sizes)
    text = ("**Dense samples.** Compacted, equilibrated samples of the paper's preparation (benchmarks/compaction.py, "
            "`fast` route, cached in benchmarks/_data/samples/), sheared by `solver.biaxial_test` (top wall 1 cm/s "
            "down, sigma_0 = 10 kPa on the right wall, dt = 5e-4 s, the default tolerance) with Anderson sweeps "
            "extrapolated every 2 sweeps and the stall test over 200 sweeps, as the shear benchmarks solve; each run "
            f"in a fresh process. Steps left out at the shear's start: {skips}; then timed: {timed}: a window of the "
            "shear, not the whole (whole shears: archive/time-to-strain.md). Each case ran "
            f"{cfg.dense_turns} times, the domain counts in turns (the order reversed every other turn); a case's "
            "turns follow the same trajectory step for step, so they differ only by what else the machine did: the "
            "row is the turn of median time, and the range is the turns' spread. 'ns / point / sweep' = NLGS solve "
            "time / (sweeps x contact points), Delassus set-up and Anderson passes included; 'steps stopped early': by "
            "the stall test or the sweep cap; 'speed-up': the serial row's time per step, and per NLGS sweep, over "
            "this row's. The two domain counts follow different trajectories (another sweep order), so their sweeps "
            "differ: the per-sweep speed-up compares equal work. Peak RSS includes the interpreter, numba and the "
            "loaded sample.\n\n")
    text += markdown_table(header, rows)
    loose_text, loose = _loose_section(cfg, log)
    return text + "\n\n" + loose_text, results + loose


def _loose_section(cfg: Config, log=print):
    """The loose rows (module docstring): Markdown text and the runs' results."""
    rows, results = [], []
    for shape in ("pentagon", "disk"):
        for n in cfg.loose_sizes:
            for domains in cfg.domain_counts:
                try:
                    r, peak = in_fresh_process(_loose_case, n, shape, cfg.compaction_steps[shape, n],
                                               cfg.loose_timed_steps, domains)
                except RuntimeError as exc:
                    rows.append([shape, f"{n:,}", domains, "failed: " + str(exc)[:80]] + [""] * 7)
                    continue
                r["peak"] = peak
                results.append(r)
                t, c = r["timings"], r["counters"]
                per_step = r["elapsed"] / r["steps"]
                ns = 1e9 * t["solve"] / max(c["point_sweeps"], 1)
                rows.append([shape, f"{n:,}", domains, r["compaction_steps"], f"{r['points'] / n:.2f}", r["steps"],
                             f"{1e3 * per_step:.0f}", f"{c['sweeps'] / r['steps']:.0f}", f"{ns:.1f}",
                             "met" if ns <= TARGET_SWEEP_NS else "missed", f"{r['peak']:.0f}"])
                log(rows[-1])
    if not rows:
        return "", results
    header = ["shape", "N", "domains", "compaction steps", "contact points / particle", "timed steps", "ms / step",
              "NLGS sweeps / step", "ns / point / sweep", f"<= {TARGET_SWEEP_NS:g} ns", "peak RSS (MiB)"]
    text = ("**Loose samples** (the cost per contact point at a size whose dense sample a benchmark run cannot "
            "afford): `solver.compaction_sample` compacted for a fixed number of steps (walls closing at <= 0.5 m/s), "
            "then biaxial steps with the library's default solver settings on the stated domains. The contact points "
            "per particle show how far from dense (about 2.6 for dense pentagons, 2.0 for disks).\n\n")
    return text + markdown_table(header, rows), results
