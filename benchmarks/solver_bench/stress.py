"""Section f: stress tests: fast impacts, dense piles, long runs."""

from __future__ import annotations

import time
import warnings

import numpy as np

from benchmarks.common import markdown_table

from .config import Config
from .helpers import dense_sample, fmt


def _stress_run(sim, steps, source):
    from grainview.contract.errors import ConvergenceWarning

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
    from solver import gravity_scene
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
