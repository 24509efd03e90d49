"""Sizes of every solver benchmark section (``--quick`` shrinks them), and the speed targets."""

from __future__ import annotations

import os
from dataclasses import dataclass


HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
"""benchmarks/: the package; its _data/ holds what the benchmarks cache."""
DATA = os.path.join(HERE, "_data")
PEER_PYTHON = os.environ.get("PEER_PYTHON", "/tmp/peervenv/bin/python")

TARGET_SWEEP_NS = 25.0  # ns per contact point and NLGS sweep (issue 13: at 57,600 particles)


@dataclass
class Config:
    quick: bool = False
    plot_dir: str = HERE  # where plots go: next to the RESULTS file that links them
    # scaling: dense samples sheared (dense_skip steps left out, dense_timed timed) on each domain count
    dense_sizes: tuple = (1000, 4000, 14400)
    domain_counts: tuple = (1, 2)
    dense_turns: int = 3  # runs of each case, the domain counts in turns
    dense_skip: dict = None
    dense_timed: dict = None
    # ... and loose samples, compacted for a fixed number of steps (the same in every run)
    loose_sizes: tuple = (57600,)
    compaction_steps: dict = None  # per (shape, N)
    loose_timed_steps: int = 3
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
    peer_measured_steps: int = 100  # untimed steps whose floor force is recorded, one value per step
    peer_budgets: tuple = (10, 25, 50)
    peer_tolerances: tuple = (3e-5, 2e-5, 1.5e-5, 1e-5, 1e-6)  # besides the default: what a smaller floor-force error costs
    # skipping
    skip_particles: int = 1000
    skip_steps: int = 40
    # stress
    stress_scale: int = 1
    # acceleration: candidates against the NLGS on one dense sheared state
    acc_particles: int = 1000
    acc_strain: float = 0.08
    acc_steps: int = 1000
    acc_compaction_steps: int = 400

    def __post_init__(self):
        if self.quick:
            self.dense_sizes = (200,)
            self.dense_skip = {200: 5}
            self.dense_timed = {200: 10}
            self.dense_turns = 1
            self.loose_sizes = ()
            self.wp_particles = 80
            self.wp_compaction_steps = 500
            self.wp_duration = 0.004
            self.wp_tolerances = (1e-2, 1.7e-4)
            self.wp_time_steps = (5e-4, 1e-3)
            self.wp_budgets = (20,)
            self.peer_particles = 60
            self.peer_settle_steps = 100
            self.peer_steps = 20
            self.peer_measured_steps = 10
            self.peer_budgets = (10,)
            self.peer_tolerances = ()
            self.skip_particles = 200
            self.acc_particles = 80
            self.acc_steps = 20
            self.skip_steps = 10
            self.stress_scale = 0
        else:
            self.dense_skip = self.dense_skip or {1000: 100, 4000: 100, 14400: 100}
            self.dense_timed = self.dense_timed or {1000: 400, 4000: 300, 14400: 200}
            # a fixed number of steps, so that every run measures the same (loose) state
            self.compaction_steps = self.compaction_steps or {("disk", 57600): 60, ("pentagon", 57600): 1000}


# --------------------------------------------------------------------------------------------
