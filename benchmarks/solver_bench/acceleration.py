"""Section: fewer sweeps at equal accuracy — the NLGS against its candidates on one dense sheared state.

Every candidate starts from the same state (deep copies): a 1000-particle sample of the fidelity
study (preparation 'paper', seed 0) sheared to eps_1 ~ ``acc_strain``, where the plain NLGS
spends its most sweeps, and runs ``acc_steps`` biaxial steps. Accuracy is judged by measures
that do not depend on which admissible force network is found (solver.residuals): the
local-law residual and the unbalanced force; cost by sweeps and solve time.
"""

from __future__ import annotations

import copy
import os
import time
import warnings
from dataclasses import replace

import numpy as np

from benchmarks.common import markdown_table

from .config import Config
from .helpers import dense_sample, fmt, reset_meters, run_steps, start_biaxial

CANDIDATES = (
    ("NLGS", dict(solver="nlgs")),
    ("NLGS, random order each sweep", dict(solver="nlgs", shuffle=True)),
    ("Anderson, m = 3", dict(solver="anderson", anderson_memory=3)),
    ("Anderson, m = 5", dict(solver="anderson", anderson_memory=5)),
    ("Anderson, m = 8", dict(solver="anderson", anderson_memory=8)),
)


def _state(cfg: Config, shape, log):
    """(simulation, description) of the common starting state."""
    import solver

    if cfg.quick:
        sim, steps = dense_sample(cfg.acc_particles, shape, np.inf, max_steps=cfg.acc_compaction_steps)
        start_biaxial(sim)
        run_steps(sim, 50)
        return sim, f"N = {sim.n_particles}, compacted {steps} steps then 50 biaxial steps (quick run)"
    from benchmarks.fidelity.__main__ import Config as FidelityConfig
    from benchmarks.fidelity.runs import simulate

    run = FidelityConfig().run(shape=shape, particles=cfg.acc_particles)
    if not os.path.exists(run.path()):
        log(f"acceleration {shape}: the fidelity run {os.path.basename(run.path())} is not cached; compacting and "
            "shearing it now (30-60 min on one core; `python -m benchmarks.fidelity` builds it too)")
    path = simulate(run)  # cached in benchmarks/_data/fidelity
    import grainview

    with grainview.open_dataset(path) as ds:
        eps_1 = ds.grain.strains()["eps_1"].values
    index = int(np.nanargmin(np.abs(eps_1 - cfg.acc_strain)))
    log(f"acceleration {shape}: snapshot {index} of {os.path.basename(path)} (eps_1 = {eps_1[index]:.3f})")
    return solver.load_sample(path, index), (f"N = {cfg.acc_particles}, snapshot {index} of the fidelity run "
                                             f"{os.path.basename(path)} (eps_1 = {eps_1[index]:.3f})")


def _measure(base, changes, steps):
    sim = copy.deepcopy(base)
    sim.parameters = replace(sim.parameters, **changes).validate()
    reset_meters(sim)
    sweeps, law, unbalanced = [], [], []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        start = time.perf_counter()
        for _ in range(steps):
            info = sim.step()
            sweeps.append(info.iterations)
            law.append(info.local_law_residual)
            unbalanced.append(info.unbalanced_force)
        elapsed = time.perf_counter() - start
    sweeps = np.array(sweeps)
    return dict(median=np.median(sweeps), mean=sweeps.mean(), p90=np.percentile(sweeps, 90),
                capped=np.mean(sweeps >= sim.parameters.max_iterations), law=np.median(law),
                law90=np.percentile(law, 90), unbalanced=np.median(unbalanced),
                solve_ms=1e3 * sim.timings["solve"] / steps, step_us=1e6 * elapsed / steps / sim.n_particles,
                ns=1e9 * sim.timings["solve"] / max(sim.counters["point_sweeps"], 1),
                points=sim.last.n_points / sim.n_particles)


def section_acceleration(cfg: Config, log=print):
    parts = []
    for shape in ("pentagon", "disk"):
        base, description = _state(cfg, shape, log)
        # compile every candidate's kernels before timing
        for _, changes in CANDIDATES:
            _measure(base, changes, 2)
        rows, points = [], []
        for label, changes in CANDIDATES:
            m = _measure(base, changes, cfg.acc_steps)
            points.append(m["points"])
            rows.append([label, f"{m['median']:.0f}", f"{m['mean']:.0f}", f"{m['p90']:.0f}", f"{100 * m['capped']:.1f}",
                         fmt(m["law"]), fmt(m["law90"]), f"{m['unbalanced']:.3f}", f"{m['solve_ms']:.2f}",
                         f"{m['step_us']:.1f}", f"{m['ns']:.0f}"])
            log(rows[-1])
        parts.append(f"**{shape}s**, {description}, {min(points):.2f}-{max(points):.2f} contact points per "
                     f"particle at the end, {cfg.acc_steps} biaxial steps per candidate at the default tolerance (1.7e-4, "
                     "max norm 1e-2, at most 2000 sweeps).\n\n"
                     + markdown_table(["candidate", "sweeps median", "mean", "p90", "% steps at the cap",
                                       "local-law residual median", "p90", "unbalanced force median",
                                       "solve ms/step", "µs/particle/step", "ns/point-sweep"], rows))
    return ("Each candidate from the same state; the local-law residual (|F|/|r| of the natural map) and the "
            "unbalanced force are zero for every admissible solution, so equal values mean equal accuracy "
            "whichever network each candidate finds. The trajectories part after the first steps, so the "
            "candidates do not see identical states: differences of ~10% in the sweep counts are noise.\n\n"
            + "\n\n".join(parts)), parts
