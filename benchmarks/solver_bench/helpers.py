"""Shared helpers of the solver benchmark sections: dense samples, timed steps, overlaps."""

from __future__ import annotations

import time
import warnings

import numpy as np




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
    from solver.shapes import Shapes

    margin = 0.02 * 2 * float(np.min(radius))
    pi, pj = broadphase.candidate_pairs(position, radius, margin)
    wp, ww = broadphase.wall_candidates(position, radius, wall_point, wall_normal, margin)
    shapes = Shapes.regular(radius, n_vertices)
    pts = narrowphase.detect(position, angle, shapes, wall_point, wall_normal, margin, pi, pj, wp, ww)
    return float(max(0.0, -pts.gap.min())) if len(pts.gap) else 0.0


def fmt(x, digits=3):
    if x is None or (isinstance(x, float) and not np.isfinite(x)):
        return "-"
    return f"{x:.{digits}g}"
